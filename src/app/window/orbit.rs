//! The viewer's camera: orbit about a target, pan, zoom (the mouse), or fly (WASD keys and
//! mouse look); reset to the scene's camera. Produces the `Camera` the view draws from.
use crate::render::Camera;
use glam::Vec3;

#[derive(Clone, Copy, Debug)]
pub struct Orbit {
    pub target: Vec3,
    pub distance: f32,
    /// Radians about +Y, and above the horizon.
    pub yaw: f32,
    pub pitch: f32,
    pub fly: bool,
    home: Camera,
    /// Moved since the reset: until then the scene's camera is used as it is (bit for
    /// bit, so the window's frames are `run`'s).
    moved: bool,
}

const PITCH_LIMIT: f32 = 1.55;

impl Orbit {
    pub fn new(home: Camera) -> Self {
        let mut o = Self {
            target: home.target,
            distance: 1.0,
            yaw: 0.0,
            pitch: 0.0,
            fly: false,
            home,
            moved: false,
        };
        o.reset();
        o
    }

    /// Back to the scene's camera (fly mode off).
    pub fn reset(&mut self) {
        let d = self.home.eye - self.home.target;
        self.target = self.home.target;
        self.distance = d.length().max(1e-3);
        self.yaw = d.x.atan2(d.z);
        self.pitch = (d.y / self.distance).clamp(-1.0, 1.0).asin();
        self.fly = false;
        self.moved = false;
    }

    /// Unit vector from the target to the eye.
    fn back(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        Vec3::new(sy * cp, sp, cy * cp)
    }

    pub fn eye(&self) -> Vec3 {
        self.target + self.distance * self.back()
    }

    /// Mouse drag of (dx, dy) pixels: orbit the target, or (fly) turn the head.
    pub fn rotate(&mut self, dx: f32, dy: f32) {
        if dx == 0.0 && dy == 0.0 {
            return;
        }
        self.moved = true;
        let eye = self.eye();
        self.yaw -= dx * 0.008;
        self.pitch = (self.pitch + dy * 0.008).clamp(-PITCH_LIMIT, PITCH_LIMIT);
        if self.fly {
            // The head turns about the eye: the target moves, the eye stays.
            self.target = eye - self.distance * self.back();
        }
    }

    /// Drag with the right button: move target and eye in the view plane.
    pub fn pan(&mut self, dx: f32, dy: f32, height_px: f32) {
        if dx == 0.0 && dy == 0.0 {
            return;
        }
        self.moved = true;
        let (right, up) = self.axes();
        let per_px = 2.0 * self.distance * (self.home.fov_y_deg.to_radians() * 0.5).tan()
            / height_px.max(1.0);
        self.target += (-dx * right + dy * up) * per_px;
    }

    /// Wheel: closer (positive) or farther; in fly mode, move forward.
    pub fn zoom(&mut self, steps: f32) {
        if steps == 0.0 {
            return;
        }
        self.moved = true;
        match self.fly {
            true => self.walk(Vec3::new(0.0, 0.0, steps * 0.1 * self.distance)),
            false => self.distance = (self.distance * 0.9f32.powf(steps)).clamp(1e-3, 1e4),
        }
    }

    /// Fly: move by (right, up, forward) metres.
    pub fn walk(&mut self, m: Vec3) {
        self.moved = true;
        let (right, up) = self.axes();
        let forward = -self.back();
        self.target += m.x * right + m.y * up + m.z * forward;
    }

    fn axes(&self) -> (Vec3, Vec3) {
        let forward = -self.back();
        let right = forward.cross(Vec3::Y).normalize_or_zero();
        (right, right.cross(forward))
    }

    pub fn camera(&self, aspect: f32) -> Camera {
        if !self.moved {
            return Camera {
                aspect,
                ..self.home
            };
        }
        Camera {
            eye: self.eye(),
            target: self.target,
            aspect,
            ..self.home
        }
    }

    /// The orbit's scale, for fly speeds (metres per second).
    pub fn scale(&self) -> f32 {
        (self.home.eye - self.home.target).length()
    }
}

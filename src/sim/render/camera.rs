//! A look-at perspective camera producing Vulkan clip space (y down, depth 0..1).
use glam::{Mat4, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub fov_y_deg: f32,
    pub aspect: f32,
    pub near: f32,
    pub far: f32,
}

impl Camera {
    pub fn look_at(eye: Vec3, target: Vec3, fov_y_deg: f32, aspect: f32) -> Self {
        Self {
            eye,
            target,
            up: Vec3::Y,
            fov_y_deg,
            aspect,
            near: 0.01,
            far: 100.0,
        }
    }

    pub fn view(&self) -> Mat4 {
        Mat4::look_at_rh(self.eye, self.target, self.up)
    }

    pub fn proj(&self) -> Mat4 {
        let mut p = Mat4::perspective_rh(
            self.fov_y_deg.to_radians(),
            self.aspect,
            self.near,
            self.far,
        );
        p.y_axis.y = -p.y_axis.y; // Vulkan's clip-space y points down
        p
    }

    pub fn view_proj(&self) -> Mat4 {
        self.proj() * self.view()
    }

    /// The unit direction of the primary ray through pixel (x, y)'s centre of a w x h
    /// frame, as march.comp makes it (the near and far points unprojected).
    pub fn pixel_ray(&self, x: u32, y: u32, w: u32, h: u32) -> Vec3 {
        let inv = self.view_proj().inverse();
        let ndc = glam::Vec2::new(
            (x as f32 + 0.5) / w as f32 * 2.0 - 1.0,
            (y as f32 + 0.5) / h as f32 * 2.0 - 1.0,
        );
        let a = inv.project_point3(ndc.extend(0.0));
        let b = inv.project_point3(ndc.extend(1.0));
        (b - a).normalize()
    }

    /// Camera right and up axes in world space.
    pub fn axes(&self) -> (Vec3, Vec3) {
        let v = self.view();
        (v.row(0).truncate(), v.row(1).truncate())
    }
}

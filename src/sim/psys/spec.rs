//! A particle system as declared in a scene file's `[[system]]` table (seed 003): the
//! emitter, every attribute as mean + rand x variance (rand uniform in [-1, 1)),
//! attributes over life as keyframe curves, forces, colliders and death rules.
use crate::kinds::SortAlgo;
use crate::psys::{Integrator, SpriteMode};
use serde::{Deserialize, Serialize};

mod validate;

/// mean + rand x variance, per component.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Vary<T> {
    pub mean: T,
    #[serde(default)]
    pub variance: T,
}

pub type Scalar = Vary<f32>;
pub type Vec3 = Vary<[f32; 3]>;
pub type Vec4 = Vary<[f32; 4]>;

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum Shape {
    Point,
    Box,
    Sphere,
    Disc,
    /// The scene character's skinned triangles, picked by bind-pose area; the velocity's
    /// +y turned onto the surface normal.
    Mesh,
}

/// Births per frame: `rate` (mean + rand x variance, rounded stochastically) or
/// `per_area` births per pixel of the emitter's projected bounding disc (level of detail).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct EmitterSpec {
    pub shape: Shape,
    #[serde(default)]
    pub centre: [f32; 3],
    /// Box half extents.
    #[serde(default)]
    pub half: [f32; 3],
    /// Sphere or disc radius.
    #[serde(default)]
    pub radius: f32,
    /// Disc normal.
    #[serde(default = "up")]
    pub normal: [f32; 3],
    /// Born on the surface only (box faces, sphere shell, disc rim).
    #[serde(default)]
    pub surface: bool,
    #[serde(default)]
    pub rate: Option<Scalar>,
    #[serde(default)]
    pub per_area: Option<f32>,
    /// Circle the centre moves on: radius (m) and period (s); none: fixed.
    #[serde(default)]
    pub orbit: Option<[f32; 2]>,
    /// Births in the first frame, besides the rate (a flock, an explosion).
    #[serde(default)]
    pub burst: u32,
}

/// Boids (Reynolds 1987) on the neighbour grid: steering from flockmates within
/// `radius` (separation within `separation_radius`, alignment, cohesion) and away from
/// the colliders the boid would touch `look_ahead` seconds ahead, at most `max_steer`
/// m/s^2; speed kept within [min_speed, max_speed].
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BoidsSpec {
    pub radius: f32,
    pub separation_radius: f32,
    pub separation: f32,
    pub alignment: f32,
    pub cohesion: f32,
    #[serde(default)]
    pub avoidance: f32,
    #[serde(default = "default_look_ahead")]
    pub look_ahead: f32,
    pub max_speed: f32,
    #[serde(default)]
    pub min_speed: f32,
    pub max_steer: f32,
    /// The box the neighbour grid covers ([min, max]); boids outside share its border cells.
    pub bounds: [[f32; 3]; 2],
}

fn default_look_ahead() -> f32 {
    0.5
}

fn up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

/// Attributes at birth.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ParticleSpec {
    #[serde(default = "zero3")]
    pub offset: Vec3,
    #[serde(default = "zero3")]
    pub velocity: Vec3,
    /// Degrees: the velocity's direction uniform in a cone about its mean (its speed
    /// still mean + rand x variance); 0 keeps the per-component variance alone.
    #[serde(default)]
    pub spread: f32,
    pub size: Scalar,
    pub life: Scalar,
    pub color: Vec4,
}

fn zero3() -> Vec3 {
    Vary {
        mean: [0.0; 3],
        variance: [0.0; 3],
    }
}

/// Keyframes over life (life fraction in [0, 1], ascending): factors on the birth values.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct OverLife {
    /// [t, factor]
    #[serde(default)]
    pub size: Vec<[f32; 2]>,
    /// [t, r, g, b]
    #[serde(default)]
    pub color: Vec<[f32; 4]>,
    /// [t, factor]
    #[serde(default)]
    pub opacity: Vec<[f32; 2]>,
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum ForceKind {
    /// strength / (r^2 + eps) toward `at` (negative strength: a repeller).
    Attractor,
    /// Swirl about `axis` through `at`: strength / (r^2 + 1) m/s^2 at distance r.
    Vortex,
    /// Curl-noise flow field: strength, scale (1/m), speed (1/s).
    Curl,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ForceSpec {
    pub kind: ForceKind,
    #[serde(default)]
    pub at: [f32; 3],
    #[serde(default = "up")]
    pub axis: [f32; 3],
    pub strength: f32,
    #[serde(default = "default_eps")]
    pub eps: f32,
    #[serde(default = "one")]
    pub scale: f32,
    #[serde(default)]
    pub speed: f32,
}

fn default_eps() -> f32 {
    0.01
}
fn one() -> f32 {
    1.0
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum ColliderKind {
    /// normal . p >= offset is free space.
    Plane,
    Sphere,
    Box,
    /// The segment a-b swept by radius.
    Capsule,
    /// The scene character's capsules (one per bone), posed every frame.
    Character,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ColliderSpec {
    pub kind: ColliderKind,
    #[serde(default = "up")]
    pub normal: [f32; 3],
    #[serde(default)]
    pub offset: f32,
    #[serde(default)]
    pub centre: [f32; 3],
    #[serde(default)]
    pub radius: f32,
    #[serde(default)]
    pub min: [f32; 3],
    #[serde(default)]
    pub max: [f32; 3],
    #[serde(default)]
    pub a: [f32; 3],
    #[serde(default)]
    pub b: [f32; 3],
    /// Normal velocity kept (and reversed) on contact, 0..=1.
    #[serde(default = "default_restitution")]
    pub restitution: f32,
    /// Tangential velocity lost on contact, 0..=1.
    #[serde(default)]
    pub friction: f32,
    /// Keep particles inside (spheres and boxes as containers).
    #[serde(default)]
    pub inside: bool,
    /// The particle dies on contact.
    #[serde(default)]
    pub kill: bool,
}

fn default_restitution() -> f32 {
    0.3
}

impl ColliderSpec {
    /// The plane y = `y` (free above it).
    pub fn ground(y: f32, restitution: f32, friction: f32) -> Self {
        Self {
            kind: ColliderKind::Plane,
            normal: [0.0, 1.0, 0.0],
            offset: y,
            centre: [0.0; 3],
            radius: 0.0,
            min: [0.0; 3],
            max: [0.0; 3],
            a: [0.0; 3],
            b: [0.0; 3],
            restitution,
            friction,
            inside: false,
            kill: false,
        }
    }
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum EventKind {
    /// A contact with any collider.
    Collision,
    /// The end of the particle's life.
    Death,
}

/// An event: on a collision or at death a particle spawns `count` particles of the
/// system `spawn` where it is (a sub-system). On a collision the parent dies unless
/// `keep_parent`, so `count = 1` changes its type (rain -> splash) and keeps the budget.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct EventSpec {
    pub on: EventKind,
    /// The system the children belong to (its particle attributes, forces, draw).
    pub spawn: String,
    /// Children per event: mean + rand x variance, rounded stochastically.
    #[serde(default = "one_child")]
    pub count: Scalar,
    /// Fraction of the parent's velocity (after the bounce) added to the children's own.
    #[serde(default)]
    pub inherit: f32,
    /// Collision: the parent lives on.
    #[serde(default)]
    pub keep_parent: bool,
    /// Collision: the children's own velocity turned from +y onto the contact normal.
    #[serde(default = "yes")]
    pub along_normal: bool,
}

fn one_child() -> Scalar {
    Vary {
        mean: 1.0,
        variance: 0.0,
    }
}
fn yes() -> bool {
    true
}

/// Most children one event spawns.
pub const MAX_CHILDREN: f32 = 64.0;

/// Death besides the end of life (always on) and the budget (the capacity).
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DeathSpec {
    /// Farther than this from the emitter's centre (m).
    #[serde(default)]
    pub max_distance: Option<f32>,
    /// Leaving the camera's view.
    #[serde(default)]
    pub out_of_view: bool,
}

/// One `[[system]]` of a scene.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SystemSpec {
    pub name: String,
    /// Slots: the budget of live particles (births past it are refused and counted).
    pub capacity: u32,
    #[serde(default)]
    pub integrator: Option<Integrator>,
    #[serde(default)]
    pub draw: Option<SpriteMode>,
    /// Depth sort of sprites and streaks (default counting; none shows the artefact).
    #[serde(default)]
    pub sort: Option<SortAlgo>,
    /// Sprite texture: disc (soft round drop) or smoke (noisy puff).
    #[serde(default)]
    pub sprite: Option<SpriteTexture>,
    /// Point size in pixels (draw = points).
    #[serde(default = "default_point")]
    pub point_px: f32,
    pub emitter: EmitterSpec,
    pub particle: ParticleSpec,
    #[serde(default)]
    pub over_life: OverLife,
    #[serde(default = "gravity")]
    pub gravity: [f32; 3],
    /// Drag toward the wind velocity: [vx, vy, vz, rate per second].
    #[serde(default)]
    pub wind: [f32; 4],
    /// Damping v = c v with c = exp(-damping dt).
    #[serde(default)]
    pub damping: f32,
    #[serde(default)]
    pub force: Vec<ForceSpec>,
    #[serde(default)]
    pub collider: Vec<ColliderSpec>,
    #[serde(default)]
    pub death: DeathSpec,
    /// Sub-systems spawned on a collision or at death (at most one event of each kind).
    #[serde(default)]
    pub event: Vec<EventSpec>,
    /// Flocking on the neighbour grid.
    #[serde(default)]
    pub boids: Option<BoidsSpec>,
}

fn default_point() -> f32 {
    3.0
}
fn gravity() -> [f32; 3] {
    [0.0, -9.81, 0.0]
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum SpriteTexture {
    Disc,
    Smoke,
}

/// Most keyframes per curve, forces and colliders per system (src/sim/psys/codes.rs).
pub const MAX_KEYS: usize = super::codes::MAX_KEYS as usize;
pub const MAX_FORCES: usize = super::codes::MAX_FORCES as usize;
pub const MAX_COLLIDERS: usize = super::codes::MAX_COLLIDERS as usize;

impl SystemSpec {
    /// Whether it emits from or collides with the scene character.
    pub fn uses_character(&self) -> bool {
        self.emitter.shape == Shape::Mesh
            || self
                .collider
                .iter()
                .any(|c| c.kind == ColliderKind::Character)
    }

    /// The integrator after `--integrator`.
    pub fn integrator(&self) -> Integrator {
        self.integrator.unwrap_or(Integrator::Euler)
    }

    pub fn draw(&self) -> SpriteMode {
        self.draw.unwrap_or(SpriteMode::Sprites)
    }

    /// The sort: points are opaque and depth-tested, so they are never sorted.
    pub fn sort(&self) -> SortAlgo {
        match self.draw() {
            SpriteMode::Points => SortAlgo::None,
            _ => self.sort.unwrap_or(SortAlgo::Counting),
        }
    }
}

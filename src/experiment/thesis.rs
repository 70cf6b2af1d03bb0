//! The thesis's rendering scene (seed 000, section 5): N fluid particles filling the built-in
//! walker, frozen at one pose so every row of a table renders the same picture, and a
//! camera framed so the lists hold about as many fragments as the thesis's memory column
//! implies (about 490 per metaball at 512x512).
use crate::character::Character;
use crate::character::Skinning;
use crate::control::placement;
use crate::error::{Error, Result};
use crate::gpu::{Context, Guard};
use crate::render::metaball::{FluidRenderer, MetaballSettings};
use crate::render::Camera;
use crate::render::ListKind;
use crate::scene::character::CharacterDesc;
use glam::Vec3;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};

/// The walk clip's time of the frozen pose (mid-stride).
pub const POSE_T: f32 = 0.4;
/// List fragments per metaball the thesis's memory column implies at 512x512 (5.8 MB of
/// S-buffer at 2048 particles: about 1.0M fragments).
pub const FRAGMENTS_PER_METABALL: f64 = 490.0;
/// Random offsets of the particles from their lattice points, in spacings: the fluid is
/// not a crystal.
const JITTER: f32 = 0.15;

/// The walker scaled so `n_ref` particles at `spacing` fill it, posed at POSE_T: its
/// skinned positions and triangles.
pub struct Body {
    pub height: f32,
    pub positions: Vec<Vec3>,
    pub indices: Vec<u32>,
}

fn posed(height: f32) -> Result<(Character, Vec<Vec3>)> {
    let desc = CharacterDesc {
        height: Some(height),
        ..CharacterDesc::new("builtin:walker")
    };
    let (ch, anim) = desc.load()?;
    let mats = anim.joint_matrices(&ch, POSE_T);
    let (pos, _) = ch.skinned_at(&mats, Skinning::Lbs)?;
    Ok((ch, pos))
}

impl Body {
    /// The walker at the height whose volume holds `n` lattice points at `spacing`.
    pub fn for_particles(n: usize, spacing: f32) -> Result<Self> {
        let mut height = 1.0f32;
        for _ in 0..8 {
            let (ch, pos) = posed(height)?;
            let count = placement::lattice((&pos, &ch.mesh.indices), spacing).len();
            // At least n points, at most 3% over (the extra points are dropped).
            if count >= n && count as f64 <= 1.03 * n as f64 {
                return Ok(Self {
                    height,
                    positions: pos,
                    indices: ch.mesh.indices,
                });
            }
            height *= ((n as f64 / count.max(1) as f64).cbrt() * 1.005) as f32;
        }
        Err(Error::Param(format!(
            "could not size the walker to hold {n} particles at spacing {spacing}"
        )))
    }

    /// `n` particles filling the body: lattice points at the spacing that gives at least
    /// `n` (from `spacing` down), jittered, the surplus dropped at random (seeded).
    pub fn fill(&self, n: usize, spacing: f32, seed: u64) -> Result<(Vec<[f32; 4]>, f32)> {
        let mut s = spacing;
        for _ in 0..12 {
            let pts = placement::lattice((&self.positions, &self.indices), s);
            if pts.len() >= n {
                let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
                let mut pts = pts;
                pts.shuffle(&mut rng);
                pts.truncate(n);
                let out = pts
                    .into_iter()
                    .map(|p| {
                        let j = Vec3::new(
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                        ) * (JITTER * s);
                        let q = p + j;
                        [q.x, q.y, q.z, 0.0]
                    })
                    .collect();
                return Ok((out, s));
            }
            s *= ((pts.len().max(1) as f64 / n as f64).cbrt() * 0.995) as f32;
        }
        Err(Error::Param(format!(
            "could not fill the walker with {n} particles"
        )))
    }

    pub fn bounds(&self) -> (Vec3, Vec3) {
        crate::character::check::bounds(&self.positions)
    }
}

/// The camera: three-quarter front view of the body, at a distance.
pub fn camera(body: &Body, distance: f32, aspect: f32) -> Camera {
    let (lo, hi) = body.bounds();
    let c = 0.5 * (lo + hi);
    let dir = Vec3::new(0.45, 0.2, 1.0).normalize();
    Camera::look_at(c + dir * distance, c, 30.0, aspect)
}

/// The thesis scene at one resolution: the body, its `n` particles and the framed camera.
pub struct ThesisScene {
    pub body: Body,
    pub centers: Vec<[f32; 4]>,
    /// Rest spacing of the particles in the body.
    pub spacing: f32,
    pub distance: f32,
    pub camera: Camera,
    /// S-buffer fragments of the calibration frame (Wyvill, R = 0.04, Phong).
    pub fragments: u64,
    pub target_fragments: u64,
}

impl ThesisScene {
    /// `n` particles at the fluid's rest spacing filling the walker, the camera moved until
    /// an S-buffer frame at width x height holds FRAGMENTS_PER_METABALL per metaball
    /// (scaled by the pixel count) within 3%.
    pub fn new(
        ctx: &Context,
        n: usize,
        spacing: f32,
        width: u32,
        height: u32,
        seed: u64,
    ) -> Result<Self> {
        let body = Body::for_particles(n, spacing)?;
        let (centers, spacing) = body.fill(n, spacing, seed)?;
        let target = (FRAGMENTS_PER_METABALL * n as f64 * (width as f64 * height as f64)
            / (512.0 * 512.0))
            .round() as u64;
        let settings = MetaballSettings {
            list: ListKind::Sbuffer,
            width,
            height,
            ..MetaballSettings::thesis()
        };
        let aspect = width as f32 / height as f32;
        let mut distance = 3.0 * body.height;
        let mut fragments = 0;
        let r = Guard::new(ctx, FluidRenderer::new(ctx, settings)?);
        let mut b = Guard::new(ctx, r.buffers(ctx, n as u64, 2, false)?);
        let mut buf = ctx.storage_buffer("thesis centers", (n * 16) as u64)?;
        let result = (|| -> Result<()> {
            ctx.upload(&mut buf, 0, &centers)?;
            for _ in 0..8 {
                let cam = camera(&body, distance, aspect);
                let (st, _) = r.render_sync(ctx, &mut b, &buf, n as u32, &cam, 0)?;
                fragments = st.fragments;
                let ratio = fragments as f64 / target as f64;
                if (ratio - 1.0).abs() <= 0.03 {
                    return Ok(());
                }
                // Billboard area falls with the square of the distance.
                distance *= ratio.sqrt() as f32;
            }
            Err(Error::Param(format!(
                "could not frame the thesis scene at {width}x{height}: {fragments} fragments \
                 against {target}"
            )))
        })();
        ctx.destroy_buffer(&mut buf);
        result?;
        Ok(Self {
            camera: camera(&body, distance, aspect),
            body,
            centers,
            spacing,
            distance,
            fragments,
            target_fragments: target,
        })
    }

    /// The same body and camera filled with `n` particles instead (table 8): the spacing
    /// shrinks with n, the metaball radius stays.
    pub fn with_particles(&self, n: usize, seed: u64) -> Result<Vec<[f32; 4]>> {
        let start = self.spacing * (self.centers.len() as f32 / n as f32).cbrt() * 1.02;
        Ok(self.body.fill(n, start, seed)?.0)
    }
}

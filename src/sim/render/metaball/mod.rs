//! Metaball rendering (seed 000, section 4): finite-support radial density functions,
//! billboards into per-pixel metaball lists (none, A-buffer, S-buffer), ray marching with
//! six materials, and a CPU reference ray marcher the GPU passes are checked against.
pub mod buffers;
pub mod density;
pub mod passes;
pub mod readback;
pub mod reference;
pub mod renderer;
pub mod settings;
pub mod stats;
pub mod tiles;

pub use buffers::MetaballBuffers;
pub use renderer::FluidRenderer;
pub use settings::MetaballSettings;
pub use stats::{FrameStats, GpuStats, MarchCounts};

/// A resting blob: the `n` points of a cubic lattice of the given spacing nearest to the
/// origin (the thesis's 2048 particles, until characters exist).
pub fn blob(n: usize, spacing: f32) -> Vec<[f32; 4]> {
    let side = ((n as f64).cbrt() * 1.3).ceil() as i32 + 2;
    let mut pts: Vec<[f32; 4]> = Vec::new();
    for z in -side..=side {
        for y in -side..=side {
            for x in -side..=side {
                pts.push([
                    x as f32 * spacing,
                    y as f32 * spacing,
                    z as f32 * spacing,
                    0.0,
                ]);
            }
        }
    }
    // Stable order: by distance, then by coordinates, so the same n gives the same blob.
    pts.sort_by(|a, b| {
        let da = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
        let db = b[0] * b[0] + b[1] * b[1] + b[2] * b[2];
        da.total_cmp(&db)
            .then(a[0].total_cmp(&b[0]))
            .then(a[1].total_cmp(&b[1]))
            .then(a[2].total_cmp(&b[2]))
    });
    pts.truncate(n);
    pts
}

/// A camera framing a blob of `n` points at `spacing`.
pub fn blob_camera(n: usize, spacing: f32, aspect: f32) -> crate::render::Camera {
    let r = spacing * (3.0 * n as f32 / (4.0 * std::f32::consts::PI)).cbrt();
    crate::render::Camera::look_at(
        glam::Vec3::new(0.0, 0.9 * r, 3.4 * r),
        glam::Vec3::ZERO,
        45.0,
        aspect,
    )
}

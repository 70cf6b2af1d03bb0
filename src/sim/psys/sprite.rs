//! Sprite textures, made on the CPU (no asset files): a soft disc for drops and a noisy
//! puff for smoke. Coverage values in [0, 1], side x side, row-major.
use super::spec::SpriteTexture;

pub const SIDE: u32 = 64;

/// Value noise on a lattice of `cells` per side, smoothly interpolated.
fn value_noise(x: f32, y: f32, cells: u32, seed: u64) -> f32 {
    let h = |i: i64, j: i64| {
        let k = super::hash64(seed ^ ((i as u64) << 32) ^ (j as u64 & 0xffff_ffff));
        (k >> 40) as f32 / (1u64 << 24) as f32
    };
    let (fx, fy) = (x * cells as f32, y * cells as f32);
    let (i, j) = (fx.floor() as i64, fy.floor() as i64);
    let (u, v) = (fx - fx.floor(), fy - fy.floor());
    let s = |t: f32| t * t * (3.0 - 2.0 * t);
    let (u, v) = (s(u), s(v));
    let a = h(i, j) + (h(i + 1, j) - h(i, j)) * u;
    let b = h(i, j + 1) + (h(i + 1, j + 1) - h(i, j + 1)) * u;
    a + (b - a) * v
}

/// (side, texels) of a texture.
pub fn texture(kind: SpriteTexture, seed: u64) -> (u32, Vec<f32>) {
    let n = SIDE;
    let mut t = Vec::with_capacity((n * n) as usize);
    for y in 0..n {
        for x in 0..n {
            let (px, py) = ((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32);
            let (dx, dy) = (2.0 * px - 1.0, 2.0 * py - 1.0);
            let r2 = dx * dx + dy * dy;
            let v = match kind {
                SpriteTexture::Disc => (1.0 - r2).max(0.0).powf(1.5),
                SpriteTexture::Smoke => {
                    let fbm = 0.5 * value_noise(px, py, 4, seed)
                        + 0.3 * value_noise(px, py, 8, seed + 1)
                        + 0.2 * value_noise(px, py, 16, seed + 2);
                    ((1.0 - r2).max(0.0).powi(2) * (0.35 + 0.9 * fbm)).min(1.0)
                }
            };
            t.push(v);
        }
    }
    (n, t)
}

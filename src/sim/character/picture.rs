//! `inspect FILE --picture PNG`: the rest pose, turned by its up axis, drawn from the front
//! and from the side (orthographic, z-buffered, lit), with its skeleton over it and the
//! floor it would stand on, so a user sees the orientation before a run.
use super::Character;
use crate::error::Result;
use glam::{Mat3, Vec2, Vec3};
use image::{Rgb, RgbImage};

/// Each view's side in pixels.
pub const VIEW: u32 = 360;
const MARGIN: f32 = 44.0;
const BACKGROUND: Rgb<u8> = Rgb([250, 250, 250]);
const FLOOR: Rgb<u8> = Rgb([120, 100, 80]);
const BONE: Rgb<u8> = Rgb([220, 40, 40]);

/// A view: screen right and the direction towards the viewer.
struct View {
    right: Vec3,
    toward: Vec3,
}

/// The front view (from +Z, the character's front) and the side view (from +X, its left).
const VIEWS: [View; 2] = [
    View {
        right: Vec3::X,
        toward: Vec3::Z,
    },
    View {
        right: Vec3::NEG_Z,
        toward: Vec3::X,
    },
];

/// Draw `ch`'s rest pose turned by `orient` side by side: front, then side.
pub fn draw(ch: &Character, orient: Mat3) -> Result<RgbImage> {
    let (pos, nrm) = ch.skinned_at(&ch.rest_matrices(), crate::character::Skinning::Lbs)?;
    let pos: Vec<Vec3> = pos.iter().map(|p| orient * *p).collect();
    let nrm: Vec<Vec3> = nrm.iter().map(|n| orient * *n).collect();
    let (lo, hi) = super::check::bounds(&pos);
    let c = 0.5 * (lo + hi);
    let extent = (hi - lo).max_element().max(1e-9);
    let scale = (VIEW as f32 - 2.0 * MARGIN) / extent;
    let mut img = RgbImage::from_pixel(2 * VIEW, VIEW, BACKGROUND);
    // Joint heads at rest: the nodes' global translations.
    let g = ch.skeleton.globals(&ch.skeleton.rest_locals());
    let heads: Vec<Vec3> = g.iter().map(|m| orient * m.w_axis.truncate()).collect();
    for (k, v) in VIEWS.iter().enumerate() {
        let up = v.toward.cross(v.right);
        let origin = Vec2::new(
            k as f32 * VIEW as f32 + 0.5 * VIEW as f32,
            0.5 * VIEW as f32,
        );
        let to_screen = |p: Vec3| {
            let q = p - c;
            origin + Vec2::new(q.dot(v.right), -q.dot(up)) * scale
        };
        let mut depth = vec![f32::NEG_INFINITY; (VIEW * VIEW) as usize];
        for tri in ch.mesh.indices.chunks_exact(3) {
            let i = [0, 1, 2].map(|k| tri[k] as usize);
            let s = i.map(|i| to_screen(pos[i]));
            let d = i.map(|i| pos[i].dot(v.toward));
            let n = (nrm[i[0]] + nrm[i[1]] + nrm[i[2]]).normalize_or_zero();
            let light: f32 = (0.35 + 0.65 * n.dot(v.toward + 0.5 * up).max(0.0) / 1.118).min(1.0);
            let shade = Rgb([
                (90.0 * light + 20.0) as u8,
                (150.0 * light + 30.0) as u8,
                (230.0 * light + 25.0) as u8,
            ]);
            fill(&mut img, &mut depth, (k as u32 * VIEW, s, d), shade);
        }
        // The floor the character stands on (its turned rest pose's bottom).
        let y = to_screen(Vec3::new(c.x, lo.y, c.z)).y;
        line(
            &mut img,
            origin.with_y(y) - Vec2::X * 0.48 * VIEW as f32,
            origin.with_y(y) + Vec2::X * 0.48 * VIEW as f32,
            FLOOR,
            k as u32,
        );
        for j in &ch.skeleton.joints {
            let a = to_screen(heads[j.node]);
            dot(&mut img, a, BONE, k as u32);
            if let Some(p) = ch.skeleton.nodes[j.node].parent {
                if ch.skeleton.joints.iter().any(|q| q.node == p) {
                    line(&mut img, to_screen(heads[p]), a, BONE, k as u32);
                }
            }
        }
    }
    Ok(img)
}

/// Fill a screen triangle `s` with depths `d` (larger nearer) in the view at `x0`.
fn fill(img: &mut RgbImage, depth: &mut [f32], (x0, s, d): (u32, [Vec2; 3], [f32; 3]), c: Rgb<u8>) {
    let area = (s[1] - s[0]).perp_dot(s[2] - s[0]);
    if area.abs() < 1e-9 {
        return;
    }
    let lo = s[0]
        .min(s[1])
        .min(s[2])
        .floor()
        .max(Vec2::new(x0 as f32, 0.0));
    let hi = s[0]
        .max(s[1])
        .max(s[2])
        .ceil()
        .min(Vec2::new((x0 + VIEW - 1) as f32, (VIEW - 1) as f32));
    for y in lo.y as u32..=hi.y.max(lo.y) as u32 {
        for x in lo.x as u32..=hi.x.max(lo.x) as u32 {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let w = [
                (s[2] - s[1]).perp_dot(p - s[1]) / area,
                (s[0] - s[2]).perp_dot(p - s[2]) / area,
                (s[1] - s[0]).perp_dot(p - s[0]) / area,
            ];
            if w.iter().any(|w| *w < 0.0) {
                continue;
            }
            let z = w[0] * d[0] + w[1] * d[1] + w[2] * d[2];
            let at = (y * VIEW + x - x0) as usize;
            if z > depth[at] {
                depth[at] = z;
                img.put_pixel(x, y, c);
            }
        }
    }
}

/// A pixel inside view `k` (others are clipped).
fn put(img: &mut RgbImage, p: Vec2, c: Rgb<u8>, k: u32) {
    let (x, y) = (p.x.floor(), p.y.floor());
    let (x0, x1) = ((k * VIEW) as f32, ((k + 1) * VIEW) as f32);
    if x >= x0 && x < x1 && y >= 0.0 && y < VIEW as f32 {
        img.put_pixel(x as u32, y as u32, c);
    }
}

fn line(img: &mut RgbImage, a: Vec2, b: Vec2, c: Rgb<u8>, k: u32) {
    let n = (b - a).abs().max_element().ceil().max(1.0) as usize;
    for i in 0..=n {
        let p = a.lerp(b, i as f32 / n as f32);
        put(img, p, c, k);
        put(img, p + Vec2::X, c, k);
    }
}

fn dot(img: &mut RgbImage, p: Vec2, c: Rgb<u8>, k: u32) {
    for dy in -2..=2 {
        for dx in -2..=2 {
            put(img, p + Vec2::new(dx as f32, dy as f32), c, k);
        }
    }
}

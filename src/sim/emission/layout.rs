//! The emission atlas: where each part of a character's surface lies in the one UV
//! texture RenderToUV fills (seed 002: "several textures merged into one atlas by a
//! per-part UV scale and offset"). A part is a triangle range with UVs in `[0,1]^2` of its
//! own: a file's UV sets (its primitives), or, for the built-in characters (no UVs),
//! generated ones: one equal-area cylindrical map per bone capsule (u = angle around the
//! axis times the radius, v = position along it: the hat-box theorem makes it area
//! preserving on a capsule). Parts get rectangles proportional to their surface area per
//! unit of UV area, packed in shelves with a gap, so texels cover about equal world areas
//! across parts and no texel is shared.
use crate::character::capsules::BoneCapsule;
use crate::character::Mesh;
use crate::error::{Error, Result};
use glam::{Vec2, Vec3};

/// A part's triangles and its rectangle in the atlas.
#[derive(Clone, Debug, PartialEq)]
pub struct LayoutPart {
    pub name: String,
    /// Layout triangles `first .. first + count`.
    pub first: u32,
    pub count: u32,
    /// UV scale (xy) and offset (zw): atlas = uv * scale + offset.
    pub rect: [f32; 4],
}

/// Triangles as drawn into the atlas: three corners each (not shared, so a corner's UV
/// is its part's), each carrying a mesh vertex's skinned position.
#[derive(Clone, Debug, Default)]
pub struct UvLayout {
    /// Per corner: the mesh vertex.
    pub src: Vec<u32>,
    /// Per corner: UV in its part's `[0,1]^2`.
    pub uvs: Vec<Vec2>,
    /// Per layout triangle: the mesh triangle.
    pub tri_of: Vec<u32>,
    pub parts: Vec<LayoutPart>,
    /// UVs were generated (the mesh has none).
    pub generated: bool,
}

/// Gap between packed parts, in texels.
pub const GAP_TEXELS: f32 = 2.0;

impl UvLayout {
    pub fn triangles(&self) -> usize {
        self.tri_of.len()
    }

    /// The mesh's own UVs: one part per UV set (`mesh.uv_parts`, else the whole mesh).
    /// A set whose UVs leave `[0,1]^2` is mapped from its UV bounds.
    pub fn from_mesh(mesh: &Mesh, size: [u32; 2]) -> Result<Self> {
        if mesh.uvs.len() != mesh.positions.len() || mesh.uvs.is_empty() {
            return Err(Error::Param(
                "the emitting mesh has no UVs (texture coordinates): the UV emitter needs them (use --emitter vertices)".into(),
            ));
        }
        let ranges: Vec<(String, u32, u32)> = match mesh.uv_parts.is_empty() {
            true => vec![("mesh".into(), 0, mesh.triangles() as u32)],
            false => mesh
                .uv_parts
                .iter()
                .map(|p| (p.name.clone(), p.first, p.count))
                .collect(),
        };
        let mut out = Self::default();
        let mut sizes = Vec::new();
        for (name, first, count) in ranges {
            let start = out.triangles() as u32;
            let tris = first..first + count;
            let corners: Vec<u32> = tris
                .clone()
                .flat_map(|t| (0..3).map(move |k| (t, k)))
                .map(|(t, k)| mesh.indices[3 * t as usize + k])
                .collect();
            let (lo, hi) = corners.iter().fold(
                (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY)),
                |(lo, hi), &v| (lo.min(mesh.uvs[v as usize]), hi.max(mesh.uvs[v as usize])),
            );
            let inside = lo.cmpge(Vec2::ZERO).all() && hi.cmple(Vec2::ONE).all();
            let map = |u: Vec2| match inside {
                true => u,
                false => (u - lo) / (hi - lo).max(Vec2::splat(1e-12)),
            };
            let mut world = 0.0f64;
            let mut uv_area = 0.0f64;
            for (t, c) in tris.clone().zip(corners.chunks_exact(3)) {
                let c: [u32; 3] = [c[0], c[1], c[2]];
                let p = c.map(|v| mesh.positions[v as usize]);
                let u = c.map(|v| map(mesh.uvs[v as usize]));
                world += tri_area(p[0], p[1], p[2]) as f64;
                uv_area += ((u[1] - u[0]).perp_dot(u[2] - u[0]).abs() * 0.5) as f64;
                out.tri_of.push(t);
                for k in 0..3 {
                    out.src.push(c[k]);
                    out.uvs.push(u[k]);
                }
            }
            // A square whose UV area maps to the part's world area.
            let side = (world / uv_area.max(1e-12)).sqrt() as f32;
            sizes.push([side, side]);
            out.parts.push(LayoutPart {
                name,
                first: start,
                count,
                rect: [1.0, 1.0, 0.0, 0.0],
            });
        }
        out.pack(&sizes, size)?;
        Ok(out)
    }

    /// Generated UVs for a mesh without them: each triangle on the capsule nearest its
    /// centroid (bind pose), one equal-area cylindrical map per capsule.
    pub fn from_capsules(mesh: &Mesh, caps: &[BoneCapsule], size: [u32; 2]) -> Result<Self> {
        if caps.is_empty() {
            return Err(Error::Param(
                "the emitting mesh has no UVs and no capsules to generate them from (use --emitter vertices)".into(),
            ));
        }
        let tris = mesh.triangles();
        let mut owner: Vec<Vec<u32>> = vec![Vec::new(); caps.len()];
        for t in 0..tris {
            let c = (0..3)
                .map(|k| mesh.positions[mesh.indices[3 * t + k] as usize])
                .sum::<Vec3>()
                / 3.0;
            let best = (0..caps.len())
                .min_by(|&x, &y| {
                    let d = |i: usize| caps[i].axis_distance(c) - caps[i].r;
                    d(x).total_cmp(&d(y))
                })
                .expect("capsules");
            owner[best].push(t as u32);
        }
        let mut out = Self {
            generated: true,
            ..Default::default()
        };
        let mut sizes = Vec::new();
        for (ci, tris) in owner.iter().enumerate().filter(|(_, t)| !t.is_empty()) {
            let cap = caps[ci];
            let len = cap.a.distance(cap.b);
            let e = match len > 1e-6 {
                true => (cap.b - cap.a) / len,
                false => Vec3::Y,
            };
            let p1 = e.any_orthonormal_vector();
            let p2 = e.cross(p1);
            let local = |v: u32| {
                let d = mesh.positions[v as usize] - cap.a;
                let ang = d.dot(p2).atan2(d.dot(p1)); // (-pi, pi]
                ((ang / std::f32::consts::TAU) + 0.5, d.dot(e))
            };
            let start = out.triangles() as u32;
            let mut corner_uv = Vec::with_capacity(tris.len() * 3);
            let (mut s_lo, mut s_hi, mut u_hi) = (f32::INFINITY, f32::NEG_INFINITY, 1.0f32);
            for &t in tris {
                let c: [u32; 3] = std::array::from_fn(|k| mesh.indices[3 * t as usize + k]);
                let mut l = c.map(local);
                // A triangle across the seam (u jumps by ~1) unwraps past u = 1.
                let (mn, mx) = l
                    .iter()
                    .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), x| {
                        (a.min(x.0), b.max(x.0))
                    });
                if mx - mn > 0.5 {
                    for x in &mut l {
                        if x.0 < 0.5 {
                            x.0 += 1.0;
                        }
                    }
                }
                for (k, x) in l.iter().enumerate() {
                    s_lo = s_lo.min(x.1);
                    s_hi = s_hi.max(x.1);
                    u_hi = u_hi.max(x.0);
                    corner_uv.push((c[k], *x));
                }
                out.tri_of.push(t);
            }
            let height = (s_hi - s_lo).max(1e-6);
            for (v, (u, s)) in corner_uv {
                out.src.push(v);
                out.uvs.push(Vec2::new(u / u_hi, (s - s_lo) / height));
            }
            sizes.push([std::f32::consts::TAU * cap.r * u_hi, height]);
            out.parts.push(LayoutPart {
                name: format!("capsule {ci} (joint {})", cap.joint),
                first: start,
                count: tris.len() as u32,
                rect: [1.0, 1.0, 0.0, 0.0],
            });
        }
        out.pack(&sizes, size)?;
        Ok(out)
    }

    /// Rectangles for parts of world `sizes` (width, height), one scale for all, packed in
    /// shelves (tallest first) with GAP_TEXELS between them; a single part fills the atlas.
    fn pack(&mut self, sizes: &[[f32; 2]], size: [u32; 2]) -> Result<()> {
        if self.parts.len() == 1 {
            self.parts[0].rect = [1.0, 1.0, 0.0, 0.0];
            return Ok(());
        }
        let gap = [GAP_TEXELS / size[0] as f32, GAP_TEXELS / size[1] as f32];
        let mut order: Vec<usize> = (0..sizes.len()).collect();
        order.sort_by(|&a, &b| sizes[b][1].total_cmp(&sizes[a][1]));
        // Offsets at scale s, or None when they do not fit in the unit square.
        let place = |s: f32| -> Option<Vec<[f32; 2]>> {
            let mut at = vec![[0.0f32; 2]; sizes.len()];
            let (mut x, mut y, mut row) = (0.0f32, 0.0f32, 0.0f32);
            for &i in &order {
                let (w, h) = (sizes[i][0] * s, sizes[i][1] * s);
                if w > 1.0 || h > 1.0 {
                    return None;
                }
                if x + w > 1.0 {
                    x = 0.0;
                    y += row + gap[1];
                    row = 0.0;
                }
                if y + h > 1.0 {
                    return None;
                }
                at[i] = [x, y];
                x += w + gap[0];
                row = row.max(h);
            }
            Some(at)
        };
        let (mut lo, mut hi) = (0.0f32, 1.0f32);
        while place(hi).is_some() {
            hi *= 2.0;
            if hi > 1e12 {
                return Err(Error::Param("atlas packing: parts of zero size".into()));
            }
        }
        for _ in 0..50 {
            let mid = 0.5 * (lo + hi);
            match place(mid) {
                Some(_) => lo = mid,
                None => hi = mid,
            }
        }
        let at = place(lo).filter(|_| lo > 0.0).ok_or_else(|| {
            Error::Param(format!(
                "{} UV parts do not fit a {}x{} atlas with {GAP_TEXELS}-texel gaps: raise --uv-size",
                self.parts.len(),
                size[0],
                size[1]
            ))
        })?;
        for (i, p) in self.parts.iter_mut().enumerate() {
            p.rect = [sizes[i][0] * lo, sizes[i][1] * lo, at[i][0], at[i][1]];
        }
        Ok(())
    }
}

fn tri_area(a: Vec3, b: Vec3, c: Vec3) -> f32 {
    0.5 * (b - a).cross(c - a).length()
}

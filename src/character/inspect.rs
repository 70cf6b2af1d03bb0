//! `fluidform inspect FILE`: what a character or mesh file holds.
use super::Character;
use crate::error::Result;
use serde::Serialize;

#[derive(Clone, Debug, Serialize)]
pub struct ClipInfo {
    pub name: String,
    pub duration: f32,
    pub channels: usize,
}

#[derive(Clone, Debug, Serialize)]
pub struct Inspection {
    pub file: String,
    pub triangles: usize,
    pub vertices: usize,
    pub welded_vertices: usize,
    pub skinned: bool,
    pub joints: usize,
    pub influences_per_vertex: usize,
    pub animations: Vec<ClipInfo>,
    /// Rest-pose bounds (min, max) and size.
    pub bounds_min: [f32; 3],
    pub bounds_max: [f32; 3],
    pub size: [f32; 3],
    pub closed: bool,
    pub boundary_edges: usize,
    pub nonmanifold_edges: usize,
    pub components: usize,
    pub signed_volume: f64,
    pub flipped: bool,
    pub normals: &'static str,
    pub uvs: bool,
    /// The thinnest part: the narrowest bone capsule (None: no capsules).
    pub thinnest: Option<Thinnest>,
    pub warnings: Vec<String>,
}

/// The narrowest bone capsule of a character, in the file's units, against the fluid's
/// default particle spacing.
#[derive(Clone, Debug, Serialize)]
pub struct Thinnest {
    pub joint: String,
    pub diameter: f32,
    /// The diameter in default particle spacings (fluid at the file's own scale).
    pub spacings_at_default: f32,
    /// The spacing that puts three particles across it.
    pub spacing_for_three: f32,
}

/// The thinnest part of `ch` (its narrowest capsule; see `capsules::of`).
pub fn thinnest(ch: &Character) -> Option<Thinnest> {
    let caps = super::capsules::of(ch);
    let c = caps.iter().min_by(|a, b| a.r.total_cmp(&b.r))?;
    let d = 2.0 * c.r;
    Some(Thinnest {
        joint: ch.joint_name(c.joint),
        diameter: d,
        spacings_at_default: d / crate::sph::FluidParams::default().spacing(),
        spacing_for_three: d / 3.0,
    })
}

pub fn inspect(ch: &Character) -> Result<Inspection> {
    let (lo, hi) = ch.rest_bounds()?;
    let c = &ch.check;
    Ok(Inspection {
        file: ch.source.clone(),
        triangles: ch.mesh.triangles(),
        vertices: ch.raw_vertices,
        welded_vertices: c.welded_vertices,
        skinned: ch.skinned,
        joints: if ch.skinned {
            ch.skeleton.joints.len()
        } else {
            0
        },
        influences_per_vertex: 4 * ch.mesh.influence_sets,
        animations: ch
            .clips
            .iter()
            .map(|a| ClipInfo {
                name: a.name.clone(),
                duration: a.duration,
                channels: a.channels.len(),
            })
            .collect(),
        bounds_min: lo.into(),
        bounds_max: hi.into(),
        size: (hi - lo).into(),
        closed: c.closed(),
        boundary_edges: c.boundary_edges,
        nonmanifold_edges: c.nonmanifold_edges,
        components: c.components,
        signed_volume: c.signed_volume,
        flipped: ch.flipped,
        normals: if ch.normals_computed {
            "computed"
        } else {
            "from the file"
        },
        uvs: !ch.mesh.uvs.is_empty(),
        thinnest: thinnest(ch),
        warnings: ch.warnings.clone(),
    })
}

impl Inspection {
    /// The human-readable report.
    pub fn text(&self) -> String {
        let mut s = format!("{}\n", self.file);
        let mut line = |k: &str, v: String| s.push_str(&format!("  {k:<18} {v}\n"));
        line("triangles", self.triangles.to_string());
        line(
            "vertices",
            format!("{} ({} welded)", self.vertices, self.welded_vertices),
        );
        line(
            "joints",
            match self.skinned {
                true => format!(
                    "{} (up to {} influences per vertex)",
                    self.joints, self.influences_per_vertex
                ),
                false => "none (static mesh)".into(),
            },
        );
        if self.animations.is_empty() {
            line("animations", "none".into());
        }
        for (i, a) in self.animations.iter().enumerate() {
            line(
                if i == 0 { "animations" } else { "" },
                format!(
                    "{i}: '{}' {:.3} s, {} channels",
                    a.name, a.duration, a.channels
                ),
            );
        }
        let f = |v: [f32; 3]| format!("({:.4}, {:.4}, {:.4})", v[0], v[1], v[2]);
        line(
            "bounds at rest",
            format!("{} .. {}", f(self.bounds_min), f(self.bounds_max)),
        );
        line("size", f(self.size));
        line(
            "closed",
            match self.closed {
                true => format!("yes ({} components)", self.components),
                false => format!(
                    "no ({} boundary, {} non-manifold edges, {} components)",
                    self.boundary_edges, self.nonmanifold_edges, self.components
                ),
            },
        );
        line(
            "signed volume",
            format!(
                "{:.6}{}",
                self.signed_volume,
                if self.flipped {
                    " (flipped: it faced inward)"
                } else {
                    ""
                }
            ),
        );
        line("normals", self.normals.to_string());
        line("uvs", if self.uvs { "yes" } else { "no" }.to_string());
        if let Some(t) = &self.thinnest {
            line(
                "thinnest part",
                format!(
                    "{:.4} across at joint '{}': {:.2} spacings at the default spacing; --fluid spacing={:.4} puts three particles across (at the file's scale)",
                    t.diameter, t.joint, t.spacings_at_default, t.spacing_for_three
                ),
            );
        }
        for w in &self.warnings {
            s.push_str(&format!("  warning: {w}\n"));
        }
        s
    }
}

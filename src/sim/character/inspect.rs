//! `fluidform inspect FILE`: what a character or mesh file holds.
use super::anim::Up;
use super::thickness::{regions, Region};
use super::Character;
use crate::error::Result;
use glam::Mat3;
use serde::Serialize;

#[derive(Clone, Debug, Serialize)]
pub struct ClipInfo {
    pub name: String,
    pub duration: f32,
    pub channels: usize,
    /// Every channel animates morph target weights: no joint or node moves, the water
    /// follows the morphs alone.
    pub morphs_only: bool,
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
    /// The up axis assumed (turned to +Y) and why.
    pub up: &'static str,
    pub up_note: String,
    /// The thinnest part: the thinnest region of the surface (None: nothing measured).
    pub thinnest: Option<Thinnest>,
    /// The thinnest regions (at most [`REGIONS`]), thinnest first.
    pub regions: Vec<Region>,
    /// The file's mesh nodes (empty: one part, the whole mesh).
    pub parts: Vec<super::MeshPart>,
    pub morph_targets: Vec<MorphInfo>,
    pub warnings: Vec<String>,
}

/// A morph target: its node, default weight, whether normals follow, the clips driving it.
#[derive(Clone, Debug, Serialize)]
pub struct MorphInfo {
    pub name: String,
    pub node: String,
    pub default: f32,
    pub normals: bool,
    pub clips: Vec<String>,
}

/// Every morph target of `ch` with the clips that animate its weight.
pub fn morphs(ch: &Character) -> Vec<MorphInfo> {
    use super::model::Property;
    (ch.mesh.morphs.targets.iter())
        .map(|t| MorphInfo {
            name: t.name.clone(),
            node: ch.skeleton.nodes[t.node].name.clone(),
            default: t.default,
            normals: t.normals,
            clips: (ch.clips.iter())
                .filter(|c| {
                    (c.channels.iter())
                        .any(|k| k.node == t.node && k.property == Property::Weight(t.index as u16))
                })
                .map(|c| c.name.clone())
                .collect(),
        })
        .collect()
}

/// Regions listed by `inspect`.
pub const REGIONS: usize = 5;

/// The thinnest region of a character's surface (`thickness::regions`), in the file's
/// units, against the fluid's default particle spacing.
#[derive(Clone, Debug, Serialize)]
pub struct Thinnest {
    /// The joint (skinned) or the grid cell (static mesh) it lies in.
    pub region: String,
    pub diameter: f32,
    /// The diameter in default particle spacings (fluid at the file's own scale).
    pub spacings_at_default: f32,
    /// The spacing that puts three particles across it.
    pub spacing_for_three: f32,
}

impl Thinnest {
    fn of(r: &Region) -> Self {
        Self {
            region: r.name.clone(),
            diameter: r.thickness,
            spacings_at_default: r.thickness / crate::sph::FluidParams::default().spacing(),
            spacing_for_three: r.thickness / 3.0,
        }
    }
}

/// The thinnest part of `ch` with its rest pose turned by `orient` (names a static
/// mesh's regions by where they lie).
pub fn thinnest(ch: &Character, orient: Mat3) -> Result<Option<Thinnest>> {
    Ok(regions(ch, orient)?.first().map(Thinnest::of))
}

/// The report on `ch` with its up axis `up` (turned to +Y: bounds and regions after it).
pub fn inspect(ch: &Character, up: Up, up_given: bool) -> Result<Inspection> {
    let (lo, hi) = super::anim::turned_bounds(&ch.rest_positions()?, up.matrix());
    let regions = regions(ch, up.matrix())?;
    let obj = ch.source.to_ascii_lowercase().ends_with(".obj");
    let up_note = match (up_given, obj) {
        (true, _) => "as given".to_string(),
        (false, true) => "assumed: OBJ has no up convention; if it lies or stands on its nose, set [character] up = \"z\" (or -z, x, -x, -y) and check with --up AXIS --picture PNG".into(),
        (false, false) if ch.source.starts_with("builtin:") => "built in, Y-up".into(),
        (false, false) => "glTF is Y-up by its specification".into(),
    };
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
                morphs_only: !a.channels.is_empty()
                    && a.channels
                        .iter()
                        .all(|c| matches!(c.property, super::Property::Weight(_))),
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
        up: up.name(),
        up_note,
        thinnest: regions.first().map(Thinnest::of),
        regions: regions.into_iter().take(REGIONS).collect(),
        parts: ch.parts.clone(),
        morph_targets: morphs(ch),
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
                    "{i}: '{}' {:.3} s, {} channels{}",
                    a.name,
                    a.duration,
                    a.channels,
                    match a.morphs_only {
                        true => ", morph target weights only",
                        false => "",
                    }
                ),
            );
        }
        let f = |v: [f32; 3]| format!("({:.4}, {:.4}, {:.4})", v[0], v[1], v[2]);
        line("up axis", format!("{} ({})", self.up, self.up_note));
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
                    "{:.4} across in '{}': {:.2} spacings at the default spacing; --fluid spacing={:.4} puts three particles across (at the file's scale)",
                    t.diameter, t.region, t.spacings_at_default, t.spacing_for_three
                ),
            );
        }
        for (i, r) in self.regions.iter().enumerate() {
            line(
                if i == 0 { "thin regions" } else { "" },
                format!(
                    "'{}' {:.4} across ({} vertices, {:.0}th percentile of the inward rays)",
                    r.name,
                    r.thickness,
                    r.vertices,
                    100.0 * super::thickness::PERCENTILE
                ),
            );
        }
        for (i, p) in self.parts.iter().enumerate() {
            let closed = match p.closed() {
                true => format!("closed, {} components", p.components),
                false => format!(
                    "open: {} boundary, {} non-manifold edges, {} components",
                    p.boundary_edges, p.nonmanifold_edges, p.components
                ),
            };
            let morphs = match p.morph_targets {
                0 => String::new(),
                n => format!(", {n} morph targets"),
            };
            line(
                if i == 0 { "parts" } else { "" },
                format!(
                    "'{}' (mesh '{}'): {} primitives, {} triangles, {}{morphs}; {closed}",
                    p.node, p.mesh, p.primitives, p.triangles, p.placed_by
                ),
            );
        }
        for (i, m) in self.morph_targets.iter().enumerate() {
            let clips = match m.clips.is_empty() {
                true => "no clip".to_string(),
                false => m.clips.join(", "),
            };
            line(
                if i == 0 { "morph targets" } else { "" },
                format!(
                    "'{}' of node '{}', default {}, normals {}; driven by {clips}",
                    m.name,
                    m.node,
                    m.default,
                    if m.normals { "follow" } else { "kept" }
                ),
            );
        }
        for w in &self.warnings {
            s.push_str(&format!("  warning: {w}\n"));
        }
        s
    }
}

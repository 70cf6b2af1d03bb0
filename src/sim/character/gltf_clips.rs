//! glTF animations -> `Clip`s: translation, rotation and scale channels with their
//! interpolation, and morph-weight channels split into one scalar channel per target.
use super::gltf_load::{check_accessor, err};
use super::model::*;
use crate::error::Result;
use glam::{Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use std::path::Path;

/// Every animation of the document as a clip.
pub(super) fn read_clips(
    path: &Path,
    doc: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    warnings: &mut Vec<String>,
) -> Result<Vec<Clip>> {
    let mut clips = Vec::new();
    for a in doc.animations() {
        let name = a
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("animation{}", a.index()));
        let mut channels = Vec::new();
        let mut duration = 0f32;
        for c in a.channels() {
            for ch in read_channel(path, &name, &c, buffers, warnings)? {
                duration = duration.max(*ch.times.last().unwrap());
                channels.push(ch);
            }
        }
        clips.push(Clip {
            name,
            duration,
            channels,
        });
    }
    Ok(clips)
}

/// One channel, checked: accessor types, key and value counts, finite rising times; a
/// morph-weight channel as one channel per target of its node's mesh (none, warned about,
/// when the node has no morph targets).
fn read_channel(
    path: &Path,
    name: &str,
    c: &gltf::animation::Channel,
    buffers: &[gltf::buffer::Data],
    warnings: &mut Vec<String>,
) -> Result<Vec<Channel>> {
    use gltf::animation::util::ReadOutputs;
    use gltf::animation::Property as P;
    use DataType::{F32, I16, I8, U16, U8};
    let label = format!("animation '{name}'");
    let s = c.sampler();
    check_accessor(path, &label, &s.input(), &[(Dimensions::Scalar, &[F32])])?;
    let out: &[(Dimensions, &[DataType])] = match c.target().property() {
        P::Translation | P::Scale => &[(Dimensions::Vec3, &[F32])],
        P::Rotation => &[(Dimensions::Vec4, &[F32, I8, U8, I16, U16])],
        P::MorphTargetWeights => &[(Dimensions::Scalar, &[F32, I8, U8, I16, U16])],
    };
    check_accessor(path, &label, &s.output(), out)?;
    let reader = c.reader(|b| Some(&buffers[b.index()]));
    let times: Vec<f32> = reader
        .read_inputs()
        .map(|i| i.collect())
        .unwrap_or_default();
    let (property, values): (Property, Vec<Vec4>) = match reader.read_outputs() {
        Some(ReadOutputs::Translations(it)) => (
            Property::Translation,
            it.map(|v| Vec3::from(v).extend(0.0)).collect(),
        ),
        Some(ReadOutputs::Scales(it)) => (
            Property::Scale,
            it.map(|v| Vec3::from(v).extend(0.0)).collect(),
        ),
        Some(ReadOutputs::Rotations(it)) => {
            (Property::Rotation, it.into_f32().map(Vec4::from).collect())
        }
        Some(ReadOutputs::MorphTargetWeights(it)) => {
            let node = c.target().node();
            let targets = (node.mesh().and_then(|m| m.primitives().next()))
                .map_or(0, |p| p.morph_targets().count());
            if targets == 0 {
                warnings.push(format!(
                    "animation '{name}': a morph-weight channel of node {} (no morph targets) is ignored",
                    node.index()
                ));
                return Ok(Vec::new());
            }
            let flat: Vec<f32> = it.into_f32().collect();
            (
                Property::Weight(targets.min(u16::MAX as usize) as u16),
                flat.into_iter()
                    .map(|w| Vec4::new(w, 0.0, 0.0, 0.0))
                    .collect(),
            )
        }
        None => {
            return Err(err(
                path,
                format!("animation '{name}': a channel's output cannot be read"),
            ))
        }
    };
    let interp = match s.interpolation() {
        gltf::animation::Interpolation::Step => Interp::Step,
        gltf::animation::Interpolation::Linear => Interp::Linear,
        gltf::animation::Interpolation::CubicSpline => Interp::CubicSpline,
    };
    let per_key = if interp == Interp::CubicSpline { 3 } else { 1 };
    // A weights channel holds every target's value per key (its Weight carries the count
    // until it is split).
    let width = match property {
        Property::Weight(n) => n as usize,
        _ => 1,
    };
    if times.is_empty() || values.len() != width * per_key * times.len() {
        return Err(err(
            path,
            format!(
                "animation '{name}': a channel has {} keys and {} values ({} per key expected)",
                times.len(),
                values.len(),
                width * per_key
            ),
        ));
    }
    if times.iter().any(|t| !t.is_finite()) {
        return Err(err(
            path,
            format!("animation '{name}': a key time is not finite"),
        ));
    }
    if times.windows(2).any(|w| w[1] < w[0]) {
        return Err(err(path, format!("animation '{name}': key times decrease")));
    }
    let node = c.target().node().index();
    let one = |property, values| Channel {
        node,
        property,
        interp,
        times: times.clone(),
        values,
    };
    Ok(match property {
        Property::Weight(_) => (0..width)
            .map(|k| {
                let v = values.iter().skip(k).step_by(width).copied().collect();
                one(Property::Weight(k as u16), v)
            })
            .collect(),
        _ => vec![one(property, values)],
    })
}

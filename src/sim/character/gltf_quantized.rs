//! Attributes as floats whatever their component type: `KHR_mesh_quantization` lets
//! positions, normals, UVs and morph offsets be 8- or 16-bit integers, normalized or not
//! (gltfpack writes them so); the gltf crate's readers take floats only for positions and
//! normals. Float accessors, sparse ones included, go through the gltf crate's reader.
use super::gltf_load::err;
use crate::error::Result;
use gltf::accessor::{DataType, Dimensions};
use gltf::buffer::Data;
use std::ops::Deref;
use std::path::Path;

/// A file's buffers and whether it declares `KHR_mesh_quantization` (integer positions,
/// normals and UVs are refused without it, as the core spec says).
pub struct Buffers {
    pub data: Vec<Data>,
    pub quantized: bool,
}

impl Deref for Buffers {
    type Target = [Data];
    fn deref(&self) -> &[Data] {
        &self.data
    }
}

use DataType::{F32, I16, I8, U16, U8};
/// The component types an attribute may have (core spec, then with quantization).
pub fn allowed(sem: &gltf::Semantic, quantized: bool) -> Option<&'static [DataType]> {
    use gltf::Semantic as S;
    Some(match (sem, quantized) {
        (S::Positions, false) | (S::Normals, false) => &[F32],
        (S::Positions, true) => &[F32, I8, U8, I16, U16],
        (S::Normals, true) => &[F32, I8, I16],
        (S::TexCoords(0), false) => &[F32, U8, U16],
        (S::TexCoords(0), true) => &[F32, I8, U8, I16, U16],
        _ => return None,
    })
}

/// A morph target's POSITION and NORMAL offsets (core: floats; quantized: bytes, shorts).
pub fn morph_allowed(quantized: bool) -> &'static [DataType] {
    match quantized {
        false => &[F32],
        true => &[F32, I8, I16],
    }
}

/// Accessor `a`'s `N` components per element as floats: integers normalized as the spec
/// says (c / (2^(bits-1) - 1), at least -1, or c / (2^bits - 1)), or taken as they are.
pub fn floats<const N: usize>(
    path: &Path,
    what: &str,
    a: &gltf::Accessor,
    buffers: &[Data],
) -> Result<Vec<[f32; N]>>
where
    [f32; N]: gltf::accessor::Item,
{
    if a.dimensions().multiplicity() != N {
        return Err(err(
            path,
            format!("{what}: accessor {} is {:?}", a.index(), a.dimensions()),
        ));
    }
    if a.data_type() == F32 {
        let it =
            gltf::accessor::Iter::<[f32; N]>::new(a.clone(), |b| Some(&buffers[b.index()][..]));
        return it.map(|it| it.collect()).ok_or_else(|| {
            err(
                path,
                format!("{what}: accessor {} cannot be read", a.index()),
            )
        });
    }
    if a.sparse().is_some() {
        return Err(err(
            path,
            format!(
                "{what}: accessor {} is sparse and quantized, which is not supported",
                a.index()
            ),
        ));
    }
    let Some(view) = a.view() else {
        return Ok(vec![[0.0; N]; a.count()]);
    };
    let size = a.data_type().size();
    let stride = view.stride().unwrap_or(size * N);
    let base = view.offset() + a.offset();
    let bytes = &buffers[view.buffer().index()][..];
    let end = base + stride * a.count().saturating_sub(1) + size * N;
    if a.count() > 0 && (end > bytes.len() || end > view.offset() + view.length()) {
        return Err(err(
            path,
            format!("{what}: accessor {} reads past its bufferView", a.index()),
        ));
    }
    let norm = a.normalized();
    let value = |at: usize| -> f32 {
        let b = &bytes[at..at + size];
        match (a.data_type(), norm) {
            (I8, true) => (b[0] as i8 as f32 / 127.0).max(-1.0),
            (U8, true) => b[0] as f32 / 255.0,
            (I16, true) => (i16::from_le_bytes([b[0], b[1]]) as f32 / 32767.0).max(-1.0),
            (U16, true) => u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
            (I8, false) => b[0] as i8 as f32,
            (U8, false) => b[0] as f32,
            (I16, false) => i16::from_le_bytes([b[0], b[1]]) as f32,
            (U16, false) => u16::from_le_bytes([b[0], b[1]]) as f32,
            _ => f32::NAN, // refused above (F32) or by `allowed` (U32)
        }
    };
    Ok((0..a.count())
        .map(|i| std::array::from_fn(|k| value(base + i * stride + k * size)))
        .collect())
}

/// The base colour texture's `KHR_texture_transform` applied to a primitive's UVs (gltfpack
/// moves quantized UVs' scale and offset there), when the transform reads TEXCOORD_0.
pub fn transform_uvs(prim: &gltf::Primitive, uvs: &mut [glam::Vec2]) {
    let info = prim
        .material()
        .pbr_metallic_roughness()
        .base_color_texture();
    let Some(t) = info.as_ref().and_then(|i| i.texture_transform()) else {
        return;
    };
    let set = t
        .tex_coord()
        .unwrap_or(info.as_ref().map_or(0, |i| i.tex_coord()));
    if set != 0 {
        return;
    }
    let (s, c) = t.rotation().sin_cos();
    let [ox, oy] = t.offset();
    let [sx, sy] = t.scale();
    for uv in uvs {
        let (x, y) = (uv.x * sx, uv.y * sy);
        *uv = glam::Vec2::new(c * x + s * y + ox, -s * x + c * y + oy);
    }
}

/// Dimensions an attribute of `sem` has, for its check.
pub fn dims(sem: &gltf::Semantic) -> Dimensions {
    match sem {
        gltf::Semantic::TexCoords(_) => Dimensions::Vec2,
        _ => Dimensions::Vec3,
    }
}

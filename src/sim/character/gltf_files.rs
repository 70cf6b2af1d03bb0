//! Opening a glTF file as people find them: the extensions a file requires are read before
//! the document is validated, so a compressed file is named by its extension; meshopt
//! compression (`EXT_meshopt_compression`, gltfpack's and glTF-Transform's) is decoded with
//! meshoptimizer into the buffers the readers see, and quantized attributes
//! (`KHR_mesh_quantization`) are read by `gltf_quantized`.
use super::gltf_load::err;
use crate::error::Result;
use gltf::buffer::Data;
use serde_json::Value;
use std::path::Path;

pub const MESHOPT: &str = "EXT_meshopt_compression";
pub const QUANTIZATION: &str = "KHR_mesh_quantization";
pub const DRACO: &str = "KHR_draco_mesh_compression";

/// A file's document and buffers, compressed views decoded.
pub struct Opened {
    pub doc: gltf::Document,
    pub buffers: Vec<Data>,
    /// It declares KHR_mesh_quantization: integer positions, normals and UVs are allowed.
    pub quantized: bool,
}

pub fn open(path: &Path) -> Result<Opened> {
    let bytes = std::fs::read(path).map_err(|e| crate::error::Error::Io {
        path: path.display().to_string(),
        source: e,
    })?;
    let invalid = |e: gltf::Error| err(path, format!("not a valid glTF 2.0 file: {e}"));
    let (json, mut blob) = match bytes.starts_with(b"glTF") {
        true => {
            let glb = gltf::Glb::from_slice(&bytes).map_err(invalid)?;
            (glb.json.into_owned(), glb.bin.map(|b| b.into_owned()))
        }
        false => (bytes, None),
    };
    let mut root: Value =
        serde_json::from_slice(&json).map_err(|e| invalid(gltf::Error::Deserialize(e)))?;
    let names = |key: &str, root: &Value| -> Vec<String> {
        root.get(key)
            .and_then(Value::as_array)
            .map(|a| {
                a.iter()
                    .filter_map(|v| v.as_str().map(String::from))
                    .collect()
            })
            .unwrap_or_default()
    };
    let required = names("extensionsRequired", &root);
    if required.iter().any(|e| e == DRACO) {
        return Err(err(
            path,
            format!(
                "{DRACO}: its meshes are Draco-compressed, which fluidform does not decode; \
                 write them uncompressed first, e.g. `npx @gltf-transform/cli copy {} out.glb`",
                path.display()
            ),
        ));
    }
    // What this loader handles itself leaves the list the validator checks.
    if let Some(list) = root
        .get_mut("extensionsRequired")
        .and_then(Value::as_array_mut)
    {
        list.retain(|v| !matches!(v.as_str(), Some(MESHOPT | QUANTIZATION)));
    }
    let known = gltf::json::extensions::ENABLED_EXTENSIONS;
    if let Some(other) = names("extensionsRequired", &root)
        .into_iter()
        .find(|e| !known.contains(&e.as_str()))
    {
        return Err(err(
            path,
            format!("{other}: the file requires this glTF extension, which fluidform cannot read"),
        ));
    }
    let quantized = names("extensionsUsed", &root)
        .iter()
        .any(|e| e == QUANTIZATION);
    let root: gltf::json::Root =
        serde_json::from_value(root).map_err(|e| invalid(gltf::Error::Deserialize(e)))?;
    let doc = gltf::Document::from_json(root).map_err(invalid)?;
    let mut buffers = read_buffers(path, &doc, &mut blob)?;
    decode_views(path, &doc, &mut buffers)?;
    Ok(Opened {
        doc,
        buffers,
        quantized,
    })
}

/// The file's buffers; a missing external buffer file is named before the reader fails. A
/// meshopt fallback buffer (no data of its own) is zeros for the decoded views to fill.
fn read_buffers(
    path: &Path,
    doc: &gltf::Document,
    blob: &mut Option<Vec<u8>>,
) -> Result<Vec<Data>> {
    let base = path.parent().unwrap_or(Path::new("."));
    let mut out = Vec::new();
    for b in doc.buffers() {
        let fallback = b
            .extension_value(MESHOPT)
            .and_then(|e| e.get("fallback"))
            .and_then(Value::as_bool)
            .unwrap_or(false);
        if fallback {
            out.push(Data(vec![0; b.length()]));
            continue;
        }
        if let gltf::buffer::Source::Uri(uri) = b.source() {
            if !uri.starts_with("data:") {
                let file = base.join(super::gltf_load::urlencoding_decode(uri));
                if !file.exists() {
                    return Err(err(
                        path,
                        format!(
                            "buffer {} names '{uri}', which is missing ({})",
                            b.index(),
                            file.display()
                        ),
                    ));
                }
            }
        }
        let data = Data::from_source_and_blob(b.source(), Some(base), blob)
            .map_err(|e| err(path, format!("cannot read its buffers: {e}")))?;
        if data.len() < b.length() {
            return Err(err(
                path,
                format!(
                    "cannot read its buffers: buffer {} holds {} bytes, {} expected",
                    b.index(),
                    data.len(),
                    b.length()
                ),
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// One `EXT_meshopt_compression` buffer view, as the extension's JSON gives it.
struct Compressed {
    buffer: usize,
    offset: usize,
    length: usize,
    stride: usize,
    count: usize,
    mode: String,
    filter: String,
}

impl Compressed {
    fn of(e: &Value) -> Option<Self> {
        let n = |k: &str| e.get(k).and_then(Value::as_u64).map(|v| v as usize);
        let s = |k: &str, d: &str| e.get(k).and_then(Value::as_str).unwrap_or(d).to_string();
        Some(Self {
            buffer: n("buffer")?,
            offset: n("byteOffset").unwrap_or(0),
            length: n("byteLength")?,
            stride: n("byteStride")?,
            count: n("count")?,
            mode: s("mode", ""),
            filter: s("filter", "NONE"),
        })
    }
}

/// Every compressed view decoded into its place in the buffer it names (the fallback).
fn decode_views(path: &Path, doc: &gltf::Document, buffers: &mut [Data]) -> Result<()> {
    for v in doc.views() {
        let Some(e) = v.extension_value(MESHOPT) else {
            continue;
        };
        let what = format!("bufferView {} ({MESHOPT})", v.index());
        let c = Compressed::of(e).ok_or_else(|| {
            err(
                path,
                format!("{what}: buffer, byteLength, byteStride and count are required"),
            )
        })?;
        let src = buffers
            .get(c.buffer)
            .and_then(|b| b.get(c.offset..c.offset.checked_add(c.length)?))
            .ok_or_else(|| {
                err(
                    path,
                    format!("{what}: its bytes lie past buffer {}", c.buffer),
                )
            })?
            .to_vec();
        let bytes = c.count.checked_mul(c.stride).filter(|&b| b <= v.length());
        let dst = bytes
            .and_then(|b| {
                buffers[v.buffer().index()]
                    .0
                    .get_mut(v.offset()..v.offset() + b)
            })
            .ok_or_else(|| {
                err(
                    path,
                    format!(
                        "{what}: {} x {} bytes do not fit the view",
                        c.count, c.stride
                    ),
                )
            })?;
        decode(&c, &src, dst).map_err(|m| err(path, format!("{what}: {m}")))?;
    }
    Ok(())
}

/// Decode one view into `dst` (count x stride bytes), then undo its filter.
fn decode(c: &Compressed, src: &[u8], dst: &mut [u8]) -> std::result::Result<(), String> {
    use meshopt::ffi;
    let (p, s) = (dst.as_mut_ptr().cast(), c.stride);
    // SAFETY: dst holds count x stride bytes (checked by the caller); meshoptimizer's
    // decoders are safe on untrusted input and write no more than that.
    let rc = unsafe {
        match c.mode.as_str() {
            "ATTRIBUTES" if s.is_multiple_of(4) && s <= 256 => {
                ffi::meshopt_decodeVertexBuffer(p, c.count, s, src.as_ptr(), src.len())
            }
            "TRIANGLES" if (s == 2 || s == 4) && c.count.is_multiple_of(3) => {
                ffi::meshopt_decodeIndexBuffer(p, c.count, s, src.as_ptr(), src.len())
            }
            "INDICES" if s == 2 || s == 4 => {
                ffi::meshopt_decodeIndexSequence(p, c.count, s, src.as_ptr(), src.len())
            }
            m => {
                return Err(format!(
                    "mode '{m}' with a {s}-byte stride is not in the extension"
                ))
            }
        }
    };
    if rc != 0 {
        return Err(format!("meshoptimizer could not decode it (error {rc})"));
    }
    // SAFETY: as above; each filter rewrites count elements of `s` bytes in place.
    unsafe {
        match (c.mode.as_str(), c.filter.as_str()) {
            (_, "NONE") => {}
            ("ATTRIBUTES", "OCTAHEDRAL") if s == 4 || s == 8 => {
                ffi::meshopt_decodeFilterOct(p, c.count, s)
            }
            ("ATTRIBUTES", "QUATERNION") if s == 8 => ffi::meshopt_decodeFilterQuat(p, c.count, s),
            ("ATTRIBUTES", "EXPONENTIAL") => ffi::meshopt_decodeFilterExp(p, c.count, s),
            ("ATTRIBUTES", "COLOR") if s == 4 || s == 8 => {
                ffi::meshopt_decodeFilterColor(p, c.count, s)
            }
            (m, f) => {
                return Err(format!(
                    "filter '{f}' on mode '{m}' with a {s}-byte stride is not in the extension"
                ))
            }
        }
    }
    Ok(())
}

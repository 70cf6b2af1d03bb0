//! Compressed and quantized glTF as people find them (gltfpack, glTF-Transform): meshopt
//! decoded to the same triangles as the original, quantized attributes read as floats,
//! Draco and any other unreadable required extension refused in one line that names it.
use super::{common, err_of, triangle_gltf, write_json};
use fluidform::character::{self, Character};
use serde_json::{json, Value};

/// A GLB's JSON and BIN chunks.
fn split_glb(bytes: &[u8]) -> (Value, Vec<u8>) {
    let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap()) as usize;
    let json_len = u32_at(12);
    let json: Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin_at = 20 + json_len;
    let bin_len = u32_at(bin_at);
    (json, bytes[bin_at + 8..bin_at + 8 + bin_len].to_vec())
}

/// `file` rewritten as gltfpack writes it: every view a primitive's attributes or indices
/// read is meshopt-encoded into buffer 0 and decoded into fallback buffer 1 at its old
/// place; the rest (animations, skin, image) stays as it was.
fn meshopt_copy(file: &str, dir: &std::path::Path) -> String {
    let (mut doc, mut bin) = split_glb(&std::fs::read(file).unwrap());
    let fallback_len = bin.len();
    let mut modes: Vec<(usize, usize, &str)> = Vec::new(); // (accessor, view, mode)
    for mesh in doc["meshes"].as_array().unwrap() {
        for prim in mesh["primitives"].as_array().unwrap() {
            for a in prim["attributes"].as_object().unwrap().values() {
                modes.push((a.as_u64().unwrap() as usize, 0, "ATTRIBUTES"));
            }
            if let Some(i) = prim.get("indices") {
                modes.push((i.as_u64().unwrap() as usize, 0, "TRIANGLES"));
            }
        }
    }
    for m in &mut modes {
        m.1 = doc["accessors"][m.0]["bufferView"].as_u64().unwrap() as usize;
    }
    let size = |a: &Value| -> usize {
        let comps = match a["type"].as_str().unwrap() {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            _ => 4,
        };
        let bytes = match a["componentType"].as_u64().unwrap() {
            5120 | 5121 => 1,
            5122 | 5123 => 2,
            _ => 4,
        };
        comps * bytes
    };
    let mut done = std::collections::HashSet::new();
    let mut encoded_views = 0;
    for (acc, view, mode) in modes {
        if !done.insert(view) {
            continue;
        }
        let a = doc["accessors"][acc].clone();
        let v = &mut doc["bufferViews"][view];
        let stride = v
            .get("byteStride")
            .and_then(Value::as_u64)
            .map_or(size(&a), |s| s as usize);
        // The whole view: it may hold several primitives' accessors.
        let count = v["byteLength"].as_u64().unwrap() as usize / stride;
        let off = v.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
        let raw = &bin[off..off + count * stride];
        let enc = match mode {
            "TRIANGLES" => {
                let idx: Vec<u32> = raw
                    .chunks(stride)
                    .map(|c| match stride {
                        2 => u16::from_le_bytes([c[0], c[1]]) as u32,
                        _ => u32::from_le_bytes(c.try_into().unwrap()),
                    })
                    .collect();
                let n = *idx.iter().max().unwrap() as usize + 1;
                meshopt::encoding::encode_index_buffer(&idx, n).unwrap()
            }
            _ if stride % 4 != 0 => continue, // meshopt's vertex codec wants 4-byte strides
            _ => {
                let mut enc =
                    vec![
                        0u8;
                        unsafe { meshopt::ffi::meshopt_encodeVertexBufferBound(count, stride) }
                    ];
                let used = unsafe {
                    meshopt::ffi::meshopt_encodeVertexBuffer(
                        enc.as_mut_ptr(),
                        enc.len(),
                        raw.as_ptr().cast(),
                        count,
                        stride,
                    )
                };
                enc.truncate(used);
                enc
            }
        };
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        v["extensions"] = json!({"EXT_meshopt_compression": {
            "buffer": 0, "byteOffset": bin.len(), "byteLength": enc.len(),
            "byteStride": stride, "count": count, "mode": mode
        }});
        v["buffer"] = json!(1);
        bin.extend(enc);
        encoded_views += 1;
    }
    assert!(encoded_views >= 4, "{encoded_views} views encoded");
    std::fs::write(dir.join("meshopt.bin"), &bin).unwrap();
    doc["buffers"] = json!([
        {"byteLength": bin.len(), "uri": "meshopt.bin"},
        {"byteLength": fallback_len, "extensions": {"EXT_meshopt_compression": {"fallback": true}}}
    ]);
    doc["extensionsUsed"] = json!(["EXT_meshopt_compression"]);
    doc["extensionsRequired"] = json!(["EXT_meshopt_compression"]);
    let p = dir.join("meshopt.gltf");
    std::fs::write(&p, serde_json::to_vec(&doc).unwrap()).unwrap();
    p.display().to_string()
}

/// Each triangle turned to start at its smallest index: meshopt's index codec keeps the
/// triangles, their order and winding, but may rotate a triangle's corners.
fn triangles(m: &fluidform::character::Mesh) -> Vec<[u32; 3]> {
    m.indices
        .chunks(3)
        .map(|t| {
            let k = (0..3).min_by_key(|&k| t[k]).unwrap();
            [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
        })
        .collect()
}

fn same_mesh(a: &Character, b: &Character) {
    assert_eq!(a.mesh.positions, b.mesh.positions);
    assert_eq!(triangles(&a.mesh), triangles(&b.mesh));
    assert_eq!(a.mesh.normals, b.mesh.normals);
    assert_eq!(a.mesh.uvs, b.mesh.uvs);
    assert_eq!(a.mesh.joints, b.mesh.joints);
    assert_eq!(a.mesh.weights, b.mesh.weights);
    assert_eq!(a.skeleton.joints.len(), b.skeleton.joints.len());
    assert_eq!(a.clips.len(), b.clips.len());
}

#[test]
fn a_meshopt_compressed_file_loads_to_its_originals_triangles() {
    let dir = tempfile::tempdir().unwrap();
    let orig = common::asset("CesiumMan.glb");
    let packed = meshopt_copy(&orig, dir.path());
    let a = character::load(&orig).unwrap();
    let b = character::load(&packed).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(b.mesh.indices.len(), 3 * 4672);
    same_mesh(&a, &b);
    // Its bytes damaged: one line naming the view and the extension, no panic.
    let mut doc: Value = serde_json::from_slice(&std::fs::read(&packed).unwrap()).unwrap();
    let views = doc["bufferViews"].as_array_mut().unwrap();
    let k = views
        .iter()
        .position(|v| v.get("extensions").is_some())
        .unwrap();
    views[k]["extensions"]["EXT_meshopt_compression"]["byteLength"] = json!(3);
    let bad = dir.path().join("bad.gltf");
    std::fs::write(&bad, serde_json::to_vec(&doc).unwrap()).unwrap();
    let e = err_of(character::load(bad.to_str().unwrap()));
    assert!(
        e.contains(&format!("bufferView {k} (EXT_meshopt_compression)")),
        "{e}"
    );
    assert_eq!(e.lines().count(), 1, "{e}");
}

/// The triangle with its positions as normalized shorts (KHR_mesh_quantization).
fn quantized_triangle(declared: bool) -> Value {
    let mut doc = triangle_gltf(4, None);
    let mut buf = Vec::new();
    for v in [[0i16, 0, 0, 0], [32767, 0, 0, 0], [0, 32767, 0, 0]] {
        buf.extend(v.iter().flat_map(|c| c.to_le_bytes()));
    }
    let b64 = common::gltf::encode(&buf);
    doc["buffers"] = json!([{"byteLength": buf.len(),
        "uri": format!("data:application/octet-stream;base64,{b64}")}]);
    doc["bufferViews"] = json!([{"buffer": 0, "byteLength": buf.len(), "byteStride": 8}]);
    doc["accessors"][0]["componentType"] = json!(5122);
    doc["accessors"][0]["normalized"] = json!(true);
    doc["accessors"][0]["max"] = json!([32767, 32767, 0]);
    if declared {
        doc["extensionsUsed"] = json!(["KHR_mesh_quantization"]);
        doc["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    }
    doc
}

#[test]
fn quantized_positions_read_as_floats_only_where_declared() {
    let dir = tempfile::tempdir().unwrap();
    let plain =
        character::load(&write_json(dir.path(), "f.gltf", &triangle_gltf(4, None))).unwrap();
    let p = write_json(dir.path(), "q.gltf", &quantized_triangle(true));
    let q = character::load(&p).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(q.mesh.positions, plain.mesh.positions);
    let p = write_json(dir.path(), "u.gltf", &quantized_triangle(false));
    let e = err_of(character::load(&p));
    assert!(
        e.contains(
            "Positions: accessor 0 is Vec3 of I16, which the glTF spec does not allow there"
        ),
        "{e}"
    );
}

#[test]
fn draco_and_unknown_required_extensions_are_named_first_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    // As glTF-Transform writes one: the accessors have no bufferView, the primitive names
    // its Draco data.
    let mut doc = triangle_gltf(4, None);
    doc["accessors"][0]
        .as_object_mut()
        .unwrap()
        .remove("bufferView");
    doc["meshes"][0]["primitives"][0]["extensions"] = json!({"KHR_draco_mesh_compression":
        {"bufferView": 0, "attributes": {"POSITION": 0}}});
    doc["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
    doc["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    let p = write_json(dir.path(), "draco.gltf", &doc);
    let e = err_of(character::load(&p));
    assert!(
        e.starts_with(&format!("{p}: KHR_draco_mesh_compression: ")),
        "{e}"
    );
    assert!(e.contains("@gltf-transform/cli copy"), "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
    let mut doc = triangle_gltf(4, None);
    doc["extensionsRequired"] = json!(["EXT_no_such_thing"]);
    let p = write_json(dir.path(), "other.gltf", &doc);
    let e = err_of(character::load(&p));
    assert!(e.starts_with(&format!("{p}: EXT_no_such_thing: ")), "{e}");
}

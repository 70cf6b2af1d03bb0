//! A small glTF 2.0 writer for generated test files: each accessor its own buffer view of
//! one data-URI buffer.
use serde_json::{json, Value};

#[derive(Default)]
pub struct Doc {
    buf: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Doc {
    fn push(&mut self, bytes: Vec<u8>, acc: Value) -> usize {
        while !self.buf.len().is_multiple_of(4) {
            self.buf.push(0);
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": self.buf.len(), "byteLength": bytes.len()}));
        self.buf.extend(bytes);
        let mut acc = acc;
        acc["bufferView"] = json!(self.views.len() - 1);
        self.accessors.push(acc);
        self.accessors.len() - 1
    }

    fn floats(v: impl IntoIterator<Item = f32>) -> Vec<u8> {
        v.into_iter().flat_map(f32::to_le_bytes).collect()
    }

    /// VEC3 floats (with min and max, which POSITION needs).
    pub fn vec3(&mut self, v: &[[f32; 3]]) -> usize {
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        for p in v {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let acc =
            json!({"componentType": 5126, "count": v.len(), "type": "VEC3", "min": lo, "max": hi});
        self.push(Self::floats(v.iter().flatten().copied()), acc)
    }

    pub fn scalars(&mut self, v: &[f32]) -> usize {
        let acc = json!({"componentType": 5126, "count": v.len(), "type": "SCALAR",
                         "min": [v.iter().cloned().fold(f32::MAX, f32::min)],
                         "max": [v.iter().cloned().fold(f32::MIN, f32::max)]});
        self.push(Self::floats(v.iter().copied()), acc)
    }

    pub fn vec4(&mut self, v: &[[f32; 4]]) -> usize {
        let acc = json!({"componentType": 5126, "count": v.len(), "type": "VEC4"});
        self.push(Self::floats(v.iter().flatten().copied()), acc)
    }

    /// VEC4 unsigned shorts (JOINTS_0).
    pub fn joints(&mut self, v: &[[u16; 4]]) -> usize {
        let bytes = v.iter().flatten().flat_map(|j| j.to_le_bytes()).collect();
        self.push(
            bytes,
            json!({"componentType": 5123, "count": v.len(), "type": "VEC4"}),
        )
    }

    pub fn mat4(&mut self, v: &[glam::Mat4]) -> usize {
        let bytes = Self::floats(v.iter().flat_map(|m| m.to_cols_array()));
        self.push(
            bytes,
            json!({"componentType": 5126, "count": v.len(), "type": "MAT4"}),
        )
    }

    pub fn indices(&mut self, v: &[u16]) -> usize {
        let bytes = v.iter().flat_map(|i| i.to_le_bytes()).collect();
        self.push(
            bytes,
            json!({"componentType": 5123, "count": v.len(), "type": "SCALAR"}),
        )
    }

    /// `doc` (nodes, meshes, skins, animations...) with the buffer, views and accessors.
    pub fn finish(self, mut doc: Value) -> Value {
        let b64 = encode(&self.buf);
        doc["asset"] = json!({"version": "2.0"});
        doc["buffers"] = json!([{"byteLength": self.buf.len(),
            "uri": format!("data:application/octet-stream;base64,{b64}")}]);
        doc["bufferViews"] = Value::Array(self.views);
        doc["accessors"] = Value::Array(self.accessors);
        doc
    }
}

/// Write `doc` as `name` in `dir`; its path.
pub fn write(dir: &std::path::Path, name: &str, doc: &Value) -> String {
    let p = dir.join(name);
    std::fs::write(&p, serde_json::to_string(doc).unwrap()).unwrap();
    p.display().to_string()
}

pub fn encode(b: &[u8]) -> String {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in b.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            s.push(match k <= c.len() {
                true => A[(n >> (18 - 6 * k) & 63) as usize] as char,
                false => '=',
            });
        }
    }
    s
}

/// A unit cube's 8 corners and 12 outward triangles.
pub fn cube() -> (Vec<[f32; 3]>, Vec<u16>) {
    let p = (0..8)
        .map(|i| [(i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2 & 1) as f32])
        .collect();
    let idx = vec![
        0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6,
        1, 3, 5, 3, 7, 5,
    ];
    (p, idx)
}

//! Mesh files: Wavefront OBJ (text, `v`, `vn`, `f v//vn`) and binary little-endian PLY
//! (float x y z nx ny nz, faces as uchar count + int indices): what Blender, Houdini,
//! MeshLab and trimesh read.
use super::Mesh;
use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

fn io(path: &Path) -> impl Fn(std::io::Error) -> Error + '_ {
    move |e| Error::Io {
        path: path.display().to_string(),
        source: e,
    }
}

pub fn write_obj(path: &Path, m: &Mesh) -> Result<()> {
    let f = std::fs::File::create(path).map_err(io(path))?;
    let mut w = std::io::BufWriter::new(f);
    writeln!(
        w,
        "# fluidform surface: {} vertices, {} triangles",
        m.positions.len(),
        m.indices.len() / 3
    )
    .map_err(io(path))?;
    for p in &m.positions {
        writeln!(w, "v {} {} {}", p[0], p[1], p[2]).map_err(io(path))?;
    }
    for n in &m.normals {
        writeln!(w, "vn {} {} {}", n[0], n[1], n[2]).map_err(io(path))?;
    }
    for t in m.indices.chunks(3) {
        let [a, b, c] = [t[0] + 1, t[1] + 1, t[2] + 1];
        writeln!(w, "f {a}//{a} {b}//{b} {c}//{c}").map_err(io(path))?;
    }
    w.flush().map_err(io(path))
}

pub fn write_ply(path: &Path, m: &Mesh) -> Result<()> {
    let f = std::fs::File::create(path).map_err(io(path))?;
    let mut w = std::io::BufWriter::new(f);
    let header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment fluidform surface\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\nproperty float nx\n\
         property float ny\nproperty float nz\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        m.positions.len(),
        m.indices.len() / 3
    );
    w.write_all(header.as_bytes()).map_err(io(path))?;
    for (p, n) in m.positions.iter().zip(&m.normals) {
        for v in p.iter().chain(n) {
            w.write_all(&v.to_le_bytes()).map_err(io(path))?;
        }
    }
    for t in m.indices.chunks(3) {
        w.write_all(&[3u8]).map_err(io(path))?;
        for i in t {
            w.write_all(&(*i as i32).to_le_bytes()).map_err(io(path))?;
        }
    }
    w.flush().map_err(io(path))
}

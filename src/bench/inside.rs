//! `bench inside`: voxelising a character at the fit's finest resolution (height / 70, the
//! spacing `scene::fit` may choose) with its inside test, on the CPU's cores: the file as
//! loaded, and a copy refined to about --triangles (default 50K) triangles with one in 97
//! removed, so that it is open and the winding number does the work.
use super::{BenchOptions, Row};
use crate::character::inside::InsideTest;
use crate::character::{self, check};
use crate::error::Result;
use crate::report::stat;
use crate::scene::fit::FINEST;
use glam::Vec3;
use std::collections::HashMap;
use std::time::Instant;

/// Triangles of the refined copy unless --triangles says otherwise.
pub const TRIANGLES: u32 = 50_000;

/// Every triangle split into four at its edges' midpoints (shared midpoints welded).
fn refine(pos: &mut Vec<Vec3>, idx: &[u32]) -> Vec<u32> {
    let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
    let mut out = Vec::with_capacity(idx.len() * 4);
    for t in idx.chunks_exact(3) {
        let m = [0, 1, 2].map(|k| {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                pos.push(0.5 * (pos[a as usize] + pos[b as usize]));
                pos.len() as u32 - 1
            })
        });
        out.extend([
            t[0], m[0], m[2], t[1], m[1], m[0], t[2], m[2], m[1], m[0], m[1], m[2],
        ]);
    }
    out
}

pub fn inside(opts: &BenchOptions) -> Result<Vec<Row>> {
    let file = opts.character.clone().unwrap_or("builtin:walker".into());
    let ch = character::load(&file)?;
    let rest = ch.rest_positions()?;
    let (lo, hi) = check::bounds(&rest);
    let side = (hi - lo).max_element() / FINEST;
    let want = opts.vertices.unwrap_or(TRIANGLES) as usize;
    if ch.mesh.indices.is_empty() {
        return Err(crate::Error::Model {
            path: file,
            message: "has no triangles to voxelise".into(),
        });
    }
    let (mut pos, mut idx) = (rest.clone(), ch.mesh.indices.clone());
    while idx.len() / 3 < want {
        idx = refine(&mut pos, &idx);
    }
    let open: Vec<u32> = (idx.chunks_exact(3).enumerate())
        .filter(|(t, _)| t % 97 != 0)
        .flat_map(|(_, t)| t.to_vec())
        .collect();
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut rows = Vec::new();
    for (variant, p, i) in [
        ("as loaded", &rest, &ch.mesh.indices),
        ("refined, open", &pos, &open),
    ] {
        let dims = ((hi - lo) / side).ceil().as_uvec3();
        let mut ms = Vec::new();
        let mut inside = 0;
        let mut test_kind = "";
        // One untimed round first (page faults, thread start-up), then --frames timed.
        for rep in 0..=opts.frames {
            let t0 = Instant::now();
            let test = InsideTest::new(p, i);
            let (_, ins) = test.voxels(lo, dims, side);
            let dt = t0.elapsed().as_secs_f64() * 1e3;
            if rep > 0 {
                ms.push(dt);
            }
            inside = ins.iter().filter(|k| **k).count();
            test_kind = match test.is_open() {
                true => "winding number",
                false => "crossings",
            };
        }
        let main =
            stat(&ms).ok_or_else(|| crate::Error::Param("--frames must be at least 1".into()))?;
        rows.push(Row {
            variant: variant.into(),
            n: (i.len() / 3) as u64,
            main,
            passes: Vec::new(),
            reps: ms.len() as u64,
            extra: vec![
                ("test".into(), test_kind.into()),
                (
                    "voxels".into(),
                    dims.as_u64vec3().element_product().to_string(),
                ),
                ("inside".into(), inside.to_string()),
                ("threads".into(), threads.to_string()),
            ],
            interval: None,
            flagged: false,
        });
    }
    Ok(rows)
}

/// What the table's times are: CPU wall time, outside the GPU protocol described beside it.
pub fn notes(rows: &[Row]) -> Vec<String> {
    let threads = rows.first().map_or("?".into(), |r| r.extra[3].1.clone());
    vec![format!(
        "Wall time on the CPU ({threads} threads), not under the GPU protocol above: one untimed round, then --frames rounds in a row, their median; building the test is included. The target: at most 1000 ms for 50K triangles on 2 cores."
    )]
}

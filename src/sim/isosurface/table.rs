//! The marching-cubes case table, built rather than typed: for each of the 256 corner
//! states, every face of the cube joins the crossed edges around its inside corners
//! (a face with two diagonal inside corners cuts each off alone), the segments link into
//! closed loops, and each loop becomes a fan of triangles facing away from the inside.
//! The face rule depends only on the face's four corners, so two cells sharing a face cut
//! it alike: the surface is closed (tested on every case).

/// Corner c at (c & 1, (c >> 1) & 1, (c >> 2) & 1).
pub fn corner(c: usize) -> [usize; 3] {
    [c & 1, (c >> 1) & 1, (c >> 2) & 1]
}

/// The 12 edges as corner pairs: 4 along x, 4 along y, 4 along z.
pub const EDGES: [(usize, usize); 12] = [
    (0, 1),
    (2, 3),
    (4, 5),
    (6, 7),
    (0, 2),
    (1, 3),
    (4, 6),
    (5, 7),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

/// The 6 faces as corners in cyclic order.
const FACES: [[usize; 4]; 6] = [
    [0, 2, 6, 4],
    [1, 3, 7, 5],
    [0, 1, 5, 4],
    [2, 3, 7, 6],
    [0, 1, 3, 2],
    [4, 5, 7, 6],
];

fn edge_of(a: usize, b: usize) -> usize {
    EDGES
        .iter()
        .position(|&(p, q)| (p, q) == (a, b) || (p, q) == (b, a))
        .expect("adjacent corners")
}

/// Triangles (edge indices, three per triangle) of corner state `case` (bit c: corner c
/// inside), facing from inside to outside.
pub fn triangles(case: usize) -> Vec<[usize; 3]> {
    let inside = |c: usize| case >> c & 1 == 1;
    // Each face's segments between crossed edges.
    let mut links: Vec<(usize, usize)> = Vec::new();
    for f in FACES {
        let ins: Vec<usize> = (0..4).filter(|&i| inside(f[i])).collect();
        let edge = |i: usize| edge_of(f[i % 4], f[(i + 1) % 4]);
        match ins.len() {
            0 | 4 => {}
            // Around each inside corner alone (one, or two on a diagonal).
            1 | 2 if ins.len() == 1 || (ins[1] - ins[0]) == 2 => {
                for &i in &ins {
                    links.push((edge(i + 3), edge(i)));
                }
            }
            // Two adjacent inside corners: the edges leaving the pair.
            2 => {
                let first = if ins == [0, 3] { 3 } else { ins[0] };
                links.push((edge(first + 3), edge(first + 1)));
            }
            // Three inside: around the outside corner.
            _ => {
                let out = (0..4).find(|&i| !inside(f[i])).unwrap();
                links.push((edge(out + 3), edge(out)));
            }
        }
    }
    // Link the segments into loops.
    let mut loops: Vec<Vec<usize>> = Vec::new();
    while let Some((a, b)) = links.pop() {
        let mut lp = vec![a, b];
        loop {
            let last = *lp.last().unwrap();
            let Some(k) = links.iter().position(|&(p, q)| p == last || q == last) else {
                break;
            };
            let (p, q) = links.swap_remove(k);
            let next = if p == last { q } else { p };
            if next == lp[0] {
                break;
            }
            lp.push(next);
        }
        loops.push(lp);
    }
    let mid = |e: usize| {
        let (a, b) = (corner(EDGES[e].0), corner(EDGES[e].1));
        [0, 1, 2].map(|k| (a[k] + b[k]) as f64 * 0.5)
    };
    let mut tris = Vec::new();
    for mut lp in loops {
        // Outward: from each crossed edge's inside end to its outside end.
        let mut out = [0.0f64; 3];
        for &e in &lp {
            let (a, b) = EDGES[e];
            let (i, o) = if inside(a) { (a, b) } else { (b, a) };
            let (ci, co) = (corner(i), corner(o));
            for k in 0..3 {
                out[k] += co[k] as f64 - ci[k] as f64;
            }
        }
        // Newell's normal of the loop.
        let mut n = [0.0f64; 3];
        for i in 0..lp.len() {
            let (p, q) = (mid(lp[i]), mid(lp[(i + 1) % lp.len()]));
            n[0] += (p[1] - q[1]) * (p[2] + q[2]);
            n[1] += (p[2] - q[2]) * (p[0] + q[0]);
            n[2] += (p[0] - q[0]) * (p[1] + q[1]);
        }
        if n[0] * out[0] + n[1] * out[1] + n[2] * out[2] < 0.0 {
            lp.reverse();
        }
        for i in 1..lp.len() - 1 {
            tris.push([lp[0], lp[i], lp[i + 1]]);
        }
    }
    tris
}

/// All 256 cases.
pub fn table() -> Vec<Vec<[usize; 3]>> {
    (0..256).map(triangles).collect()
}

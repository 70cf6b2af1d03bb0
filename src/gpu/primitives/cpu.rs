//! CPU references for the GPU primitives (tests compare against these).

/// Prefix sum with wrapping u32 arithmetic, as the GPU computes it.
pub fn scan(input: &[u32], inclusive: bool) -> Vec<u32> {
    let mut acc = 0u32;
    input
        .iter()
        .map(|&v| {
            let before = acc;
            acc = acc.wrapping_add(v);
            if inclusive {
                acc
            } else {
                before
            }
        })
        .collect()
}

/// Component-wise min and max of the xyz of vec4 positions.
pub fn bounds(pos: &[[f32; 4]]) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f32::MAX; 3];
    let mut hi = [-f32::MAX; 3];
    for p in pos {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// Check a key/value sort: keys ascending, the same multiset of (key, value) pairs.
pub fn check_sorted_pairs(
    in_keys: &[u32],
    in_vals: &[u32],
    keys: &[u32],
    vals: &[u32],
) -> Result<(), String> {
    if keys.len() != in_keys.len() || vals.len() != in_vals.len() {
        return Err("length changed".into());
    }
    if let Some(i) = keys.windows(2).position(|w| w[0] > w[1]) {
        return Err(format!(
            "keys[{i}] = {} > keys[{}] = {}",
            keys[i],
            i + 1,
            keys[i + 1]
        ));
    }
    let mut a: Vec<(u32, u32)> = in_keys
        .iter()
        .copied()
        .zip(in_vals.iter().copied())
        .collect();
    let mut b: Vec<(u32, u32)> = keys.iter().copied().zip(vals.iter().copied()).collect();
    a.sort_unstable();
    b.sort_unstable();
    if a != b {
        let i = a.iter().zip(&b).position(|(x, y)| x != y).unwrap_or(0);
        return Err(format!(
            "pairs differ from the input (first at sorted pair {i}: {:?} vs {:?})",
            a.get(i),
            b.get(i)
        ));
    }
    Ok(())
}

/// All j != i with |p_i - p_j|^2 <= r^2, by brute force (f64 distances).
pub fn brute_neighbors(pos: &[[f32; 4]], r: f32) -> Vec<Vec<u32>> {
    let r2 = (r as f64) * (r as f64);
    pos.iter()
        .enumerate()
        .map(|(i, p)| {
            pos.iter()
                .enumerate()
                .filter(|&(j, q)| j != i && dist2(p, q) <= r2)
                .map(|(j, _)| j as u32)
                .collect()
        })
        .collect()
}

pub fn dist2(p: &[f32; 4], q: &[f32; 4]) -> f64 {
    (0..3).map(|k| (p[k] as f64 - q[k] as f64).powi(2)).sum()
}

//! f64 vector arithmetic and kernels of the CPU references (cpu_pressure.rs, the
//! paper_*.rs, boundary.rs).
pub type V3 = [f64; 3];

pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
/// y + a x.
pub fn axpy(a: f64, x: V3, y: V3) -> V3 {
    [y[0] + a * x[0], y[1] + a * x[1], y[2] + a * x[2]]
}
pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// xyz of each vec4, in f64.
pub fn xyz(v: &[[f32; 4]]) -> Vec<V3> {
    v.iter()
        .map(|p| [p[0] as f64, p[1] as f64, p[2] as f64])
        .collect()
}

pub use super::kernel::Smoothing;

/// For each point, the others within h of it (brute force).
pub fn neighbours(p: &[V3], h: f64) -> Vec<Vec<usize>> {
    (0..p.len())
        .map(|i| {
            (0..p.len())
                .filter(|&j| j != i && dot(sub(p[i], p[j]), sub(p[i], p[j])) < h * h)
                .collect()
        })
        .collect()
}

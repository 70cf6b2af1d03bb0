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

/// Poly6 densities and spiky gradients at support h, in f64 (the paper references').
pub struct Smoothing {
    h: f64,
    k: super::params::Kernels,
}

impl Smoothing {
    pub fn new(h: f64) -> Self {
        Self {
            h,
            k: super::params::Kernels::new(h),
        }
    }

    /// W(d), poly6.
    pub fn w(&self, d: V3) -> f64 {
        self.w_r2(dot(d, d))
    }

    /// W at squared distance r2, poly6.
    pub fn w_r2(&self, r2: f64) -> f64 {
        let q = self.h * self.h - r2;
        if q > 0.0 {
            self.k.poly6 * q * q * q
        } else {
            0.0
        }
    }

    /// grad W(d), spiky (0 at d = 0).
    pub fn grad(&self, d: V3) -> V3 {
        let r = dot(d, d).sqrt();
        if r >= self.h || r <= 1e-6 * self.h {
            return [0.0; 3];
        }
        let s = self.k.spiky_grad * (self.h - r) * (self.h - r) / r;
        [s * d[0], s * d[1], s * d[2]]
    }
}

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

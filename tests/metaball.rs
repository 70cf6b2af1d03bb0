//! Metaball density functions and the CPU reference ray marcher.
use fluidform::render::metaball::reference::{field, march, MarchParams};
use fluidform::render::DensityFn;
use glam::Vec3;

#[test]
fn density_functions_are_normalised_continuous_and_decreasing() {
    let r = 0.04;
    for f in DensityFn::all().iter().copied() {
        assert!((f.value(0.0, r) - 1.0).abs() < 1e-6, "{f:?}: D(0)");
        assert!(
            f.value(r * 0.99999, r).abs() < 1e-3,
            "{f:?}: D(R-) = {}",
            f.value(r * 0.99999, r)
        );
        assert_eq!(f.value(r, r), 0.0, "{f:?}: D(R)");
        assert_eq!(f.value(2.0 * r, r), 0.0, "{f:?}: beyond R");
        let mut last = f.value(0.0, r);
        for i in 1..=200 {
            let x = r * i as f32 / 200.0;
            let v = f.value(x, r);
            assert!(v <= last + 1e-6, "{f:?}: increases at r = {x}");
            last = v;
            // Derivative against central differences (away from Nishimura's seam at R/3).
            if i < 199 && (x / r - 1.0 / 3.0).abs() > 0.01 {
                let h = 1e-4 * r;
                let fd = (f.value(x + h, r) - f.value(x - h, r)) / (2.0 * h);
                let d = f.derivative(x, r);
                assert!(
                    (fd - d).abs() <= 1e-2 * (1.0 / r) + 1e-3 * d.abs(),
                    "{f:?}: D'({x}) = {d}, differences {fd}"
                );
            }
        }
    }
    // Nishimura's two pieces meet at R/3 with value 2/3.
    assert!((DensityFn::Nishimura.value(0.04 / 3.0, 0.04) - 2.0 / 3.0).abs() < 1e-5);
}

#[test]
fn reference_marcher_hits_a_single_ball_where_expected() {
    // One metaball: the surface is the sphere where D(r) = T.
    for f in DensityFn::all().iter().copied() {
        let p = MarchParams {
            density: f,
            radius: 0.04,
            threshold: 0.5,
            step: 0.0005,
            max_steps: 10_000,
            refine: 20,
        };
        // Radius of the iso-surface by bisection on D.
        let (mut a, mut b) = (0.0f32, 0.04f32);
        for _ in 0..60 {
            let m = 0.5 * (a + b);
            if f.value(m, 0.04) >= 0.5 {
                a = m
            } else {
                b = m
            }
        }
        let iso = 0.5 * (a + b);
        let c = [Vec3::new(0.1, 0.2, 0.3)];
        let origin = Vec3::new(0.1, 0.2, 1.0);
        let hit = march(&c, &p, origin, Vec3::new(0.0, 0.0, -1.0)).expect("hit");
        let expected_t = 1.0 - 0.3 - iso;
        assert!(
            (hit.t - expected_t).abs() < 1e-5,
            "{f:?}: t {} vs {expected_t}",
            hit.t
        );
        assert!(
            (hit.normal - Vec3::Z).length() < 1e-3,
            "{f:?}: normal {:?}",
            hit.normal
        );
        assert!((field(&c, &p, hit.point) - 0.5).abs() < 1e-3);
        // A ray passing beside the ball misses.
        assert!(march(&c, &p, Vec3::new(0.2, 0.2, 1.0), Vec3::new(0.0, 0.0, -1.0)).is_none());
    }
}

//! Dam breaks, colliders (still and moving), bad scenes.

use super::*;

#[test]
fn short_dam_break_is_stable_and_stays_in_the_domain() {
    let ctx = common::ctx();
    let scene = Scene::built_in("dam-break").unwrap().with_particles(3000);
    let d = run_steps(&ctx, &scene, 400, Neighbors::Grid, SortAlgo::Counting);
    assert_sane(&d, &scene, "dam break");
    // The column has collapsed: the centre of mass moved down and along x.
    let n = d.pos.len() as f32;
    let cy = d.pos.iter().map(|p| p[1]).sum::<f32>() / n;
    let parts = scene.particles(1);
    let cy0 = parts.pos.iter().map(|p| p[1]).sum::<f32>() / n;
    assert!(cy < cy0 * 0.97, "centre of mass {cy0} -> {cy}");
    let groups: std::collections::BTreeSet<u32> = d.attr.iter().map(|a| a[3].to_bits()).collect();
    assert_eq!(groups.len(), 1);
    common::finish(&ctx);
}

#[test]
fn colliders_keep_fluid_out_and_strategies_agree() {
    let ctx = common::ctx();
    let scene = Scene::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/scenes/obstacles.toml"
    ))
    .unwrap();
    assert_eq!(scene.colliders.len(), 3);
    let mut means = Vec::new();
    for (strategy, sort) in STRATEGIES {
        let d = run_steps(&ctx, &scene, 150, strategy, sort);
        assert_sane(&d, &scene, "obstacles");
        for (i, p) in d.pos.iter().enumerate() {
            for c in &scene.colliders {
                let dist = c.distance([p[0], p[1], p[2]]);
                assert!(
                    dist > -1e-4,
                    "{strategy:?}/{sort:?}: particle {i} inside {c:?} by {dist}"
                );
            }
        }
        let n = d.pos.len() as f64;
        let cy = d.pos.iter().map(|p| p[1] as f64).sum::<f64>() / n;
        let rho = d.rho_p.iter().map(|r| r[0] as f64).sum::<f64>() / n;
        means.push((cy, rho));
    }
    // Same physics whatever the neighbour search: aggregates agree closely.
    for m in &means[1..] {
        assert!((m.0 - means[0].0).abs() < 2e-3, "centre of mass {means:?}");
        assert!(
            (m.1 / means[0].1 - 1.0).abs() < 1e-2,
            "mean density {means:?}"
        );
    }
    common::finish(&ctx);
}

#[test]
fn moving_collider_pushes_fluid() {
    let ctx = common::ctx();
    let mut scene = Scene::built_in("resting-block").unwrap();
    scene.fluid.dt = 0.002;
    let parts = scene.particles(1);
    let mut solver = SphSolver::new(&ctx, Neighbors::Grid, None).unwrap();
    let mut st = solver.state(&ctx, &scene, &parts).unwrap();
    // A sphere sweeping through the block along x.
    for step in 0..60 {
        let x = 0.05 + step as f32 * 0.008;
        let c = Collider::Sphere {
            center: [x, 0.08, 0.3],
            radius: 0.06,
            velocity: [4.0, 0.0, 0.0],
        };
        st.set_colliders(&[c.to_gpu().unwrap()]).unwrap();
        ctx.one_shot(|cmd| solver.record_step(&ctx, cmd, &mut Labels, &mut st).unwrap())
            .unwrap();
        let d = st.read(&ctx).unwrap();
        for p in &d.pos {
            assert!(
                c.distance([p[0], p[1], p[2]]) > -1e-4,
                "step {step}: particle inside the moving sphere"
            );
        }
    }
    let d = st.read(&ctx).unwrap();
    assert_sane(&d, &scene, "moving collider");
    assert!(
        d.vel.iter().any(|v| v[0] > 0.5),
        "nothing was pushed along +x"
    );
    st.destroy(&ctx);
    let too_many = st.set_colliders(&vec![
        Collider::Plane {
            normal: [0.0, 1.0, 0.0],
            offset: 0.0,
            velocity: [0.0; 3]
        }
        .to_gpu()
        .unwrap();
        65
    ]);
    let msg = too_many.err().map(|e| e.to_string()).unwrap_or_default();
    assert!(msg.contains("at most 64"), "{msg}");
    solver.destroy(&ctx);
    common::finish(&ctx);
}

#[test]
fn bad_scenes_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("name = \"x\"\n[domain]\nmin = [0,0,0]\nmax = [1,1,1]\nbogus = 1\n", "unknown field"),
        ("name = \"x\"\n[domain]\nmin = [0,0,0]\nmax = [1,1,1]\n", "no fluid"),
        ("name = \"x\"\n[domain]\nmin = [0,0,0]\nmax = [1,1,1]\n[fluid]\nh = -1.0\n[[blocks]]\nmin=[0,0,0]\nmax=[1,1,1]\n", "fluid.h must be positive"),
        ("name = \"x\"\n[domain]\nmin = [0,0,0]\nmax = [0,1,1]\n[[blocks]]\nmin=[0,0,0]\nmax=[1,1,1]\n", "empty domain"),
        ("name = \"x\"\n[domain]\nmin = [0,0,0]\nmax = [1,1,1]\n[[blocks]]\nmin=[0,0,0]\nmax=[1,1,1]\n[[colliders]]\nkind = \"sphere\"\ncenter = [0,0,0]\nradius = 0.0\n", "radius must be positive"),
        ("this is not toml [", "scene file"),
    ];
    for (i, (text, needle)) in cases.iter().enumerate() {
        let p = dir.path().join(format!("bad{i}.toml"));
        std::fs::write(&p, text).unwrap();
        let e = Scene::load(p.to_str().unwrap()).unwrap_err().to_string();
        assert!(e.contains(needle), "case {i}: {e}");
    }
    let e = Scene::load("no/such/scene.toml").unwrap_err().to_string();
    assert!(e.contains("unknown scene"), "{e}");
    use fluidform::scene::load::{kind_of, SceneKind};
    let fluid = fluidform::scene::builtin::BUILT_IN
        .iter()
        .filter(|b| kind_of(b.text) == SceneKind::Fluid);
    for name in fluid.map(|b| b.name) {
        let mut s = Scene::built_in(name).unwrap();
        s.validate().unwrap();
        // A liquid character's [pool] becomes a block when the scene is fitted.
        fluidform::scene::fit::fit(&mut s).unwrap();
        // Every built-in has fluid, or a character alone.
        assert!(
            s.particles(1).len() > 1000 || (!s.has_fluid() && s.character.is_some()),
            "{name}"
        );
    }
    let dam = Scene::built_in("dam-break").unwrap();
    let n = dam.particles(1).len();
    assert!(
        (30_000..36_000).contains(&n),
        "dam break has {n} particles, meant 32K"
    );
}

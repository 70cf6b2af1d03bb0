//! A liquid character's scene fitted to its character (scene::fit): the spacing from the
//! thinnest part, and `[pool]` holding the asked multiple of the character's volume under
//! its first pose. Checked against the character's own numbers (inspect), on the CPU.
use fluidform::character::inspect::thinnest;
use fluidform::scene::fit::{fit, ACROSS, COARSEST, FINEST};
use fluidform::scene::Scene;

fn scene(dir: &std::path::Path, body: &str) -> fluidform::Result<Scene> {
    let path = dir.join("scene.toml");
    std::fs::write(&path, body).unwrap();
    Scene::load(path.to_str().unwrap())
}

const HEAD: &str = r#"
name = "fit"
[domain]
min = [-0.6, 0.0, -0.4]
max = [0.6, 1.3, 0.4]
[character]
file = "builtin:walker"
"#;

#[test]
fn spacing_and_pool_follow_the_character() {
    let dir = std::env::temp_dir().join("fluidform-fit-1");
    std::fs::create_dir_all(&dir).unwrap();
    let mut s = scene(
        &dir,
        &format!("{HEAD}height = 1.2\n[control]\n[pool]\nvolume = 1.5\n"),
    )
    .unwrap();
    let f = fit(&mut s).unwrap();
    let (ch, anim) = s.character.as_ref().unwrap().load().unwrap();
    let (lo, hi) = ch.rest_bounds().unwrap();
    let scale = 1.2 / (hi.y - lo.y);
    assert!((anim.placement.x_axis.length() - scale).abs() < 1e-4);
    let d = thinnest(&ch, glam::Mat3::IDENTITY)
        .unwrap()
        .unwrap()
        .diameter
        * scale;
    let want = (d / ACROSS).clamp(1.2 / FINEST, 1.2 / COARSEST);
    let (got, why) = f.spacing.clone().unwrap();
    assert!((got - want).abs() < 1e-6, "spacing {got} against {want}");
    assert!(why.contains("thinnest"), "{why}");
    let sp = s.fluid.spacing();
    assert!((sp - want).abs() < 1e-4 * want, "the fluid's spacing {sp}");
    // The pool: one block on the floor, under the walker, holding 1.5 times his volume
    // (to within one layer of particles).
    assert!(s.pool.is_none(), "the pool becomes a block");
    assert_eq!(s.blocks.len(), 1);
    let b = &s.blocks[0];
    assert_eq!(b.min[1], 0.0);
    assert!(b.min[0] < 0.0 && b.max[0] > 0.0 && b.min[2] < 0.0 && b.max[2] > 0.0);
    let n = s.particles(1).len() as f64;
    let (_, count) = f.pool.clone().unwrap();
    assert_eq!(count as f64, n, "the reported count is the lattice's");
    let vol = ch.check.signed_volume.abs() * (scale as f64).powi(3) * 1.5;
    let layer = ((b.max[0] - b.min[0]) * (b.max[2] - b.min[2]) * sp) as f64;
    let held = n * (sp as f64).powi(3);
    assert!(
        held >= vol - 1e-9 && held <= vol + layer,
        "pool holds {held} m^3 for {vol} (layer {layer})"
    );
    // Metaballs and control follow the spacing: h scaled with it.
    let d0 = fluidform::sph::FluidParams::default();
    assert!((s.fluid.h / d0.h - sp / d0.spacing()).abs() < 1e-3);
}

#[test]
fn a_given_spacing_stays_and_bad_pools_are_refused() {
    let dir = std::env::temp_dir().join("fluidform-fit-2");
    std::fs::create_dir_all(&dir).unwrap();
    let mut s = scene(&dir, &format!("{HEAD}[control]\n[fluid]\nspacing = 0.03\n[[blocks]]\nmin = [-0.6, 0.0, -0.4]\nmax = [0.6, 0.1, 0.4]\n")).unwrap();
    let f = fit(&mut s).unwrap();
    assert!(f.spacing.is_none() && f.pool.is_none());
    assert_eq!(s.fluid.spacing, Some(0.03), "the scene's spacing is kept");
    // A mass other than the default's says the spacing too.
    let mut s = scene(
        &dir,
        &format!("{HEAD}[control]\n[fluid]\nmass = 0.01\n[pool]\n"),
    )
    .unwrap();
    let f = fit(&mut s).unwrap();
    assert!(f.spacing.is_none() && f.pool.is_some());
    assert_eq!(s.fluid.mass, 0.01);
    // A pool deeper than the domain.
    let mut s = scene(&dir, &format!("{HEAD}[control]\n[pool]\nvolume = 19\n")).unwrap();
    let e = fit(&mut s).unwrap_err().to_string();
    assert!(e.contains("higher than the domain"), "{e}");
    let mut s = scene(&dir, &format!("{HEAD}[control]\n[pool]\nvolume = -1\n")).unwrap();
    let e = fit(&mut s).unwrap_err().to_string();
    assert!(e.contains("volume"), "{e}");
    // A pool needs the character it is sized from.
    let e = scene(
        &dir,
        "name = \"p\"\n[domain]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\n[pool]\n",
    )
    .and_then(|mut s| fit(&mut s).map(|_| ()))
    .unwrap_err()
    .to_string();
    assert!(e.contains("[pool]"), "{e}");
}

/// A scene with a character and no `[domain]` or `[camera]` (scene::around): the domain
/// holds the placed skin at every moment of its lap, off the sampled times too, stands on
/// the floor the character stands on, and the camera sees the whole of it.
#[test]
fn the_domain_and_camera_are_fitted_around_the_motion() {
    use fluidform::character::Skinning;
    use fluidform::scene::character::placed_matrices;
    let dir = std::env::temp_dir().join("fluidform-fit-3");
    std::fs::create_dir_all(&dir).unwrap();
    let body = "name = \"around\"\n[pool]\n[control]\n[character]\nfile = \"builtin:walker\"\nheight = 1.0\npath = [[-0.3, 0.1, -0.2], [0.3, 0.1, -0.2], [0.3, 0.1, 0.2], [-0.3, 0.1, 0.2]]\npath_speed = 0.5\n";
    let s = scene(&dir, body).unwrap();
    let (lo, hi) = (s.domain.min, s.domain.max);
    assert_eq!(lo[1], 0.1, "the floor is where the path stands");
    let desc = s.character.as_ref().unwrap();
    let (ch, anim) = desc.load().unwrap();
    let path = desc.path();
    let cam = s.camera.clone().expect("a fitted camera");
    let eye = glam::Vec3::from(cam.eye);
    let ahead = (glam::Vec3::from(cam.target) - eye).normalize();
    let half = (0.5 * cam.fov).to_radians();
    // The lap is 2 m at 0.5 m/s: 4 s, sampled at times between the fit's own samples.
    for k in 0..160 {
        let t = 0.0137 + k as f64 * 0.025;
        let mats = placed_matrices(&ch, &anim, desc.speed, path.as_ref(), t);
        for p in ch.skinned_at(&mats, Skinning::Lbs).unwrap().0 {
            for a in 0..3 {
                let below_floor = a == 1 && p[1] < lo[1];
                assert!(
                    below_floor || (p[a] >= lo[a] && p[a] <= hi[a]),
                    "t {t}: skin point {p} outside the domain {lo:?}..{hi:?}"
                );
            }
            let d = (p - eye).normalize();
            assert!(
                d.dot(ahead).clamp(-1.0, 1.0).acos() < half,
                "t {t}: {p} outside the camera's view"
            );
        }
    }
    // Fitted, the scene plays as one with a domain: its pool lies inside it.
    let mut s = s;
    fit(&mut s).unwrap();
    s.validate().unwrap();
    // Without a character there is nothing to fit a domain around.
    let e = scene(
        &dir,
        "name = \"none\"\n[[blocks]]\nmin = [0.0, 0.0, 0.0]\nmax = [0.1, 0.1, 0.1]\n",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("no [domain]"), "{e}");
}

/// A pool whose thinnest-part spacing would hold more than the budget's particles is
/// coarsened to about the budget (within a layer), and says so.
#[test]
fn the_spacing_keeps_the_pool_within_the_budget() {
    use fluidform::scene::fit::BUDGET;
    let dir = std::env::temp_dir().join("fluidform-fit-4");
    std::fs::create_dir_all(&dir).unwrap();
    let mut s = scene(
        &dir,
        &format!("{HEAD}height = 1.2\n[control]\n[pool]\nvolume = 6\n"),
    )
    .unwrap();
    let f = fit(&mut s).unwrap();
    let (sp, why) = f.spacing.clone().unwrap();
    assert!(
        why.contains("budget") || why.contains(&format!("{BUDGET}")),
        "{why}"
    );
    let (ch, _) = s.character.as_ref().unwrap().load().unwrap();
    let (lo, hi) = ch.rest_bounds().unwrap();
    let scale = 1.2 / (hi.y - lo.y);
    let d = thinnest(&ch, glam::Mat3::IDENTITY)
        .unwrap()
        .unwrap()
        .diameter
        * scale;
    assert!(
        sp > (d / ACROSS).clamp(1.2 / FINEST, 1.2 / COARSEST),
        "coarser than the thinnest part asks"
    );
    let n = s.particles(1).len() as f32;
    let b = &s.blocks[0];
    let layer = (b.max[0] - b.min[0]) * (b.max[2] - b.min[2]) / (sp * sp);
    assert!(
        n >= 0.95 * BUDGET && n <= BUDGET + layer + 1.0,
        "{n} particles (layer {layer})"
    );
}

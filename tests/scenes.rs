//! Built-in scenes are TOML files read by the same code as a user's: listed and shown by
//! `fluidform scene`, nested per concern, unknown keys refused with their path.
mod common;
use fluidform::scene::builtin::BUILT_IN;
use fluidform::scene::load::{kind_of, SceneKind};
use fluidform::scene::particles::ParticleScene;
use fluidform::scene::Scene;
use fluidform::sph::FluidParams;

#[test]
fn every_built_in_reads_back_from_its_shown_text_as_a_user_file() {
    let dir = tempfile::tempdir().unwrap();
    for b in BUILT_IN {
        // `scene show` prints the embedded text, which is the file in scenes/.
        let on_disk = std::fs::read_to_string(format!("scenes/{}.toml", b.name)).unwrap();
        assert_eq!(b.text, on_disk, "{}", b.name);
        let o = common::fluidform(&["scene", "show", b.name]);
        assert!(o.status.success(), "{}", common::text(&o));
        assert_eq!(String::from_utf8_lossy(&o.stdout), b.text, "{}", b.name);
        assert!(!b.summary().is_empty(), "{} has no opening comment", b.name);
        // Copied to a user's file, it loads as the same scene.
        let p = dir.path().join(format!("{}.toml", b.name));
        std::fs::write(&p, b.text).unwrap();
        let p = p.to_str().unwrap();
        match kind_of(b.text) {
            SceneKind::Fluid => {
                assert_eq!(Scene::load(p).unwrap(), Scene::built_in(b.name).unwrap());
                assert!(ParticleScene::find(b.name).unwrap().is_none(), "{}", b.name);
            }
            SceneKind::Particles => {
                let file = ParticleScene::find(p).unwrap().unwrap();
                assert_eq!(file, ParticleScene::built_in(b.name).unwrap());
                assert!(Scene::built_in(b.name).is_err(), "{}", b.name);
            }
        }
    }
}

#[test]
fn scene_list_names_every_built_in_and_show_refuses_unknown_names() {
    let o = common::fluidform(&["scene", "list"]);
    assert!(o.status.success(), "{}", common::text(&o));
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    for b in BUILT_IN {
        let line = out
            .lines()
            .find(|l| l.split_whitespace().next() == Some(b.name));
        let line = line.unwrap_or_else(|| panic!("{} not listed:\n{out}", b.name));
        assert!(line.contains(&b.summary()), "{line}");
    }
    assert!(out.lines().any(|l| l.starts_with("orbits")), "{out}");
    for name in ["nope", "orbits"] {
        let o = common::fluidform(&["scene", "show", name]);
        assert!(!o.status.success());
        let t = common::text(&o);
        assert_eq!(t.trim().lines().count(), 1, "{t}");
        assert!(t.contains(name), "{t}");
    }
}

#[test]
fn unknown_keys_are_refused_with_their_path_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let head = "name = \"t\"\n[domain]\nmin = [0, 0, 0]\nmax = [1, 1, 1]\n";
    let cases = [
        ("[fluid.dfsph]\nnope = 1\n", "fluid.dfsph.nope", "line 6"),
        (
            "[fluid]\nneighbor_list = 4\n",
            "fluid.neighbor_list",
            "line 6",
        ),
        ("[look]\ncolour = \"red\"\n", "look.colour", "line 6"),
        (
            "[[blocks]]\nmin = [0, 0, 0]\nmax = [1, 1, 1]\nvelocty = [0, 0, 0]\n",
            "blocks[0].velocty",
            "line 8",
        ),
    ];
    for (i, (tail, path, line)) in cases.iter().enumerate() {
        let p = dir.path().join(format!("bad{i}.toml"));
        std::fs::write(&p, format!("{head}{tail}")).unwrap();
        let e = Scene::load(p.to_str().unwrap()).unwrap_err().to_string();
        assert!(e.contains(path) && e.contains(line), "case {i}: {e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}

#[test]
fn fluid_overrides_reach_each_solvers_table() {
    let f = FluidParams::default();
    let o = |args: &[&str]| {
        let a: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        f.with_overrides(&a, None)
    };
    // A dotted key sets one table; the flat names keep their earlier meaning.
    let g = o(&["dfsph.neighbor_list=32", "pbf.xsph=0.05"]).unwrap();
    assert_eq!((g.dfsph.neighbor_list, g.pbf.xsph), (32, 0.05));
    assert_eq!(g.pcisph, f.pcisph);
    let g = o(&["density_error=0.002", "max_iterations=7"]).unwrap();
    for (e, max) in [
        (g.pcisph.density_error, g.pcisph.max_iterations),
        (g.dfsph.density_error, g.dfsph.max_iterations),
        (g.pbf.density_error, g.pbf.max_iterations),
    ] {
        assert_eq!((e, max), (0.002, 7));
    }
    let g = o(&["pbf_iterations=4", "neighbor_list=0", "vorticity=0"]).unwrap();
    assert_eq!(
        (g.pbf.iterations, g.dfsph.neighbor_list, g.pbf.vorticity),
        (4, 0, 0.0)
    );
    // Out of range, unknown, or through a value that is not a table: one-line errors
    // naming the key.
    for (args, needle) in [
        (
            &["dfsph.neighbor_list=1000"][..],
            "fluid.dfsph.neighbor_list",
        ),
        (&["pcisph.min_iterations=0"][..], "fluid.pcisph"),
        (&["dfsph.nope=1"][..], "nope"),
        (&["h.x=1"][..], "fluid.h is not a table"),
    ] {
        let e = o(args).unwrap_err().to_string();
        assert!(e.contains(needle), "{args:?}: {e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}

/// Choosing a solver gives its own step (its table's cfl and dt_max); an explicit value in
/// [fluid], its table or --fluid wins, each on its own; wcsph keeps the fixed step.
#[test]
fn each_solver_takes_its_own_step_unless_told_otherwise() {
    use fluidform::sph::Solver;
    let f = FluidParams::default();
    let o = |args: &[&str], s: Option<Solver>| {
        let a: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        f.with_overrides(&a, s).unwrap()
    };
    let w = o(&[], None);
    assert_eq!((w.solver, w.cfl, w.dt_max), (Solver::Wcsph, None, None));
    assert!(
        w.describe_step().contains("fixed steps"),
        "{}",
        w.describe_step()
    );
    for (s, cfl, own) in [
        (Solver::Pcisph, f.pcisph.cfl, f.pcisph.dt_max),
        (Solver::Dfsph, f.dfsph.cfl, f.dfsph.dt_max),
        (Solver::Pbf, f.pbf.cfl, f.pbf.dt_max),
    ] {
        // The own CFL numbers (of the cubic's 2 spacings for PCISPH and DFSPH).
        let want = match s {
            Solver::Pcisph => 0.05,
            Solver::Dfsph => 0.15,
            _ => 0.2,
        };
        assert_eq!(cfl, want, "{s:?}");
        let g = o(&[], Some(s));
        assert_eq!((g.cfl, g.dt_max), (Some(cfl), Some(own)), "{s:?}");
        let line = g.describe_step();
        assert!(
            line.contains(&format!("CFL {cfl}")) && line.contains("0.1%"),
            "{line}"
        );
        // The table's values, then explicit ones, each on its own.
        let g = o(
            &[&format!("{}.dt_max=0.003", format!("{s:?}").to_lowercase())],
            Some(s),
        );
        assert_eq!((g.cfl, g.dt_max), (Some(cfl), Some(0.003)), "{s:?}");
        let g = o(&["cfl=0.3"], Some(s));
        assert_eq!((g.cfl, g.dt_max), (Some(0.3), Some(own)), "{s:?}");
        let g = o(&["dt_max=0.001"], Some(s));
        assert_eq!((g.cfl, g.dt_max), (Some(cfl), Some(0.001)), "{s:?}");
    }
    // cfl 0 in the table: fixed steps.
    let g = o(&["dfsph.cfl=0"], Some(Solver::Dfsph));
    assert_eq!((g.cfl, g.dt_max), (None, None));
    assert!(
        g.describe_step().contains("fixed steps"),
        "{}",
        g.describe_step()
    );
    // A scene file's solver gets the same.
    let d = FluidParams {
        solver: Solver::Dfsph,
        ..FluidParams::default()
    };
    let g = d.with_overrides(&[], None).unwrap();
    assert_eq!((g.cfl, g.dt_max), (Some(f.dfsph.cfl), Some(f.dfsph.dt_max)));
    // wcsph with dt_max alone is still refused.
    let e = f
        .with_overrides(&["dt_max=0.001".to_string()], None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("needs a CFL-limited step"), "{e}");
}

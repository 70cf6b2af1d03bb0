//! A character whose bind pose is wider than its clip (a T-pose whose arm hangs down in
//! the clip): the fitted domain and the control check follow one rule, the poses that
//! play. It plays, its control particles inside the domain on every frame; a clip that
//! truly leaves a user-given domain is refused in one line naming the frame and joint.
mod common;
use common::gltf::{cube, Doc};
use fluidform::character::Skinning;
use fluidform::control::target::Bound;
use fluidform::scene::character::placed_matrices;
use fluidform::scene::Scene;
use glam::{Mat4, Quat, Vec3};
use serde_json::json;

/// A body (0.3 x 1 x 0.2 m on the root joint) and an arm held straight out to x = 0.85
/// in the bind pose (on joint 'arm' at the shoulder, (0.15, 0.9, 0)); its clip 'hang'
/// swings the arm down, from 100 degrees below the horizontal (towards the body) at 0 s
/// to 80 degrees at 1 s (its tip out to x = 0.33).
fn t_pose() -> serde_json::Value {
    let (unit, idx) = cube();
    let boxed = |lo: [f32; 3], hi: [f32; 3]| -> Vec<[f32; 3]> {
        unit.iter()
            .map(|u| [0, 1, 2].map(|k| lo[k] + u[k] * (hi[k] - lo[k])))
            .collect()
    };
    let mut pos = boxed([-0.15, 0.0, -0.1], [0.15, 1.0, 0.1]);
    pos.extend(boxed([0.15, 0.84, -0.06], [0.85, 0.96, 0.06]));
    let mut ind = idx.clone();
    ind.extend(idx.iter().map(|i| i + 8));
    let mut d = Doc::default();
    let p = d.vec3(&pos);
    let joints = d.joints(
        &(0..16)
            .map(|v| [(v >= 8) as u16, 0, 0, 0])
            .collect::<Vec<_>>(),
    );
    let weights = d.vec4(&[[1.0, 0.0, 0.0, 0.0]; 16]);
    let ind = d.indices(&ind);
    let ibm = d.mat4(&[
        Mat4::IDENTITY,
        Mat4::from_translation(-Vec3::new(0.15, 0.9, 0.0)),
    ]);
    let times = d.scalars(&[0.0, 1.0]);
    let down = |deg: f32| Quat::from_rotation_z(-deg.to_radians()).to_array();
    let rot = d.vec4(&[down(100.0), down(80.0)]);
    d.finish(json!({
        "scene": 0, "scenes": [{"nodes": [0, 2]}],
        "nodes": [
            {"name": "hips", "children": [1]},
            {"name": "arm", "translation": [0.15, 0.9, 0.0]},
            {"name": "body", "mesh": 0, "skin": 0}
        ],
        "skins": [{"joints": [0, 1], "inverseBindMatrices": ibm}],
        "meshes": [{"primitives": [{
            "attributes": {"POSITION": p, "JOINTS_0": joints, "WEIGHTS_0": weights},
            "indices": ind
        }]}],
        "animations": [{
            "name": "hang",
            "samplers": [{"input": times, "output": rot, "interpolation": "LINEAR"}],
            "channels": [{"sampler": 0, "target": {"node": 1, "path": "rotation"}}]
        }]
    }))
}

/// The five-line scene of the T-pose file in `dir`, with `extra` lines.
fn scene(dir: &std::path::Path, extra: &str) -> std::path::PathBuf {
    common::gltf::write(dir, "tpose.gltf", &t_pose());
    let path = dir.join("tpose.toml");
    let body = format!(
        "name = \"tpose\"\nframes = 90\n{extra}[character]\nfile = \"tpose.gltf\"\nanimation = \"hang\"\n[pool]\n[control]\n"
    );
    std::fs::write(&path, body).unwrap();
    path
}

fn run(path: &std::path::Path, out: &std::path::Path) -> std::process::Output {
    common::fluidform(&[
        "run",
        "--scene",
        path.to_str().unwrap(),
        "--frames",
        "3",
        "--render",
        "points",
        "--width",
        "64",
        "--height",
        "64",
        "--validation",
        "--out",
        out.to_str().unwrap(),
    ])
}

#[test]
fn a_bind_pose_wider_than_its_clip_plays_inside_its_fitted_domain() {
    let dir = tempfile::tempdir().unwrap();
    let path = scene(dir.path(), "");
    let s = Scene::load(path.to_str().unwrap()).unwrap();
    let (lo, hi) = (Vec3::from(s.domain.min), Vec3::from(s.domain.max));
    let desc = s.character.clone().unwrap();
    let (ch, anim) = desc.load().unwrap();
    let control = s.control.clone().unwrap();
    let bound = Bound::new(&ch, &anim, &control, &s.fluid, 1)
        .unwrap()
        .expect("particles placed in the bind pose");
    // The bind pose's particles reach past the fitted domain (the arm held out)...
    let rest_hi = bound
        .mesh
        .positions
        .iter()
        .fold(Vec3::splat(f32::MIN), |a, p| a.max(*p));
    assert!(rest_hi.x > hi.x, "bind pose {rest_hi} inside {lo}..{hi}");
    // ...and every frame's stay inside it: the same particles skinned to the clip (at
    // k frames' time; the run's clock sums its steps, a few ulps off).
    let frame_s = s.fluid.dt as f64 * s.fluid.substeps as f64;
    let ulps = Vec3::splat(1e-5);
    for k in 0..s.frames {
        let t = k as f64 * frame_s;
        let mats = placed_matrices(&ch, &anim, desc.speed, desc.path().as_ref(), t);
        for p in bound.at(&ch, (&mats, &[]), Skinning::Lbs).unwrap() {
            assert!(
                p.cmpge(lo - ulps).all() && p.cmple(hi + ulps).all(),
                "frame {k}: {p} outside {lo}..{hi}"
            );
        }
    }
    // It plays.
    let out = dir.path().join("out");
    let r = run(&path, &out);
    assert!(r.status.success(), "{}", common::text(&r));
}

#[test]
fn a_clip_leaving_a_given_domain_is_refused_by_frame_and_joint() {
    let dir = tempfile::tempdir().unwrap();
    // The character is centred on its bind pose (x shifted by -0.35): the body fits, and
    // the arm swings out past x = 0.05 + a tenth of its height towards the clip's end.
    let path = scene(
        dir.path(),
        "[domain]\nmin = [-0.9, 0.0, -0.6]\nmax = [0.05, 1.4, 0.6]\n",
    );
    let r = run(&path, &dir.path().join("out"));
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    let line = err
        .lines()
        .find(|l| l.contains("outside the domain"))
        .unwrap_or_else(|| panic!("{err}"));
    assert!(line.contains("joint 'arm'"), "{line}");
    assert!(line.contains("x = "), "{line}");
    assert!(line.contains("widen the scene's [domain]"), "{line}");
    // Not the first frame (the arm starts swung in): a later one.
    let frame: u64 = line
        .split("(frame ")
        .nth(1)
        .and_then(|r| r.split(')').next())
        .and_then(|f| f.parse().ok())
        .unwrap_or_else(|| panic!("{line}"));
    assert!(frame > 0, "{line}");
}

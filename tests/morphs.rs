//! Morph targets and several skins, on generated glTF files: the loader, the CPU reference
//! against hand-computed values, the GPU skinning pass against the CPU reference, what
//! `inspect` lists, and bad morph accessors refused.
mod common;
#[path = "morphs_files/control.rs"]
mod control;
use common::gltf::{cube, write, Doc};
use fluidform::character::skin::Skinner;
use fluidform::character::{self, inspect, Animator, Character, Skinning};
use fluidform::gpu::Context;
use glam::{Mat4, Quat, Vec3};
use serde_json::json;

const SMILE: [f32; 3] = [0.5, 0.0, 0.0];
const BLINK: [f32; 3] = [0.0, 0.0, 0.25];

/// A cube skinned to two joints (bottom corners to `hips`, top to `spine`, one up), with
/// two morph targets ('Smile' moves the top corners along x, 'Blink' the bottom ones along
/// z and tilts their normals), default weights (0.2, 0), and a clip that turns the spine
/// 90 degrees about y and takes the weights from (0, 0) to (1, 0.5) over a second.
/// `blink_count`: the vertices 'Blink's POSITION accessor claims (8 is right).
fn morph_cube(blink_count: usize) -> serde_json::Value {
    morph_cube_with(blink_count, |_| {})
}

/// The same with its triangle list changed by `edit` (reversed, a face removed).
fn morph_cube_with(blink_count: usize, edit: impl Fn(&mut Vec<u16>)) -> serde_json::Value {
    let (p, mut idx) = cube();
    edit(&mut idx);
    let top = |v: &[f32; 3]| v[1] > 0.5;
    let mut d = Doc::default();
    let pos = d.vec3(&p);
    let nrm = d.vec3(&[[0.0, 1.0, 0.0]; 8]);
    let joints = d.joints(
        &p.iter()
            .map(|v| [top(v) as u16, 0, 0, 0])
            .collect::<Vec<_>>(),
    );
    let weights = d.vec4(&[[1.0, 0.0, 0.0, 0.0]; 8]);
    let ind = d.indices(&idx);
    let smile = d.vec3(
        &p.iter()
            .map(|v| if top(v) { SMILE } else { [0.0; 3] })
            .collect::<Vec<_>>(),
    );
    let blink: Vec<[f32; 3]> = p
        .iter()
        .map(|v| if top(v) { [0.0; 3] } else { BLINK })
        .collect();
    let blink = d.vec3(
        &blink[..blink_count.min(8)]
            .iter()
            .chain(&vec![BLINK; blink_count.saturating_sub(8)])
            .copied()
            .collect::<Vec<_>>(),
    );
    let blink_n = d.vec3(&[[0.0, 0.0, 0.1]; 8]);
    let ibm = d.mat4(&[Mat4::IDENTITY, Mat4::from_translation(-Vec3::Y)]);
    let times = d.scalars(&[0.0, 1.0]);
    let turn = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
    let rot = d.vec4(&[[0.0, 0.0, 0.0, 1.0], turn.to_array()]);
    let w = d.scalars(&[0.0, 0.0, 1.0, 0.5]);
    d.finish(json!({
        "scene": 0, "scenes": [{"nodes": [0, 2]}],
        "nodes": [
            {"name": "hips", "children": [1]},
            {"name": "spine", "translation": [0, 1, 0]},
            {"name": "body", "mesh": 0, "skin": 0}
        ],
        "skins": [{"joints": [0, 1], "inverseBindMatrices": ibm}],
        "meshes": [{
            "primitives": [{
                "attributes": {"POSITION": pos, "NORMAL": nrm, "JOINTS_0": joints, "WEIGHTS_0": weights},
                "indices": ind,
                "targets": [{"POSITION": smile}, {"POSITION": blink, "NORMAL": blink_n}]
            }],
            "weights": [0.2, 0.0],
            "extras": {"targetNames": ["Smile", "Blink"]}
        }],
        "animations": [{
            "name": "wave",
            "samplers": [
                {"input": times, "output": rot, "interpolation": "LINEAR"},
                {"input": times, "output": w, "interpolation": "LINEAR"}
            ],
            "channels": [
                {"sampler": 0, "target": {"node": 1, "path": "rotation"}},
                {"sampler": 1, "target": {"node": 2, "path": "weights"}}
            ]
        }]
    }))
}

fn anim(ch: &Character) -> Animator {
    Animator {
        clip: (!ch.clips.is_empty()).then_some(0),
        looping: false,
        placement: Mat4::IDENTITY,
    }
}

/// The GPU's skinned positions for `ch` at clip time `t`, and the largest distance from the
/// CPU reference's.
fn gpu_against_cpu(ctx: &Context, ch: &Character, method: Skinning, t: f32) -> f32 {
    let a = anim(ch);
    let mats = a.joint_matrices(ch, t);
    let weights = a.morph_weights(ch, t);
    let joints = ch.gpu_joints(&mats, method).unwrap();
    let mut sk = Skinner::new(ctx, ch, method).unwrap();
    let (gpu, _) = common::skin_on_gpu(ctx, &sk, &joints, &weights);
    sk.destroy(ctx);
    let (cpu, _) = ch.skinned_with(&mats, &weights, method).unwrap();
    (gpu.iter().zip(&cpu))
        .map(|(g, c)| (Vec3::from_slice(&g[..3]) - *c).length())
        .fold(0.0, f32::max)
}

#[test]
fn morph_targets_load_animate_and_skin_as_by_hand() {
    let dir = tempfile::tempdir().unwrap();
    let ch = character::load(&write(dir.path(), "morph.gltf", &morph_cube(8))).unwrap();
    assert!(!ch.flipped, "the generated cube faces outward");
    let m = &ch.mesh.morphs;
    let names: Vec<&str> = m.targets.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names, ["Smile", "Blink"]);
    assert_eq!(m.defaults(), [0.2, 0.0]);
    assert!(!m.targets[0].normals && m.targets[1].normals);
    // The clip's weights, linear between its keys; the defaults without a clip.
    let a = anim(&ch);
    assert_eq!(a.morph_weights(&ch, 0.5), [0.5, 0.25]);
    assert_eq!(a.morph_weights(&ch, 2.0), [1.0, 0.5]);
    let rest = Animator {
        clip: None,
        ..a.clone()
    };
    assert_eq!(rest.morph_weights(&ch, 0.5), [0.2, 0.0]);
    // The rest pose carries the default weights: top corners 0.2 x SMILE along.
    let p = ch.rest_positions().unwrap();
    let (base, _) = (cube().0, ());
    for (v, b) in base.iter().enumerate() {
        let b = Vec3::from(*b);
        let want = if b.y > 0.5 {
            b + 0.2 * Vec3::from(SMILE)
        } else {
            b
        };
        assert!(
            (p[v] - want).length() < 1e-6,
            "rest vertex {v}: {} vs {want}",
            p[v]
        );
    }
    // Mid-clip by hand: weights (0.5, 0.25), the spine turned 45 degrees about y about its
    // joint at y = 1; the bottom corners stay with the hips.
    let mats = a.joint_matrices(&ch, 0.5);
    let w = a.morph_weights(&ch, 0.5);
    let (cp, cn) = ch.skinned_with(&mats, &w, Skinning::Lbs).unwrap();
    let spine = Mat4::from_translation(Vec3::Y)
        * Mat4::from_quat(Quat::from_rotation_y(std::f32::consts::FRAC_PI_4))
        * Mat4::from_translation(-Vec3::Y);
    for (v, b) in base.iter().enumerate() {
        let b = Vec3::from(*b);
        let want = match b.y > 0.5 {
            true => spine.transform_point3(b + 0.5 * Vec3::from(SMILE)),
            false => b + 0.25 * Vec3::from(BLINK),
        };
        assert!(
            (cp[v] - want).length() < 1e-5,
            "vertex {v} at 0.5 s: {} vs {want}",
            cp[v]
        );
        // Blink's normal offsets (every corner's) tilt the normals toward z; the top ones
        // then turn with the spine.
        let n = (Vec3::Y + 0.25 * Vec3::new(0.0, 0.0, 0.1)).normalize();
        let n = match b.y > 0.5 {
            true => spine.transform_vector3(n),
            false => n,
        };
        assert!((cn[v] - n).length() < 1e-5, "normal {v}: {} vs {n}", cn[v]);
    }
    // The GPU pass against the CPU reference, both methods, three times.
    let ctx = common::ctx();
    for method in [Skinning::Lbs, Skinning::Dqs] {
        for t in [0.0, 0.5, 1.0] {
            let e = gpu_against_cpu(&ctx, &ch, method, t);
            assert!(e < 1e-5, "{method:?} at {t} s: {e}");
        }
    }
    common::finish(&ctx);
    // inspect lists the targets and the clip that drives them.
    let report = inspect::inspect(&ch, character::anim::Up::Y, false).unwrap();
    let text = report.text();
    assert!(
        text.contains("'Smile' of node 'body', default 0.2, normals kept; driven by wave"),
        "{text}"
    );
    assert!(
        text.contains("'Blink' of node 'body', default 0, normals follow; driven by wave"),
        "{text}"
    );
    assert!(text.contains("2 morph targets"), "{text}");
}

#[test]
fn a_morph_target_with_a_wrong_count_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let e = character::load(&write(dir.path(), "bad.gltf", &morph_cube(7)))
        .expect_err("7 offsets for 8 vertices must be refused")
        .to_string();
    assert_eq!(e.lines().count(), 1, "{e}");
    for needle in [
        "bad.gltf",
        "morph target 1 POSITION",
        "7 entries for 8 vertices",
    ] {
        assert!(e.contains(needle), "'{needle}' in: {e}");
    }
}

/// Two cubes, each skinned by its own skin to its own joint ('left' moves +x over the
/// clip, 'right' turns 90 degrees about y), and a third cube unskinned under 'left'.
fn two_skins() -> serde_json::Value {
    let (p, idx) = cube();
    let mut d = Doc::default();
    let pos = d.vec3(&p);
    let joints = d.joints(&[[0, 0, 0, 0]; 8]);
    let weights = d.vec4(&[[1.0, 0.0, 0.0, 0.0]; 8]);
    let ind = d.indices(&idx);
    let ibm_l = d.mat4(&[Mat4::from_translation(Vec3::new(2.0, 0.0, 0.0))]);
    let ibm_r = d.mat4(&[Mat4::from_translation(Vec3::new(-2.0, 0.0, 0.0))]);
    let times = d.scalars(&[0.0, 1.0]);
    let moves = d.vec3(&[[-2.0, 0.0, 0.0], [-1.0, 0.0, 0.0]]);
    let turn = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
    let turns = d.vec4(&[[0.0, 0.0, 0.0, 1.0], turn.to_array()]);
    let prim = json!({"attributes": {"POSITION": pos, "JOINTS_0": joints, "WEIGHTS_0": weights}, "indices": ind});
    let plain = json!({"attributes": {"POSITION": pos}, "indices": ind});
    d.finish(json!({
        "scene": 0, "scenes": [{"nodes": [0, 1, 2, 3]}],
        "nodes": [
            {"name": "left", "translation": [-2, 0, 0], "children": [4]},
            {"name": "right", "translation": [2, 0, 0]},
            {"name": "left body", "mesh": 0, "skin": 0},
            {"name": "right body", "mesh": 0, "skin": 1},
            {"name": "hat", "mesh": 1, "translation": [0, 3, 0]}
        ],
        "skins": [
            {"name": "L", "joints": [0], "inverseBindMatrices": ibm_l},
            {"name": "R", "joints": [1], "inverseBindMatrices": ibm_r}
        ],
        "meshes": [{"primitives": [prim]}, {"primitives": [plain]}],
        "animations": [{
            "name": "go",
            "samplers": [
                {"input": times, "output": moves, "interpolation": "LINEAR"},
                {"input": times, "output": turns, "interpolation": "LINEAR"}
            ],
            "channels": [
                {"sampler": 0, "target": {"node": 0, "path": "translation"}},
                {"sampler": 1, "target": {"node": 1, "path": "rotation"}}
            ]
        }]
    }))
}

#[test]
fn two_skins_place_their_own_parts() {
    let dir = tempfile::tempdir().unwrap();
    let ch = character::load(&write(dir.path(), "two.gltf", &two_skins())).unwrap();
    let placed: Vec<&str> = ch.parts.iter().map(|p| p.placed_by.as_str()).collect();
    assert_eq!(
        placed,
        [
            "skin 0 'L' (1 joints)",
            "skin 1 'R' (1 joints)",
            "rigid, follows its node"
        ]
    );
    assert!(ch.parts.iter().all(|p| p.closed() && p.triangles == 12));
    // At the clip's end, by hand: the left skin's cube moved +1 in x from where it was
    // bound, the right one turned 90 degrees about its joint, the hat rode on 'left'.
    let a = anim(&ch);
    let (cp, _) = ch
        .skinned_at(&a.joint_matrices(&ch, 1.0), Skinning::Lbs)
        .unwrap();
    let turn = Mat4::from_translation(Vec3::new(2.0, 0.0, 0.0))
        * Mat4::from_quat(Quat::from_rotation_y(std::f32::consts::FRAC_PI_2))
        * Mat4::from_translation(Vec3::new(-2.0, 0.0, 0.0));
    for (v, b) in cube().0.iter().enumerate() {
        let b = Vec3::from(*b);
        let wants = [
            b + Vec3::X,
            turn.transform_point3(b),
            b + Vec3::new(-1.0, 3.0, 0.0),
        ];
        for (k, want) in wants.into_iter().enumerate() {
            let got = cp[8 * k + v];
            assert!(
                (got - want).length() < 1e-5,
                "part {k} vertex {v}: {got} vs {want}"
            );
        }
    }
    let ctx = common::ctx();
    for t in [0.0, 0.5, 1.0] {
        let e = gpu_against_cpu(&ctx, &ch, Skinning::Lbs, t);
        assert!(e < 1e-5, "two skins at {t} s: {e}");
    }
    common::finish(&ctx);
    let text = inspect::inspect(&ch, character::anim::Up::Y, false)
        .unwrap()
        .text();
    for needle in [
        "'left body' (mesh 'mesh0'): 1 primitives, 12 triangles, skin 0 'L'",
        "'right body'",
        "'hat' (mesh 'mesh1')",
    ] {
        assert!(text.contains(needle), "'{needle}' in:\n{text}");
    }
}

#[test]
fn an_inward_cube_is_flipped_with_its_morph_normals_closed_or_open() {
    let dir = tempfile::tempdir().unwrap();
    let load = |name: &str, doc: serde_json::Value| {
        character::load(&write(dir.path(), name, &doc)).unwrap()
    };
    let plain = load("plain.gltf", morph_cube(8));
    let reverse = |i: &mut Vec<u16>| i.chunks_exact_mut(3).for_each(|t| t.swap(1, 2));
    // Inward and closed (by its signed volume), and inward with one face missing (open: by
    // its winding number behind its triangles).
    let closed = load("inward.gltf", morph_cube_with(8, reverse));
    let open = load(
        "inward_open.gltf",
        morph_cube_with(8, |i| {
            reverse(i);
            i.truncate(i.len() - 6);
        }),
    );
    let flags = (plain.flipped, closed.flipped, open.flipped);
    assert_eq!(
        flags,
        (false, true, true),
        "{:?} {:?}",
        closed.warnings,
        open.warnings
    );
    assert!(!open.check.closed(), "{:?}", open.check);
    assert!(
        open.warnings
            .iter()
            .any(|w| w.contains("open mesh faced inward")),
        "{:?}",
        open.warnings
    );
    // Flipped normals are the plain file's turned around, morph offsets included.
    let a = anim(&plain);
    let (mats, w) = (a.joint_matrices(&plain, 0.5), a.morph_weights(&plain, 0.5));
    let (_, n0) = plain.skinned_with(&mats, &w, Skinning::Lbs).unwrap();
    for ch in [&closed, &open] {
        let (_, n1) = ch.skinned_with(&mats, &w, Skinning::Lbs).unwrap();
        for (v, (a, b)) in n0.iter().zip(&n1).enumerate() {
            assert!((*a + *b).length() < 1e-5, "normal {v}: {a} vs {b}");
        }
    }
}

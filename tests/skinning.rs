//! GPU skinning (LBS and DQS) against the CPU reference, on CesiumMan at three times and
//! on a mesh with eight influences per vertex.
mod common;
use common::asset;
use fluidform::character::skin::{SkinnedMesh, Skinner};
use fluidform::character::Skinning;
use fluidform::character::{self, Animator, Character};
use fluidform::gpu::Context;
use glam::{Mat4, Vec3};
use rand::{Rng, SeedableRng};

/// Skin on the GPU; the largest position error relative to the mesh size, and the largest
/// normal error, against the CPU reference. Each vertex carries a tag in its rest position's
/// w (the control particles' fill of the shape), which must come out unchanged.
fn compare(ctx: &Context, ch: &Character, method: Skinning, t: f32) -> (f32, f32) {
    let anim = Animator {
        clip: (!ch.clips.is_empty()).then_some(0),
        looping: true,
        placement: Mat4::IDENTITY,
    };
    let mats = anim.joint_matrices(ch, t);
    let joints = ch.gpu_joints(&mats, method).unwrap();
    let weights = anim.morph_weights(ch, t);
    let tags: Vec<f32> = (0..ch.mesh.vertices())
        .map(|v| 0.5 + (v % 7) as f32 / 16.0)
        .collect();
    let plain = Skinner::new(ctx, ch, method).unwrap();
    let mesh = SkinnedMesh::tagged(ctx, &ch.mesh, ch.skeleton.joints.len(), Some(&tags)).unwrap();
    let mut sk = Skinner {
        pass: plain.pass,
        mesh,
    };
    let mut unused = plain.mesh;
    unused.destroy(ctx);
    let (pos, nrm) = common::skin_on_gpu(ctx, &sk, &joints, &weights);
    sk.destroy(ctx);
    for (v, p) in pos.iter().enumerate() {
        assert_eq!(p[3], tags[v], "{method:?}: vertex {v}'s tag");
    }
    let (cp, cn) = ch.skinned_with(&mats, &weights, method).unwrap();
    let (lo, hi) = character::check::bounds(&cp);
    let size = (hi - lo).length();
    let mut e = (0f32, 0f32);
    for v in 0..cp.len() {
        let g = Vec3::from_slice(&pos[v][..3]);
        e.0 = e.0.max((g - cp[v]).length() / size);
        e.1 = e.1.max((Vec3::from_slice(&nrm[v][..3]) - cn[v]).length());
    }
    e
}

#[test]
fn gpu_skinning_matches_the_cpu_reference() {
    let ctx = common::ctx();
    let ch = character::load(&asset("CesiumMan.glb")).unwrap();
    for method in [Skinning::Lbs, Skinning::Dqs] {
        for t in [0.0, 0.5, 1.3] {
            let (p, n) = compare(&ctx, &ch, method, t);
            assert!(
                p <= 1e-5,
                "{method:?} t = {t}: position error {p} of the size"
            );
            assert!(n <= 1e-4, "{method:?} t = {t}: normal error {n}");
        }
    }
    common::finish(&ctx);
}

#[test]
fn eight_influences_and_dqs_against_lbs() {
    let ctx = common::ctx();
    // The walker with eight random influences per vertex (JOINTS_1/WEIGHTS_1's path).
    let mut ch = character::load("builtin:walker").unwrap();
    let joints = ch.skeleton.joints.len() as u16;
    let mut rng = rand_pcg::Pcg32::seed_from_u64(7);
    for (j, w) in ch.mesh.joints.iter_mut().zip(&mut ch.mesh.weights) {
        let mut pairs: Vec<(u16, f32)> = (0..8)
            .map(|_| (rng.random_range(0..joints), rng.random_range(0.01..1.0)))
            .collect();
        pairs.sort_by(|a, b| b.1.total_cmp(&a.1));
        let sum: f32 = pairs.iter().map(|p| p.1).sum();
        for (k, (id, wt)) in pairs.into_iter().enumerate() {
            j[k] = id;
            w[k] = wt / sum;
        }
    }
    ch.mesh.influence_sets = 2;
    for method in [Skinning::Lbs, Skinning::Dqs] {
        let (p, n) = compare(&ctx, &ch, method, 0.37);
        assert!(p <= 1e-5 && n <= 1e-4, "{method:?}: {p} {n}");
    }
    // Rigid motion (one influence each): both methods give the same mesh.
    let rigid = character::load("builtin:walker").unwrap();
    let anim = Animator {
        clip: Some(0),
        looping: true,
        placement: glam::Mat4::from_scale(Vec3::splat(2.0)),
    };
    let mats = anim.joint_matrices(&rigid, 0.25);
    let mut one = rigid.clone();
    for (j, w) in one.mesh.joints.iter_mut().zip(&mut one.mesh.weights) {
        *w = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        j[1] = 0;
    }
    let (l, _) = one.skinned_at(&mats, Skinning::Lbs).unwrap();
    let (d, _) = one.skinned_at(&mats, Skinning::Dqs).unwrap();
    let worst = l
        .iter()
        .zip(&d)
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0, f32::max);
    assert!(
        worst < 1e-5,
        "uniformly scaled rigid joints: LBS and DQS differ by {worst}"
    );
    common::finish(&ctx);
}

#[test]
fn dqs_refuses_a_mirroring_joint() {
    let ch = character::load("builtin:walker").unwrap();
    let anim = Animator {
        clip: None,
        looping: true,
        placement: Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)),
    };
    let mats = anim.joint_matrices(&ch, 0.0);
    let e = ch.gpu_joints(&mats, Skinning::Dqs).unwrap_err().to_string();
    assert!(
        e.contains("determinant") && e.contains("--skinning lbs") && e.lines().count() == 1,
        "{e}"
    );
    assert!(ch.gpu_joints(&mats, Skinning::Lbs).is_ok());
}

#[test]
fn polar_split_at_any_scale_and_collapsed_joints() {
    use fluidform::character::pose::polar;
    let r = glam::Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0);
    for s in [1e-7f32, 1e-3, 1.0, 250.0] {
        let stretch = glam::Mat3::from_diagonal(Vec3::new(s, 2.0 * s, 0.5 * s));
        let a = glam::Mat3::from_quat(r) * stretch;
        let (rr, ss) = polar(a).expect("converges");
        let q = glam::Quat::from_mat3(&rr);
        assert!(
            q.angle_between(r) < 1e-4,
            "scale {s}: rotation off by {}",
            q.angle_between(r)
        );
        let err = (ss - stretch)
            .to_cols_array()
            .iter()
            .map(|x| x.abs())
            .fold(0.0, f32::max);
        assert!(err <= 1e-4 * s, "scale {s}: stretch off by {err}");
    }
    // A joint scaled to nothing (hiding a part) skins under DQS as under LBS.
    let ch = character::load("builtin:walker").unwrap();
    let mut mats = Animator {
        clip: Some(0),
        looping: true,
        placement: Mat4::IDENTITY,
    }
    .joint_matrices(&ch, 0.2);
    mats[3] *= Mat4::from_scale(Vec3::ZERO);
    let (l, _) = ch.skinned_at(&mats, Skinning::Lbs).unwrap();
    let (d, _) = ch.skinned_at(&mats, Skinning::Dqs).unwrap();
    assert!(l
        .iter()
        .zip(&d)
        .all(|(a, b)| a.is_finite() && b.is_finite()));
}

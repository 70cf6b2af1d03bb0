//! Morph weights move the water (issue 68): a box on no skin and no animated node, grown by
//! one morph target, is a full character; its control particles carry the nearest skin's
//! offsets and follow the morphed surface, GPU against CPU.
use super::common::{
    self,
    gltf::{cube, Doc},
};
use fluidform::character::{inspect, pose, skin::Skinner, Skinning};
use fluidform::control::target::Bound;
use fluidform::scene::character::placed_matrices;
use fluidform::scene::Scene;
use glam::Vec3;
use serde_json::json;

/// Rest size of the box (m) and how far 'Grow' lifts its top.
const SIZE: [f32; 3] = [0.3, 0.5, 0.24];
const GROW: f32 = 0.4;

/// The box, its top corners lifted by 'Grow', and a clip 'grow' taking the weight from 0
/// to 1 at 1 s and back to 0 at 2 s (weights only: nothing else moves).
fn growing_box() -> serde_json::Value {
    let (unit, idx) = cube();
    let p: Vec<[f32; 3]> = unit
        .iter()
        .map(|u| [0, 1, 2].map(|k| (u[k] - if k == 1 { 0.0 } else { 0.5 }) * SIZE[k]))
        .collect();
    let mut d = Doc::default();
    let pos = d.vec3(&p);
    let ind = d.indices(&idx);
    let lift: Vec<[f32; 3]> = p
        .iter()
        .map(|v| [0.0, if v[1] > 0.0 { GROW } else { 0.0 }, 0.0])
        .collect();
    let lift = d.vec3(&lift);
    let times = d.scalars(&[0.0, 1.0, 2.0]);
    let w = d.scalars(&[0.0, 1.0, 0.0]);
    d.finish(json!({
        "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"name": "box", "mesh": 0}],
        "meshes": [{
            "primitives": [{"attributes": {"POSITION": pos}, "indices": ind,
                            "targets": [{"POSITION": lift}]}],
            "extras": {"targetNames": ["Grow"]}
        }],
        "animations": [{
            "name": "grow",
            "samplers": [{"input": times, "output": w, "interpolation": "LINEAR"}],
            "channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}]
        }]
    }))
}

fn scene(dir: &std::path::Path) -> std::path::PathBuf {
    common::gltf::write(dir, "box.gltf", &growing_box());
    let path = dir.join("box.toml");
    let body = "name = \"box\"\nframes = 90\n[character]\nfile = \"box.gltf\"\n[pool]\n[control]\n";
    std::fs::write(&path, body).unwrap();
    path
}

#[test]
fn morph_weights_move_the_control_particles_gpu_as_cpu() {
    let dir = tempfile::tempdir().unwrap();
    let path = scene(dir.path());
    let s = Scene::load(path.to_str().unwrap()).unwrap();
    let desc = s.character.clone().unwrap();
    let (ch, anim) = desc.load().unwrap();
    assert!(!ch.skinned);
    let text = inspect::inspect(&ch, fluidform::character::anim::Up::Y, false)
        .unwrap()
        .text();
    assert!(
        text.contains("'grow' 2.000 s, 1 channels, morph target weights only"),
        "{text}"
    );
    // The fitted domain holds the grown box, not only the rest pose.
    let (lo, hi) = (Vec3::from(s.domain.min), Vec3::from(s.domain.max));
    let rest_top = anim
        .placement
        .transform_point3(Vec3::new(0.0, SIZE[1], 0.0))
        .y;
    let scale = anim.placement.transform_vector3(Vec3::Y).length();
    assert!(
        hi.y >= rest_top + GROW * scale - 1e-4,
        "domain {lo}..{hi}, rest top {rest_top}"
    );
    let control = s.control.clone().unwrap();
    let bound = Bound::new(&ch, &anim, &control, &s.fluid, 1)
        .unwrap()
        .unwrap();
    assert_eq!(bound.mesh.morphs.targets.len(), 1);
    let spacing = bound.spacing;
    let ctx = common::ctx();
    let mut probe = ch.clone();
    probe.mesh = bound.mesh.clone();
    let mut sk = Skinner::new(&ctx, &probe, Skinning::Lbs).unwrap();
    let rest = bound.at(
        &ch,
        (&placed_matrices(&ch, &anim, desc.speed, None, 0.0), &[0.0]),
        Skinning::Lbs,
    );
    let rest = rest.unwrap();
    let (bottom, top) = rest
        .iter()
        .fold((f32::MAX, f32::MIN), |(a, b), p| (a.min(p.y), b.max(p.y)));
    for t in [0.5f64, 1.0] {
        let mats = placed_matrices(&ch, &anim, desc.speed, None, t);
        let weights = anim.morph_weights(&ch, t as f32);
        assert!((weights[0] - t as f32).abs() < 1e-6);
        let cpu = bound.at(&ch, (&mats, &weights), Skinning::Lbs).unwrap();
        // The CPU reference: each particle rises with the skin nearest it, by its height
        // in the box (the side faces' corners interpolated), the top ones by the whole lift.
        let lift = GROW * scale * weights[0];
        let mut highest = f32::MIN;
        for (p, r) in cpu.iter().zip(&rest) {
            let rise = p.y - r.y;
            assert!(
                rise >= -1e-5 && rise <= lift + 1e-5,
                "t {t}: rise {rise} of {lift}"
            );
            assert!((p.x - r.x).abs() < 1e-5 && (p.z - r.z).abs() < 1e-5);
            highest = highest.max(p.y);
        }
        assert!(
            highest >= top + lift - 0.1 * spacing,
            "t {t}: top {highest}, {top} + {lift}"
        );
        assert!(bottom >= lo.y - 1e-4 && highest <= hi.y + 1e-4);
        // The GPU's skinning of the same particles (joints relative to the rest pose).
        let rel: Vec<_> = mats
            .iter()
            .zip(&bound.rest_inv)
            .map(|(m, r)| *m * *r)
            .collect();
        let joints = pose::gpu_joints(&rel, Skinning::Lbs, &|j| ch.joint_name(j)).unwrap();
        let (gpu, _) = common::skin_on_gpu(&ctx, &sk, &joints, &weights);
        let worst = gpu
            .iter()
            .zip(&cpu)
            .map(|(g, c)| (Vec3::from_slice(&g[..3]) - *c).length())
            .fold(0.0, f32::max);
        assert!(worst < 0.1 * spacing, "t {t}: GPU {worst} m from the CPU");
    }
    sk.destroy(&ctx);
    common::finish(&ctx);
}

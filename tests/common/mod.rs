//! Shared test helpers: every test opens its device with the validation layer on and
//! ends with `finish`, which fails on any validation error.
#![allow(dead_code)]
pub mod blob;
pub mod gltf;
use fluidform::gpu::{Context, ContextOptions};

pub fn ctx() -> Context {
    Context::new(&ContextOptions {
        device: std::env::var("FLUIDFORM_TEST_DEVICE").ok(),
        validation: true,
        present: None,
    })
    .expect("open a Vulkan device with validation (run scripts/setup.sh)")
}

pub fn finish(ctx: &Context) {
    let (errors, _) = ctx.validation_counts();
    assert_eq!(
        errors,
        0,
        "validation errors: {:#?}",
        ctx.validation_messages()
    );
    assert!(
        ctx.memory_bytes().is_empty() && ctx.live_objects().is_empty(),
        "GPU objects leaked: {:?} {:?}",
        ctx.memory_bytes(),
        ctx.live_objects()
    );
}

/// A file of ../shared/assets (CI has it; a missing one fails the test, never skips it).
pub fn asset(name: &str) -> String {
    let p = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/assets")
        .join(name);
    assert!(
        p.exists(),
        "test asset {} is missing (CI has ../shared/assets)",
        p.display()
    );
    p.display().to_string()
}

/// The fluidform binary run with `args`.
pub fn fluidform(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_fluidform"))
        .args(args)
        .output()
        .expect("spawn fluidform")
}

/// A command's stdout and stderr together.
pub fn text(o: &std::process::Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The run's summary.json, also read back typed (the whole schema must parse).
pub fn summary(dir: &std::path::Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    let typed: fluidform::run::RunSummary =
        serde_json::from_str(&text).unwrap_or_else(|e| panic!("typed summary: {e}\n{text}"));
    assert_eq!(typed.frames as u64, typed.config.frames);
    serde_json::from_str(&text).unwrap()
}

/// `n` random points in the cube [lo, lo + side]^3, no two closer than a third of
/// `spacing`, with random velocities of up to `speed` per axis and white attributes.
pub fn random_particles(
    spacing: f32,
    n: usize,
    lo: [f32; 3],
    side: f32,
    speed: f32,
    seed: u64,
) -> fluidform::scene::schema::Particles {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
    let mut pos: Vec<[f32; 4]> = Vec::new();
    while pos.len() < n {
        let p = [
            lo[0] + rng.random::<f32>() * side,
            lo[1] + rng.random::<f32>() * side,
            lo[2] + rng.random::<f32>() * side,
            0.0,
        ];
        let close = pos
            .iter()
            .any(|q| (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f32>() < (spacing / 3.0).powi(2));
        if !close {
            pos.push(p);
        }
    }
    let vel = (0..n)
        .map(|_| {
            [
                rng.random_range(-speed..speed),
                rng.random_range(-speed..speed),
                rng.random_range(-speed..speed),
                0.0,
            ]
        })
        .collect();
    fluidform::scene::schema::Particles {
        pos,
        vel,
        attr: vec![[1.0, 1.0, 1.0, 0.0]; n],
    }
}

/// Seeded pseudo-random u32s.
pub fn random_u32(n: usize, seed: u64) -> Vec<u32> {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
    (0..n).map(|_| rng.random()).collect()
}

/// Distance from `p` to triangle (a, b, c) (the library's, Ericson 5.1.5).
#[allow(unused_imports)]
pub use fluidform::control::mesh_distance::tri_distance;

/// The dam break's scene with `fluid` in a box from the origin to `domain`, filled with
/// `blocks` (with none, a 10 cm cube: a scene needs some fluid; tests that bring their
/// own particles pass none), no balls, no colliders.
pub fn box_scene(
    fluid: fluidform::sph::FluidParams,
    domain: [f32; 3],
    blocks: Vec<fluidform::scene::schema::Block>,
) -> fluidform::scene::schema::Scene {
    use fluidform::scene::schema::{Block, Scene};
    let blocks = if blocks.is_empty() {
        vec![Block {
            min: [0.0; 3],
            max: [0.1; 3],
            group: 0,
            color: [1.0; 3],
            velocity: [0.0; 3],
        }]
    } else {
        blocks
    };
    let mut s = Scene::water_box(fluid, domain, blocks).expect("the dam break is built in");
    s.name = "solver test".into();
    s
}

/// Record `sk`'s joints, morph weights and skinning pass, then read back its skinned
/// positions and normals (vec4 each).
pub fn skin_on_gpu(
    ctx: &Context,
    sk: &fluidform::character::skin::Skinner,
    joints: &[fluidform::character::pose::GpuJoint],
    weights: &[f32],
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    use fluidform::gpu::sync;
    ctx.one_shot(|cmd| {
        sk.record(ctx, cmd, joints, weights).unwrap();
        ctx.barrier(
            cmd,
            sync::COMPUTE_WRITE,
            sync::HOST_READ | sync::TRANSFER_READ,
        );
    })
    .unwrap();
    (
        ctx.read_all(&sk.mesh.pos).unwrap(),
        ctx.read_all(&sk.mesh.nrm).unwrap(),
    )
}

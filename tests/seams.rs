//! The seams of issue 10: checked shader interfaces, the particle registry and its GPU
//! count, SPH hooks, and error paths that release what they made.
mod common;
use bytemuck::{Pod, Zeroable};
use fluidform::gpu::{ComputeDesc, ComputePipeline, Labels};
use fluidform::scene::Scene;
use fluidform::sph::hooks::{ConstantForce, Hooks, SphHook};
use fluidform::sph::store::{AttributeDecl, LiveArgsPass, LiveCount, ParticleStore};
use fluidform::sph::SphSolver;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct SaxpyPush {
    a: f32,
    n: u32,
}

fluidform::gpu_interface! { SwappedIo / SwappedBufs: "S1", push SaxpyPush { y = 0, x = 1, u = 2 } }
fluidform::gpu_interface! { MissingIo / MissingBufs: "S2", push SaxpyPush { x = 0, y = 1 } }
fluidform::gpu_interface! { ExtraIo / ExtraBufs: "S3", push SaxpyPush { x = 0, y = 1, u = 2, w = 3 } }
fluidform::gpu_interface! { PushIo / PushBufs: "S4", push u32 { x = 0, y = 1, u = 2 } }
fluidform::gpu_interface! { RightIo / RightBufs: "S5", push SaxpyPush { x = 0, y = 1, u = 2 } }

fn refusal<I: fluidform::gpu::Interface>(ctx: &fluidform::gpu::Context) -> String {
    match ComputePipeline::<I>::new(
        ctx,
        &ComputeDesc::plain("saxpy-pass", "test/saxpy.comp", &[], 64),
    ) {
        Ok(mut p) => {
            p.destroy(ctx);
            String::new()
        }
        Err(e) => e.to_string(),
    }
}

#[test]
fn wrong_interfaces_are_refused_with_the_pass_and_binding() {
    let ctx = common::ctx();
    let e = refusal::<SwappedIo>(&ctx);
    assert!(
        e.contains("saxpy-pass") && e.contains("binding 0 is 'y'"),
        "{e}"
    );
    let e = refusal::<MissingIo>(&ctx);
    assert!(e.contains("saxpy-pass") && e.contains("binding 2"), "{e}");
    let e = refusal::<ExtraIo>(&ctx);
    assert!(
        e.contains("saxpy-pass") && e.contains("binding 3 ('w')"),
        "{e}"
    );
    let e = refusal::<PushIo>(&ctx);
    assert!(
        e.contains("saxpy-pass") && e.contains("4 bytes in Rust but 8"),
        "{e}"
    );
    assert_eq!(
        refusal::<RightIo>(&ctx),
        "",
        "the right interface is accepted"
    );
    assert!(ctx.live_objects().is_empty(), "{:?}", ctx.live_objects());
    common::finish(&ctx);
}

#[test]
fn registry_uploads_grows_and_refuses_bad_attributes() {
    let ctx = common::ctx();
    let mut s = ParticleStore::new(&ctx, "test", 100).unwrap();
    let v = AttributeDecl {
        name: "v",
        bytes: 16,
        reorder: true,
    };
    let id = s.register(&ctx, v).unwrap();
    assert!(s.register(&ctx, v).is_err(), "a name is registered once");
    let bad = AttributeDecl {
        name: "w",
        bytes: 8,
        reorder: true,
    };
    assert!(s
        .register(&ctx, bad)
        .unwrap_err()
        .to_string()
        .contains("vec4"));
    let data: Vec<[f32; 4]> = (0..100).map(|i| [i as f32, 1.0, 2.0, 3.0]).collect();
    s.upload(&ctx, id, &data).unwrap();
    s.set_live(&ctx, 100, 64).unwrap();
    assert!(s.set_live(&ctx, 101, 64).is_err());
    s.grow(&ctx, 300).unwrap();
    assert_eq!(s.capacity, 300);
    assert_eq!(
        s.read::<[f32; 4]>(&ctx, id, 100).unwrap(),
        data,
        "grow keeps the live particles"
    );
    let c: LiveCount = ctx.readback(&s.count, 0, 1).unwrap()[0];
    assert_eq!((c.n, c.capacity, c.groups[0]), (100, 300, 2));
    s.destroy(&ctx);
    common::finish(&ctx);
}

/// A count changed on the GPU sets the group count of an indirect dispatch.
#[test]
fn gpu_live_count_drives_indirect_dispatch() {
    let ctx = common::ctx();
    let mut s = ParticleStore::new(&ctx, "test", 1000).unwrap();
    let acc = s
        .register(
            &ctx,
            AttributeDecl {
                name: "acc",
                bytes: 16,
                reorder: false,
            },
        )
        .unwrap();
    s.upload(&ctx, acc, &vec![[0f32; 4]; 1000]).unwrap();
    s.set_live(&ctx, 1000, 128).unwrap();
    let args = LiveArgsPass::new(&ctx).unwrap();
    let mut force = ConstantForce::new(&ctx, [1.0, 0.0, 0.0]).unwrap();
    ctx.one_shot(|cmd| {
        use fluidform::gpu::sync;
        // "Death" on the GPU: 300 live.
        ctx.update(cmd, &s.count, 0, &[300u32]);
        ctx.barrier(cmd, sync::TRANSFER_WRITE, sync::COMPUTE_READ);
        args.record(&ctx, cmd, &s.count);
        ctx.barrier(cmd, sync::COMPUTE_WRITE, sync::INDIRECT_READ);
        force.record_indirect(
            &ctx,
            cmd,
            s.get(acc),
            1000,
            &s.count,
            LiveCount::ARGS_OFFSET,
        );
    })
    .unwrap();
    let a: Vec<[f32; 4]> = s.read(&ctx, acc, 1000).unwrap();
    // ceil(300 / 128) = 3 groups of 128: exactly the first 384 slots ran.
    let ran = a.iter().filter(|v| v[0] == 1.0).count();
    assert_eq!(ran, 384);
    assert!(a[..384].iter().all(|v| v[0] == 1.0));
    force.destroy(&ctx);
    let mut args = args;
    args.destroy(&ctx);
    s.destroy(&ctx);
    common::finish(&ctx);
}

fn block() -> Scene {
    Scene::built_in("resting-block").expect("built-in")
}

/// A force term through the hook equals the same acceleration added to gravity.
#[test]
fn constant_force_hook_moves_particles_as_gravity_would() {
    let ctx = common::ctx();
    let extra = [0.0f32, 3.0, 0.0];
    let run = |scene: &Scene, hook: bool| {
        let mut solver = SphSolver::new(&ctx, fluidform::kinds::Neighbors::Grid, None).unwrap();
        let mut force = ConstantForce::new(&ctx, extra).unwrap();
        let parts = scene.particles(1);
        let mut st = solver.state(&ctx, scene, &parts).unwrap();
        for _ in 0..5 {
            let mut hooks = Hooks::none();
            if hook {
                hooks.force.push(&mut force);
            }
            ctx.one_shot(|cmd| {
                solver
                    .record_hooked_step(&ctx, cmd, &mut Labels, &mut st, &mut hooks)
                    .unwrap()
            })
            .unwrap();
        }
        let d = st.read(&ctx).unwrap();
        st.destroy(&ctx);
        force.destroy(&ctx);
        solver.destroy(&ctx);
        d
    };
    let a = block();
    let with_hook = run(&a, true);
    let mut b = block();
    for (g, e) in b.fluid.gravity.iter_mut().zip(extra) {
        *g += e;
    }
    let plain = run(&b, false);
    let base = run(&a, false);
    let mean_vy = |d: &fluidform::sph::solver::StateDump| {
        d.vel.iter().map(|v| v[1] as f64).sum::<f64>() / d.vel.len() as f64
    };
    let (h, p, n) = (mean_vy(&with_hook), mean_vy(&plain), mean_vy(&base));
    assert!(
        (h - p).abs() <= 1e-4 * p.abs().max(1e-3),
        "hook {h} vs gravity {p}"
    );
    assert!(
        (h - n).abs() > 1e-3,
        "the hook changed the motion: {h} vs {n}"
    );
    common::finish(&ctx);
}

/// A test-only attribute follows its particle through the reorder.
#[test]
fn registered_attribute_survives_reorder() {
    let ctx = common::ctx();
    let mut solver = SphSolver::new(&ctx, fluidform::kinds::Neighbors::Grid, None).unwrap();
    let scene = block();
    let parts = scene.particles(3);
    let mut st = solver.state(&ctx, &scene, &parts).unwrap();
    let tag = st
        .particles
        .register(
            &ctx,
            AttributeDecl {
                name: "tag",
                bytes: 16,
                reorder: true,
            },
        )
        .unwrap();
    // Shuffle the upload order so the sort must move particles.
    let n = st.n as usize;
    let mut pos: Vec<[f32; 4]> = st
        .particles
        .read(&ctx, fluidform::sph::solver::POS, n)
        .unwrap();
    pos.reverse();
    st.particles
        .upload(&ctx, fluidform::sph::solver::POS, &pos)
        .unwrap();
    st.particles.upload(&ctx, tag, &pos).unwrap();
    ctx.one_shot(|cmd| {
        solver.record_params(&ctx, cmd, &st);
        solver
            .record_arrange(&ctx, cmd, &mut Labels, &mut st)
            .unwrap();
    })
    .unwrap();
    let after: Vec<[f32; 4]> = st
        .particles
        .read(&ctx, fluidform::sph::solver::POS, n)
        .unwrap();
    let tags: Vec<[f32; 4]> = st.particles.read(&ctx, tag, n).unwrap();
    assert!(after != pos, "the arrange reordered the particles");
    assert_eq!(tags, after, "each tag is still beside its particle");
    st.destroy(&ctx);
    solver.destroy(&ctx);
    common::finish(&ctx);
}

/// Construction that fails halfway leaves no GPU object behind.
#[test]
fn failed_construction_leaks_nothing() {
    use fluidform::render::metaball::FluidRenderer;
    let ctx = common::ctx();
    let sw = {
        use clap::Parser;
        #[derive(Parser)]
        struct Only {
            #[command(flatten)]
            s: fluidform::config::Switches,
        }
        Only::parse_from(["t", "--list", "sbuffer", "--material", "glass"]).s
    };
    let mut r =
        FluidRenderer::new(&ctx, fluidform::settings::metaball_settings(&sw).unwrap()).unwrap();
    let before = ctx.live_objects();
    // Params, offsets and lists are made before the metaball-sized depths fail.
    let e = r.buffers(&ctx, 1 << 40, 2, false);
    // It fails at the metaball-sized buffer, after the pixel-sized ones were made.
    let msg = e.err().map(|e| e.to_string()).unwrap_or_default();
    assert!(msg.contains("metaball depths"), "{msg}");
    assert_eq!(
        ctx.live_objects(),
        before,
        "every buffer made before the failure was released"
    );
    assert!(ctx.memory_bytes().is_empty(), "{:?}", ctx.memory_bytes());
    r.destroy(&ctx);
    assert!(ctx.live_objects().is_empty(), "{:?}", ctx.live_objects());
    common::finish(&ctx);
}

/// Synchronization validation reports a fill's missing barrier (the tracker places it);
/// Debian 12's layer (1.3.239) sees transfer-dispatch hazards, not dispatch-dispatch ones.
#[test]
fn sync_validation_reports_a_missing_barrier() {
    let ctx = common::ctx();
    let mut p = ComputePipeline::<RightIo>::new(
        &ctx,
        &ComputeDesc::plain("saxpy", "test/saxpy.comp", &[], 64),
    )
    .unwrap();
    let mut b: Vec<_> = ["x", "y", "u"]
        .iter()
        .map(|n| ctx.storage_buffer(n, 4096).unwrap())
        .collect();
    let bufs = RightBufs {
        x: &b[0],
        y: &b[1],
        u: &b[2],
    };
    let push = SaxpyPush { a: 1.0, n: 1024 };
    // Through the context, the barrier tracker places the barrier the fill needs.
    ctx.one_shot(|cmd| {
        ctx.fill(cmd, &b[1], 0);
        p.dispatch(&ctx, cmd, &bufs, &push, 1024); // no hand barrier after the fill
    })
    .unwrap();
    assert_eq!(
        ctx.validation_counts().0,
        0,
        "{:?}",
        ctx.validation_messages()
    );
    assert_eq!(ctx.tracked_barriers(), (1, 0));
    // A fill recorded behind the tracker's back is a hazard the layer reports.
    ctx.one_shot(|cmd| {
        unsafe {
            ctx.device
                .cmd_fill_buffer(cmd, b[1].raw, 0, ash::vk::WHOLE_SIZE, 0)
        };
        p.dispatch(&ctx, cmd, &bufs, &push, 1024);
    })
    .unwrap();
    let (errors, _) = ctx.validation_counts();
    let msgs = ctx.validation_messages();
    assert!(
        errors > 0 && msgs.iter().any(|m| m.contains("SYNC-HAZARD")),
        "{msgs:?}"
    );
    for x in &mut b {
        ctx.destroy_buffer(x);
    }
    p.destroy(&ctx);
}

//! `bench emission` (seed 002, figure 9): frames per second of the emitting scene at N =
//! 8K ... 64K particles with the counting grid and with hash + bitonic sort. The scene is
//! `game`'s room with a 2 x 1.5 m pool of N particles that are all emitter slots, alive at the start
//! with ages spread over the life limit (`recycle`), and a birth rate that keeps them all
//! alive: every frame skins the walker, renders it into its UV atlas, emits, and steps.
use super::protocol::{self, Case};
use super::{BenchOptions, Row};
use crate::error::Result;
use crate::gpu::Open;
use crate::gpu::{Context, Guard};
use crate::kinds::{Neighbors, SortAlgo};
use crate::run::targets::SceneTargets;
use crate::scene::emission::EmissionDesc;
use crate::scene::schema::Block;
use crate::scene::Scene;
use crate::sph::SphSolver;
use serde_json::json;

/// Figure 9's particle counts.
pub const COUNTS: &[u32] = &[8 << 10, 16 << 10, 32 << 10, 64 << 10];

/// Life limit of the benchmark's particles (seconds).
const LIFE: f32 = 4.0;

/// The game room with a floor pool of about `n` particles, every one an emitter slot.
pub fn scene(n: u32) -> Scene {
    let mut s = Scene::built_in("game").expect("built-in");
    // A 2 x 1.5 m pool in the middle of the room (two layers at 8K, 16 at 64K).
    let (lo, hi) = ([-1.0f32, 0.0, -0.75], [1.0f32, 0.0, 0.75]);
    let sp = s.fluid.spacing() as f64;
    let floor = (hi[0] - lo[0]) as f64 * (hi[2] - lo[2]) as f64;
    let depth = (n as f64 * sp.powi(3) / floor) as f32;
    s.blocks = vec![Block {
        min: lo,
        max: [hi[0], depth, hi[2]],
        group: 0,
        color: [0.2, 0.45, 1.0],
        velocity: [0.0; 3],
    }];
    // The pillars stand in the pool; the lattice leaves their volume empty.
    s.emission = Some(EmissionDesc {
        slots: 0,
        recycle: true,
        life_limit: Some(LIFE),
        // Births keep up with deaths: lives last 3/4 of the limit on average.
        rate: Some(n as f32 / (0.75 * LIFE)),
        ..EmissionDesc::new(0)
    });
    s
}

pub fn emission(ctx: &Context, opts: &BenchOptions) -> Result<Vec<Row>> {
    let sw = &opts.switches;
    let strategies = super::sph::strategies(
        opts,
        &[
            (Neighbors::Grid, SortAlgo::Counting),
            (Neighbors::Hash, SortAlgo::Bitonic),
        ],
    );
    let counts = match sw.common.particles {
        Some(n) => vec![n],
        None if !opts.counts.is_empty() => opts.counts.clone(),
        None => COUNTS.to_vec(),
    };
    let mut cases = Vec::new();
    for (strategy, sort) in strategies {
        for &n in &counts {
            let mut scene = scene(n);
            scene.fluid = sw.fluid_args.apply(&scene.fluid)?;
            let parts = scene.particles(sw.common.seed);
            let opts = crate::settings::target_options(sw);
            let mut solver = Guard::new(ctx, SphSolver::new(ctx, strategy, Some(sort))?);
            let mut st = Guard::new(ctx, solver.state(ctx, &scene, &parts)?);
            let mut targets = Guard::new(
                ctx,
                SceneTargets::new(ctx, &scene, &opts, &solver, &mut st, &parts.pos, 1)?,
            );
            let actual = st.n as u64;
            let dt = st.dt;
            let variant = format!("{}-{}", strategy.as_str(), sort.as_str());
            let detail = json!({
                "scene": "game room, a floor pool of N emitter slots (recycle)",
                "particles": actual,
                "dt": dt,
                "life_limit": LIFE,
                "rate": n as f32 / (0.75 * LIFE),
                "fluid": scene.fluid,
            });
            let mut t = 0.0f64;
            // The case owns its solver, state and targets: each advances in its own frames.
            cases.push(Case::new(
                variant,
                actual,
                crate::gpu::FRAME,
                detail,
                move |prof, cmd| {
                    {
                        let mut prof = prof.open(ctx, cmd, crate::gpu::FRAME.scope());
                        targets.record_before(ctx, cmd, &mut prof, &mut st, t, dt, 1)?;
                        solver.record_hooked_step(
                            ctx,
                            cmd,
                            &mut *prof,
                            &mut st,
                            &mut targets.hooks(),
                        )?;
                    }
                    t += dt as f64;
                    Ok(())
                },
            ));
        }
    }
    let mut rows = protocol::run(ctx, opts, cases)?;
    for row in &mut rows {
        row.variant = row.variant.replacen('-', "/", 1);
        row.extra = vec![("fps".into(), format!("{:.1}", 1000.0 / row.main.median))];
    }
    Ok(rows)
}

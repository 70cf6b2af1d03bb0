//! `bench particles` (seed 003): a full pool of N sprites thrown up from a sphere under
//! gravity, bouncing on one plane (the closed form has no plane: gravity alone), one
//! step, sort and draw per frame at 512 x 512 (or --width, --height).
use super::protocol::{self, Case};
use super::{counts, BenchOptions, Row};
use crate::error::{Error, Result};
use crate::gpu::Open;
use crate::gpu::{ColorTarget, Context, Guard};
use crate::kinds::SortAlgo;
use crate::psys::frame::{frame_info, record_simulation};
use crate::psys::spec::{ColliderSpec, ParticleSpec, Shape, SystemSpec, Vary};
use crate::psys::{Integrator, SpriteMode};
use crate::psys::{ParticleSystem, Passes};
use crate::render::Camera;
use crate::scene::particles::{base_system, emitter};
use serde_json::json;

pub const COUNTS: &[u32] = &[64 << 10, 256 << 10, 1 << 20];

/// The benchmark's system at N slots: lives of 2 +- 1 s, so none dies while measured.
pub fn system(n: u32, integrator: Integrator, sort: SortAlgo, draw: SpriteMode) -> SystemSpec {
    let mut s = base_system(
        "bench",
        n,
        emitter(
            Shape::Sphere,
            [0.0, 1.0, 0.0],
            0.8,
            Vary {
                mean: 0.0,
                variance: 0.0,
            },
        ),
        ParticleSpec {
            offset: Vary {
                mean: [0.0; 3],
                variance: [0.0; 3],
            },
            velocity: Vary {
                mean: [0.0, 2.0, 0.0],
                variance: [1.5, 1.5, 1.5],
            },
            spread: 0.0,
            size: Vary {
                mean: 0.012,
                variance: 0.004,
            },
            life: Vary {
                mean: 2.0,
                variance: 1.0,
            },
            color: Vary {
                mean: [0.5, 0.7, 1.0, 0.6],
                variance: [0.2, 0.2, 0.0, 0.2],
            },
        },
    );
    s.integrator = Some(integrator);
    s.draw = Some(draw);
    s.sort = Some(sort);
    // Births keep the pool full once lives end (N / mean life per second).
    s.emitter.rate = Some(Vary {
        mean: n as f32 / 2.0 / 60.0,
        variance: 0.0,
    });
    if integrator != Integrator::Closed {
        s.collider.push(ColliderSpec::ground(0.0, 0.4, 0.1));
    }
    s
}

/// (integrator, sort) pairs: --integrator and --sort pick, else each integrator unsorted
/// and each sort with Euler, plus the closed form counting-sorted.
fn variants(opts: &BenchOptions) -> Result<Vec<(Integrator, SortAlgo)>> {
    let sw = &opts.switches;
    let ints = [Integrator::Euler, Integrator::Verlet, Integrator::Closed];
    if sw.particle.draw == Some(SpriteMode::Points) {
        if sw.sorting.sort.is_some_and(|s| s != SortAlgo::None) {
            return Err(Error::Param(
                "bench particles --draw points: points are opaque and take no --sort".into(),
            ));
        }
        return Ok(match sw.particle.integrator {
            Some(i) => vec![(i, SortAlgo::None)],
            None => ints.iter().map(|&i| (i, SortAlgo::None)).collect(),
        });
    }
    let sorts = [
        SortAlgo::None,
        SortAlgo::OddEven,
        SortAlgo::Bitonic,
        SortAlgo::Counting,
    ];
    Ok(match (sw.particle.integrator, sw.sorting.sort) {
        (Some(i), Some(s)) => vec![(i, s)],
        (Some(i), None) => sorts.iter().map(|&s| (i, s)).collect(),
        (None, Some(s)) => ints.iter().map(|&i| (i, s)).collect(),
        (None, None) => {
            let mut v: Vec<_> = ints.iter().map(|&i| (i, SortAlgo::None)).collect();
            v.extend(sorts[1..].iter().map(|&s| (Integrator::Euler, s)));
            v.push((Integrator::Closed, SortAlgo::Counting));
            v
        }
    })
}

pub fn particles(ctx: &Context, opts: &BenchOptions) -> Result<Vec<Row>> {
    let (w, h) = (opts.switches.frame.width(), opts.switches.frame.height());
    let cam = Camera::look_at(
        glam::Vec3::new(0.0, 1.6, 6.0),
        glam::Vec3::new(0.0, 1.0, 0.0),
        45.0,
        w as f32 / h as f32,
    );
    let passes = Guard::new(ctx, Passes::new(ctx)?);
    let target = Guard::new(ctx, ColorTarget::new(ctx, w, h, 0)?);
    let list: Vec<u32> = match opts.counts.is_empty() && opts.switches.common.particles.is_none() {
        true => COUNTS.to_vec(),
        false => counts(opts),
    };
    let draw = opts.switches.particle.draw.unwrap_or(SpriteMode::Sprites);
    let dt = 1.0 / 60.0;
    // Every system first, its pool filled at t = 0; each case then steps its own.
    let mut keys = Vec::new();
    let mut systems = Guard::new(ctx, Vec::new());
    for (integrator, sort) in variants(opts)? {
        for &n in &list {
            let spec = system(n, integrator, sort, draw);
            let mut s = ParticleSystem::new(ctx, &passes, &spec, 0, opts.switches.common.seed)?;
            let f0 = frame_info(&cam, dt, 0, w, h);
            let born = ctx.one_shot(|cmd| {
                s.record_births(ctx, cmd, &mut crate::gpu::Labels, &passes, &f0, n)
            });
            systems.push(s);
            born?;
            keys.push((integrator, sort, n, spec));
        }
    }
    let (passes, target, cam) = (&*passes, &*target, &cam);
    let cases = systems
        .iter_mut()
        .zip(&keys)
        .map(|(s, (integrator, sort, n, spec))| {
            let variant = format!("{}-{}", integrator.as_str(), sort.as_str());
            let detail = json!({ "system": spec, "width": w, "height": h });
            let mut k = 1u64;
            Case::new(
                variant,
                *n as u64,
                crate::gpu::FRAME,
                detail,
                move |prof, cmd| {
                    let f = frame_info(cam, dt, k, w, h);
                    k += 1;
                    record_simulation(ctx, cmd, prof, passes, std::slice::from_mut(s), &f)?;
                    {
                        let _scope = prof.open(ctx, cmd, Passes::DRAW);
                        s.prepare_draw(ctx, cmd, passes, &f);
                        target.begin_rendering(ctx, cmd, [0.0, 0.0, 0.0, 1.0]);
                        s.record_draw(ctx, cmd, passes, &f);
                        target.end_rendering(ctx, cmd);
                    }
                    Ok(())
                },
            )
        })
        .collect();
    let mut rows = protocol::run(ctx, opts, cases)?;
    for ((row, s), (integrator, sort, n, _)) in rows.iter_mut().zip(systems.iter()).zip(&keys) {
        let c = s.read_counters(ctx)?;
        // The unsorted closed form draws every slot (the vertex shader culls the dead).
        let drawn = match (integrator, sort) {
            (Integrator::Closed, SortAlgo::None) => *n,
            _ => c.draw_args[0] / c.verts,
        };
        row.variant = format!("{}/{}", integrator.as_str(), sort.as_str());
        row.extra = vec![
            ("fps".into(), format!("{:.1}", 1000.0 / row.main.median)),
            ("drawn".into(), drawn.to_string()),
        ];
    }
    Ok(rows)
}

/// The targets, from the rows measured.
pub fn notes(rows: &[Row]) -> Vec<String> {
    let at = |v: &str, n: u64, pass: Option<&str>| {
        rows.iter()
            .find(|r| r.variant == v && r.n == n)
            .and_then(|r| match pass {
                None => Some(r.main.median),
                Some(p) => r
                    .passes
                    .iter()
                    .find(|(name, _)| name == p)
                    .map(|(_, s)| s.median),
            })
    };
    let mut out = Vec::new();
    for &n in COUNTS.iter().rev() {
        let n = n as u64;
        if let (Some(c), Some(e)) = (at("closed/none", n, None), at("euler/none", n, None)) {
            out.push(format!(
                "at {n}: the closed form's frame is {:.2}x Euler's ({c:.2} vs {e:.2} ms; target: at most 0.5x at 1M)",
                c / e
            ));
        }
        let sim = |v: &str| Some(at(v, n, Some("emit"))? + at(v, n, Some("update")).unwrap_or(0.0));
        if let (Some(c), Some(e)) = (sim("closed/none"), sim("euler/none")) {
            out.push(format!(
                "at {n}: simulation alone (emit + update): the closed form takes {:.3}x Euler's ({c:.2} vs {e:.2} ms)",
                c / e
            ));
        }
        if let (Some(o), Some(c)) = (
            at("euler/odd-even", n, Some("sort")),
            at("euler/counting", n, Some("sort")),
        ) {
            out.push(format!(
                "at {n}: the counting sort of sprite depths is {:.1}x faster than odd-even ({c:.2} vs {o:.2} ms; target: 10x at 1M)",
                o / c
            ));
        }
    }
    out
}

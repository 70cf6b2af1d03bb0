//! `bench march`: what the march's own machinery costs, each suspect switched alone on
//! `bench render`'s resting blob, timed together under the protocol: the counters (added
//! per subgroup into 64 slots, the default; summed per workgroup first; off) and the
//! lanes (8 x 8 blocks, the default; rows of 64), and the lanes per ray (1, the default;
//! 8, 16 and 32 where the device's subgroup holds them), per list mode (or --list). Each
//! row gives the march scope's ms beside the frame's, its ratio to the default's row and
//! the longest serial chain. Where the frame has secondary rays, a last row marches them
//! over every sample (--occupancy off).
use super::{BenchOptions, Row};
use crate::error::Result;
use crate::gpu::Context;
use crate::render::{Counters, Lanes, ListKind};

/// (counters, lanes, lanes per ray) per row: the default first, then each switched alone.
const SUSPECTS: [(Counters, Lanes, u32); 7] = [
    (Counters::Subgroup, Lanes::Blocks, 1),
    (Counters::Workgroup, Lanes::Blocks, 1),
    (Counters::Off, Lanes::Blocks, 1),
    (Counters::Subgroup, Lanes::Rows, 1),
    (Counters::Subgroup, Lanes::Blocks, 8),
    (Counters::Subgroup, Lanes::Blocks, 16),
    (Counters::Subgroup, Lanes::Blocks, 32),
];
const DEFAULT: &str = "counters=subgroup lanes=blocks";

pub fn march(ctx: &Context, opts: &BenchOptions) -> Result<Vec<Row>> {
    let mut rows = Vec::new();
    let held = crate::render::metaball::settings::ray_lanes_on(&ctx.info);
    for (list, sorted, build) in super::render::rows_of(&opts.switches)? {
        let mut s = crate::settings::metaball_settings(&opts.switches)?;
        (s.list, s.sorted, s.build) = (list, sorted, build);
        for (counters, lanes, ray_lanes) in SUSPECTS {
            if list == ListKind::Tiles && lanes == Lanes::Rows {
                continue; // tiles stage their tile per block
            }
            if !held.contains(&ray_lanes) {
                continue; // a ray's lanes share one subgroup
            }
            let mut name = format!(
                "{} counters={} lanes={}",
                s.list_name(),
                counters.as_str(),
                lanes.as_str()
            );
            if ray_lanes > 1 {
                name += &format!(" ray-lanes={ray_lanes}");
            }
            rows.push((
                crate::render::metaball::MetaballSettings {
                    counters,
                    lanes,
                    ray_lanes,
                    ..s.clone()
                },
                name,
            ));
        }
        // Secondary rays over every sample, where the frame has them.
        if s.skips_empty() {
            let name = format!("{} {DEFAULT} occupancy=off", s.list_name());
            let off = crate::render::metaball::MetaballSettings {
                occupancy: false,
                ..s.clone()
            };
            rows.push((off, name));
        }
    }
    let mut out = super::render::time_rows(ctx, opts, rows)?;
    // Each list's default row is its first.
    let mut first = 0;
    for k in 0..out.len() {
        if !out[k].variant.ends_with(DEFAULT) && k > 0 {
            let (m, d) = (march_ms(&out[k]), march_ms(&out[first]));
            out[k]
                .extra
                .insert(0, ("x default march".into(), ratio(m, d)));
        } else {
            first = k;
            out[k]
                .extra
                .insert(0, ("x default march".into(), "1.000".into()));
        }
        let m = march_ms(&out[k]);
        out[k].extra.insert(
            0,
            (
                "march ms".into(),
                m.map_or("-".into(), |m| format!("{m:.3}")),
            ),
        );
    }
    Ok(out)
}

/// The march scope's median ms of a row.
fn march_ms(row: &Row) -> Option<f64> {
    row.passes
        .iter()
        .find(|(k, _)| k == "render/march")
        .map(|(_, s)| s.median)
}

fn ratio(a: Option<f64>, b: Option<f64>) -> String {
    match (a, b) {
        (Some(a), Some(b)) if b > 0.0 => format!("{:.3}", a / b),
        _ => "-".into(),
    }
}

/// Per list: what the counters cost (the default's march over the one without counters;
/// target: at most 2% of the march) and what each former choice cost.
pub fn notes(rows: &[Row]) -> Vec<String> {
    let mut out = Vec::new();
    for d in rows.iter().filter(|r| r.variant.ends_with(DEFAULT)) {
        let list = d.variant.trim_end_matches(DEFAULT).trim_end();
        let of = |suffix: &str| {
            rows.iter()
                .find(|r| r.variant == format!("{list} {suffix}"))
                .and_then(march_ms)
        };
        let (Some(on), Some(off)) = (march_ms(d), of("counters=off lanes=blocks")) else {
            continue;
        };
        let cost = 100.0 * (on / off - 1.0);
        let verdict = if cost <= 2.0 { "meets" } else { "misses" };
        let mut line = format!(
            "{list}: counters cost {cost:+.1}% of the march ({on:.3} against {off:.3} ms off; \
             {verdict} the 2% target)"
        );
        for (what, suffix) in [
            ("summed per workgroup", "counters=workgroup lanes=blocks"),
            ("rows of 64", "counters=subgroup lanes=rows"),
            (
                "8 lanes a ray",
                "counters=subgroup lanes=blocks ray-lanes=8",
            ),
            (
                "16 lanes a ray",
                "counters=subgroup lanes=blocks ray-lanes=16",
            ),
            (
                "32 lanes a ray",
                "counters=subgroup lanes=blocks ray-lanes=32",
            ),
            (
                "secondary rays over every sample",
                "counters=subgroup lanes=blocks occupancy=off",
            ),
        ] {
            if let Some(m) = of(suffix) {
                line += &format!("; {what}: {:.3}x", m / on);
            }
        }
        out.push(line);
    }
    out
}

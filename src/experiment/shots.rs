//! The metaball frames of a table, timed together under the measurement protocol
//! (bench/protocol.rs): every cell gets its own buffers, sized (and its lists grown) before
//! anything is timed, and the cells that need the same shaders share one renderer, so the
//! protocol can interleave them. A `none` frame asked for again in the same invocation
//! (several tables share the thesis frame) is measured once and reused.
use super::Env;
use crate::bench::protocol::{self, Case};
use crate::bench::{BenchOptions, Row};
use crate::error::Result;
use crate::gpu::Open;
use crate::gpu::{Buffer, Context, Guard};
use crate::render::metaball::{FrameStats, MetaballSettings};
use crate::render::Camera;
use crate::render::ListKind;
use serde_json::Value;

/// One frame to time.
pub struct Shot<'a> {
    pub variant: String,
    pub settings: MetaballSettings,
    pub centers: &'a Buffer,
    /// Names the centres' contents, for reusing a `none` frame across tables.
    pub centers_key: String,
    pub n: u32,
    pub cam: Camera,
    pub detail: Value,
}

/// What a shot measured.
#[derive(Clone)]
pub struct Timed {
    pub row: Row,
    /// The sizing frame's statistics (lists, fragments), or the last timed frame's for
    /// `none`, which sizes nothing.
    pub sized: FrameStats,
    pub redos: u32,
    /// The last timed frame's statistics.
    pub after: FrameStats,
    /// The sizing frame's picture (RGBA8; empty for `none`).
    pub pixels: Vec<u8>,
}

/// The renderer's passes before the march: bounds, lists and tiles.
const LIST_PASSES: [&str; 7] = ["bounds", "count", "scan", "fill", "sort", "bin", "ranges"];

/// Shots that differ only in what the march alone reads (material, recursion depth,
/// refinement steps) do the same work before the march.
fn steady_group(s: &Shot) -> String {
    let mut v = serde_json::to_value(&s.settings).unwrap_or_default();
    if let Some(m) = v.as_object_mut() {
        for k in ["material", "depth", "refine"] {
            m.remove(k);
        }
    }
    format!("{v} {} {} {:?}", s.centers_key, s.n, s.cam)
}

fn memo_key(s: &Shot) -> Option<String> {
    (s.settings.list == ListKind::None).then(|| {
        format!(
            "{} {} {} {:?}",
            serde_json::to_string(&s.settings).unwrap_or_default(),
            s.centers_key,
            s.n,
            s.cam
        )
    })
}

/// Time `shots` interleaved; one result per shot, in order.
pub fn time_shots(
    ctx: &Context,
    env: &mut Env,
    opts: &BenchOptions,
    shots: &[Shot],
) -> Result<Vec<Timed>> {
    let fresh: Vec<usize> = (0..shots.len())
        .filter(|&i| memo_key(&shots[i]).is_none_or(|k| !env.timed.contains_key(&k)))
        .collect();
    // Every fresh shot's buffers, sized; its renderer made (once per shader configuration).
    let mut bufs = Guard::new(ctx, Vec::new());
    let mut sized = Vec::new();
    for &i in &fresh {
        let s = &shots[i];
        let r = env.shared_renderer(ctx, &s.settings)?;
        bufs.push(r.buffers(ctx, s.n as u64, 2, false)?);
        let b = bufs.last_mut().expect("pushed");
        sized.push(match s.settings.list {
            // none has no lists to size; its frames are the slowest, so none is not drawn
            // once more (its statistics come from the timed frames).
            ListKind::None => None,
            _ => {
                let st = r.render_sync(ctx, b, s.centers, s.n, &s.cam, 0)?;
                Some((st, b.pixels(0).to_vec()))
            }
        });
    }
    let mut cases = Vec::new();
    for (k, &i) in fresh.iter().enumerate() {
        let s = &shots[i];
        let r = env.made_renderer(&s.settings)?;
        let b = &bufs[k];
        let mut case = Case::new(
            s.variant.clone(),
            s.n as u64,
            crate::render::SCOPE,
            s.detail.clone(),
            move |prof, cmd| {
                {
                    let mut prof = prof.open(ctx, cmd, crate::render::SCOPE.scope());
                    r.record_as(&s.settings, ctx, cmd, &mut *prof, b, s.centers, s.n, &s.cam)?;
                }
                Ok(())
            },
        );
        // The passes before the march do not depend on what only the march reads.
        case.steady = LIST_PASSES.iter().map(|p| format!("render/{p}")).collect();
        case.group = Some(steady_group(s));
        cases.push(case);
    }
    let rows = protocol::run(ctx, opts, cases)?;
    for ((k, &i), row) in fresh.iter().enumerate().zip(rows) {
        let s = &shots[i];
        let after = env.made_renderer(&s.settings)?.frame_stats(&bufs[k], 0);
        let ((st, redos), pixels) = match sized[k].take() {
            Some((st, px)) => (st, px),
            None => ((after, 0), Vec::new()),
        };
        let t = Timed {
            row,
            sized: st,
            redos,
            after,
            pixels,
        };
        env.timed
            .insert(memo_key(s).unwrap_or_else(|| format!("shot {i}")), t);
    }
    let out = shots
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let key = memo_key(s).unwrap_or_else(|| format!("shot {i}"));
            env.timed.get(&key).cloned().expect("timed")
        })
        .collect();
    // Only `none` frames are kept for reuse.
    env.timed.retain(|k, _| !k.starts_with("shot "));
    Ok(out)
}

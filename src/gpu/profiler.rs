//! GPU timestamp scopes. One query pool per frame slot, so a slot's results are read after
//! its own fence without waiting for frames still in flight. Each scope opens a debug label
//! of the same name, so captures and timings agree on pass names.
use super::Context;
use crate::error::{Error, Result, VkContext};
use ash::vk;

/// GPU time of one frame: its passes in order (name, ms) and the whole frame in ms.
#[derive(Clone, Debug)]
pub struct FrameTiming {
    pub frame: u64,
    pub passes: Vec<(String, f64)>,
    pub frame_ms: f64,
}

struct Slot {
    pool: vk::QueryPool,
    /// (name, begin query, end query)
    scopes: Vec<(String, u32, u32)>,
    used: u32,
    frame: Option<u64>,
}

pub struct Profiler {
    slots: Vec<Slot>,
    capacity: u32,
    period_ns: f64,
    mask: u64,
    stack: Vec<usize>,
    current: usize,
    pub results: Vec<FrameTiming>,
}

/// Where passes report their named scopes: the profiler (label + timestamps) or
/// `Labels` (debug labels only, for one-shot work and tests).
pub trait Scopes {
    fn begin(&mut self, ctx: &Context, cmd: vk::CommandBuffer, name: &str);
    fn end(&mut self, ctx: &Context, cmd: vk::CommandBuffer);
}

pub struct Labels;

impl Scopes for Labels {
    fn begin(&mut self, ctx: &Context, cmd: vk::CommandBuffer, name: &str) {
        ctx.begin_label(cmd, name);
    }
    fn end(&mut self, ctx: &Context, cmd: vk::CommandBuffer) {
        ctx.end_label(cmd);
    }
}

impl Scopes for Profiler {
    fn begin(&mut self, ctx: &Context, cmd: vk::CommandBuffer, name: &str) {
        Profiler::begin(self, ctx, cmd, name)
    }
    fn end(&mut self, ctx: &Context, cmd: vk::CommandBuffer) {
        Profiler::end(self, ctx, cmd)
    }
}

/// Name of the scope that spans a whole frame.
pub const FRAME_SCOPE: &str = "frame";

impl Profiler {
    /// `slots` frames in flight, up to `max_scopes` scopes each (the frame scope included).
    pub fn new(ctx: &Context, slots: usize, max_scopes: u32) -> Result<Self> {
        let capacity = max_scopes * 2;
        let mut v = Vec::new();
        for i in 0..slots {
            let info = vk::QueryPoolCreateInfo::default()
                .query_type(vk::QueryType::TIMESTAMP)
                .query_count(capacity);
            let pool = unsafe { ctx.device.create_query_pool(&info, None) }.ctx("query pool")?;
            ctx.set_name(pool, &format!("timestamps slot {i}"));
            // Queries must be reset before first use; a host reset needs no command buffer.
            unsafe { ctx.device.reset_query_pool(pool, 0, capacity) };
            v.push(Slot {
                pool,
                scopes: Vec::new(),
                used: 0,
                frame: None,
            });
        }
        let bits = ctx.info.timestamp_valid_bits;
        Ok(Self {
            slots: v,
            capacity,
            period_ns: ctx.info.timestamp_period_ns as f64,
            mask: if bits >= 64 {
                u64::MAX
            } else {
                (1u64 << bits) - 1
            },
            stack: Vec::new(),
            current: 0,
            results: Vec::new(),
        })
    }

    /// Start recording frame `frame` into `slot` (whose previous results were collected).
    pub fn begin_frame(&mut self, ctx: &Context, cmd: vk::CommandBuffer, slot: usize, frame: u64) {
        let s = &mut self.slots[slot];
        debug_assert!(s.frame.is_none(), "slot {slot} not collected");
        unsafe {
            ctx.device
                .cmd_reset_query_pool(cmd, s.pool, 0, self.capacity)
        };
        s.scopes.clear();
        s.used = 0;
        s.frame = Some(frame);
        self.current = slot;
        self.stack.clear();
        self.begin(ctx, cmd, FRAME_SCOPE);
    }

    pub fn end_frame(&mut self, ctx: &Context, cmd: vk::CommandBuffer) {
        while !self.stack.is_empty() {
            self.end(ctx, cmd);
        }
    }

    /// Open a named scope: a debug label and a timestamp.
    pub fn begin(&mut self, ctx: &Context, cmd: vk::CommandBuffer, name: &str) {
        ctx.begin_label(cmd, name);
        let s = &mut self.slots[self.current];
        if s.used + 2 > self.capacity {
            // Out of queries: keep the label, skip the timing (reported at collect).
            s.scopes.push((name.to_string(), u32::MAX, u32::MAX));
        } else {
            let q = s.used;
            s.used += 2;
            unsafe {
                ctx.device.cmd_write_timestamp2(
                    cmd,
                    vk::PipelineStageFlags2::ALL_COMMANDS,
                    s.pool,
                    q,
                )
            };
            s.scopes.push((name.to_string(), q, q + 1));
        }
        self.stack.push(s.scopes.len() - 1);
    }

    pub fn end(&mut self, ctx: &Context, cmd: vk::CommandBuffer) {
        let Some(i) = self.stack.pop() else { return };
        let s = &self.slots[self.current];
        let (_, _, q) = s.scopes[i];
        if q != u32::MAX {
            unsafe {
                ctx.device.cmd_write_timestamp2(
                    cmd,
                    vk::PipelineStageFlags2::ALL_COMMANDS,
                    s.pool,
                    q,
                )
            };
        }
        ctx.end_label(cmd);
    }

    /// Read `slot`'s results; call only after that slot's fence has signalled.
    pub fn collect(&mut self, ctx: &Context, slot: usize) -> Result<()> {
        let s = &mut self.slots[slot];
        let Some(frame) = s.frame.take() else {
            return Ok(());
        };
        if s.scopes.iter().any(|(_, q, _)| *q == u32::MAX) {
            return Err(Error::Param(format!(
                "profiler: more than {} scopes in frame {frame}",
                self.capacity / 2
            )));
        }
        let mut raw = vec![0u64; s.used as usize];
        if s.used > 0 {
            unsafe {
                ctx.device.get_query_pool_results(
                    s.pool,
                    0,
                    &mut raw,
                    vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
                )
            }
            .ctx("read timestamps")?;
        }
        let ms = |a: u32, b: u32| {
            let ticks = raw[b as usize].wrapping_sub(raw[a as usize]) & self.mask;
            ticks as f64 * self.period_ns / 1e6
        };
        let mut passes = Vec::new();
        let mut frame_ms = 0.0;
        for (name, a, b) in &s.scopes {
            if name == FRAME_SCOPE {
                frame_ms = ms(*a, *b);
            } else {
                passes.push((name.clone(), ms(*a, *b)));
            }
        }
        self.results.push(FrameTiming {
            frame,
            passes,
            frame_ms,
        });
        Ok(())
    }

    /// Drop a slot's recording that was never submitted.
    pub fn forget(&mut self, slot: usize) {
        self.slots[slot].frame = None;
        self.stack.clear();
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for s in self.slots.drain(..) {
            unsafe { ctx.device.destroy_query_pool(s.pool, None) };
        }
    }
}

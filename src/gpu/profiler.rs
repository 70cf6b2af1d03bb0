//! GPU timestamp scopes. Query pools per frame slot, so a slot's results are read after its
//! own fence without waiting for frames still in flight; a slot adds a pool when a frame
//! records more scopes than it holds, so the profiler sizes itself from what is recorded.
//! A scope is keyed by its path, the names of the scopes open around it and its own
//! (`sph/arrange/sort`, `render/sort`), so two passes of the same name never merge. Each
//! scope opens a debug label of its name, so captures and timings agree.
use super::Context;
use crate::error::{Error, Result, VkContext};
use ash::vk;

/// GPU time of one frame: its scopes in order (key, ms) and the whole frame in ms; where
/// each scope starts, for timelines (`trace`).
#[derive(Clone, Debug, Default)]
pub struct FrameTiming {
    pub frame: u64,
    pub passes: Vec<(String, f64)>,
    pub frame_ms: f64,
    /// Each pass's start, ms after the frame's (parallel to `passes`).
    pub starts: Vec<f64>,
    /// The pass each pass was opened inside, as an index into `passes` (None: the frame).
    /// A key's path names its parents by convention only (`sph/health` is opened at the
    /// top), so a timeline nests by this.
    pub parents: Vec<Option<usize>>,
    /// The frame's first timestamp on the device's clock, ns (ticks times the period).
    pub gpu_ns: f64,
    /// When the CPU began recording the frame and when its submit returned, ns of
    /// CLOCK_MONOTONIC (`clock::monotonic_ns`).
    pub cpu_ns: Option<(f64, f64)>,
}

impl FrameTiming {
    /// Pass `key`'s ms in this frame, summed over its repeats; None where it did not run.
    pub fn pass_ms(&self, key: &str) -> Option<f64> {
        let mut found = self.passes.iter().filter(|(k, _)| k == key).peekable();
        found.peek()?;
        Some(found.map(|(_, ms)| ms).sum())
    }
}

/// Queries per pool (a begin and an end per scope).
const POOL_QUERIES: u32 = 256;
/// A scope deeper than the profiler times: its label, no timestamps.
const UNTIMED: u32 = u32::MAX - 1;

crate::switch_enum!(
    /// Which scopes write timestamps (`--scopes`): the frame alone, the frame and the
    /// scopes directly in it (sph, render, ...: one pair each, however many substeps), or
    /// every scope (about 1,000 timestamps a frame of the 64K character). Deeper scopes keep
    /// their debug labels. What the profiler itself costs is the frame's time between them.
    ScopeDepth {
        Frame,
        Passes,
        All
    }
);

impl ScopeDepth {
    /// The deepest scope timed (the frame is depth 0).
    fn depth(self) -> usize {
        match self {
            ScopeDepth::Frame => 0,
            ScopeDepth::Passes => 1,
            ScopeDepth::All => usize::MAX,
        }
    }
}

struct Slot {
    pools: Vec<vk::QueryPool>,
    /// (key, begin query, end query); query q lives in pool q / POOL_QUERIES.
    scopes: Vec<(String, u32, u32)>,
    /// The scope each scope was opened inside (an index into `scopes`).
    parents: Vec<Option<usize>>,
    used: u32,
    frame: Option<u64>,
    cpu_ns: Option<(f64, f64)>,
}

pub struct Profiler {
    slots: Vec<Slot>,
    /// llvmpipe resolves a timestamp on its rasterizer threads at the next flush once a
    /// framebuffer has been bound (lavapipe flushes before each timestamp, and llvmpipe
    /// bins the query into a new scene), so later compute scopes read too short. There,
    /// every timestamp is followed by a barrier, which lavapipe executes as a stall (flush
    /// and wait): the timestamp resolves before any later work starts.
    settle: bool,
    period_ns: f64,
    mask: u64,
    /// Open scopes: (index into the slot's scopes, key).
    stack: Vec<(usize, String)>,
    /// The deepest scope that writes timestamps.
    timed: usize,
    current: usize,
    pub results: Vec<FrameTiming>,
}

/// Where passes report their named scopes: the profiler (label + timestamps) or
/// `Labels` (debug labels only, for one-shot work and tests).
/// Scopes are opened with [`Open::open`], whose guard closes them when dropped (early
/// returns included); `begin` and `end` are what the guard calls.
pub trait Scopes {
    fn begin(&mut self, ctx: &Context, cmd: vk::CommandBuffer, name: ScopeName);
    fn end(&mut self, ctx: &Context, cmd: vk::CommandBuffer);
}

/// A scope's own name (its path is its parents' and its own): declared once as a
/// constant, or taken from a pass's declaration or a [`ScopeKey`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ScopeName(&'static str);

impl ScopeName {
    pub const fn new(name: &'static str) -> Self {
        Self(name)
    }

    pub const fn as_str(self) -> &'static str {
        self.0
    }
}

/// An open scope: closed when dropped. Derefs to the scopes, for the work inside it.
pub struct Scope<'a, S: Scopes + ?Sized> {
    scopes: &'a mut S,
    ctx: &'a Context,
    cmd: vk::CommandBuffer,
}

impl<S: Scopes + ?Sized> Drop for Scope<'_, S> {
    fn drop(&mut self) {
        self.scopes.end(self.ctx, self.cmd);
    }
}

impl<S: Scopes + ?Sized> std::ops::Deref for Scope<'_, S> {
    type Target = S;
    fn deref(&self) -> &S {
        self.scopes
    }
}

impl<S: Scopes + ?Sized> std::ops::DerefMut for Scope<'_, S> {
    fn deref_mut(&mut self) -> &mut S {
        self.scopes
    }
}

/// Opening a scope as a guard, on any [`Scopes`] (a profiler, labels, `dyn Scopes`).
pub trait Open: Scopes {
    fn open<'a>(
        &'a mut self,
        ctx: &'a Context,
        cmd: vk::CommandBuffer,
        name: ScopeName,
    ) -> Scope<'a, Self> {
        self.begin(ctx, cmd, name);
        Scope {
            scopes: self,
            ctx,
            cmd,
        }
    }
}

impl<S: Scopes + ?Sized> Open for S {}

pub struct Labels;

impl Scopes for Labels {
    fn begin(&mut self, ctx: &Context, cmd: vk::CommandBuffer, name: ScopeName) {
        ctx.begin_label(cmd, name.as_str());
    }
    fn end(&mut self, ctx: &Context, cmd: vk::CommandBuffer) {
        ctx.end_label(cmd);
    }
}

impl Scopes for Profiler {
    fn begin(&mut self, ctx: &Context, cmd: vk::CommandBuffer, name: ScopeName) {
        Profiler::open_scope(self, ctx, cmd, name.as_str())
    }
    fn end(&mut self, ctx: &Context, cmd: vk::CommandBuffer) {
        Profiler::close_scope(self, ctx, cmd)
    }
}

/// A timestamp scope's key, shared by the code that records the scope and the code that
/// reads its timings: the names of the scopes open around it and its own, joined by `/`
/// (`render/density`). The recording code opens it by `name()` inside its parents; a reader
/// that finds no such scope gets an error naming the ones recorded, never a NaN.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ScopeKey {
    path: &'static str,
    name: &'static str,
}

impl ScopeKey {
    pub const fn new(path: &'static str) -> Self {
        let b = path.as_bytes();
        let mut i = b.len();
        while i > 0 && b[i - 1] != b'/' {
            i -= 1;
        }
        let name = match std::str::from_utf8(b.split_at(i).1) {
            Ok(n) => n,
            Err(_) => path,
        };
        Self { path, name }
    }

    /// The whole path: the key in frame timings, summaries and tables.
    pub const fn path(self) -> &'static str {
        self.path
    }

    /// The scope's own name, opened inside its parent scopes.
    pub const fn name(self) -> &'static str {
        self.name
    }

    /// The scope to open, inside its parents, for this key.
    pub const fn scope(self) -> ScopeName {
        ScopeName(self.name)
    }

    /// The error for a reader that did not find this scope among `recorded`.
    pub fn missing<'a>(self, recorded: impl Iterator<Item = &'a str>) -> Error {
        let names: Vec<&str> = recorded.collect();
        Error::Bug(format!(
            "timestamp scope '{}' was not recorded (recorded: {})",
            self.path,
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        ))
    }

    /// This scope's milliseconds in one frame's timing (summed over its repeats).
    pub fn ms_in(self, t: &FrameTiming) -> Result<f64> {
        t.pass_ms(self.path)
            .ok_or_else(|| self.missing(t.passes.iter().map(|(k, _)| k.as_str())))
    }
}

impl std::fmt::Display for ScopeKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.path)
    }
}

/// Name of the scope that spans a whole frame.
pub const FRAME_SCOPE: &str = "frame";
/// The whole frame: its time is each `FrameTiming`'s `frame_ms`, not one of its passes.
pub const FRAME: ScopeKey = ScopeKey::new(FRAME_SCOPE);

impl Profiler {
    /// `slots` frames in flight.
    pub fn new(ctx: &Context, slots: usize) -> Result<Self> {
        let mut v = Vec::new();
        for _ in 0..slots {
            v.push(Slot {
                pools: Vec::new(),
                scopes: Vec::new(),
                parents: Vec::new(),
                used: 0,
                frame: None,
                cpu_ns: None,
            });
        }
        let bits = ctx.info.timestamp_valid_bits;
        let mut p = Self {
            slots: v,
            settle: ctx.info.loop_budget.is_some(),
            period_ns: ctx.info.timestamp_period_ns as f64,
            mask: if bits >= 64 {
                u64::MAX
            } else {
                (1u64 << bits) - 1
            },
            stack: Vec::new(),
            timed: ScopeDepth::All.depth(),
            current: 0,
            results: Vec::new(),
        };
        for i in 0..slots {
            if let Err(e) = p.add_pool(ctx, i) {
                p.destroy(ctx);
                return Err(e);
            }
        }
        Ok(p)
    }

    fn add_pool(&mut self, ctx: &Context, slot: usize) -> Result<()> {
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(POOL_QUERIES);
        let pool = unsafe { ctx.device.create_query_pool(&info, None) }.ctx("query pool")?;
        ctx.count_object("query pool", 1);
        let s = &mut self.slots[slot];
        ctx.set_name(
            pool,
            &format!("timestamps slot {slot} pool {}", s.pools.len()),
        );
        // Queries must be reset before first use; a host reset needs no command buffer.
        unsafe { ctx.device.reset_query_pool(pool, 0, POOL_QUERIES) };
        s.pools.push(pool);
        Ok(())
    }

    /// Which scopes write timestamps from the next frame on (`--scopes`; default all).
    pub fn time_scopes(&mut self, depth: ScopeDepth) {
        self.timed = depth.depth();
    }

    /// Start recording frame `frame` into `slot` (whose previous results were collected).
    pub fn begin_frame(&mut self, ctx: &Context, cmd: vk::CommandBuffer, slot: usize, frame: u64) {
        let s = &mut self.slots[slot];
        debug_assert!(s.frame.is_none(), "slot {slot} not collected");
        for &pool in &s.pools {
            unsafe { ctx.device.cmd_reset_query_pool(cmd, pool, 0, POOL_QUERIES) };
        }
        s.scopes.clear();
        s.parents.clear();
        s.used = 0;
        s.frame = Some(frame);
        self.current = slot;
        self.stack.clear();
        self.open_scope(ctx, cmd, FRAME_SCOPE);
    }

    pub fn end_frame(&mut self, ctx: &Context, cmd: vk::CommandBuffer) {
        while !self.stack.is_empty() {
            self.close_scope(ctx, cmd);
        }
    }

    /// The next query, adding a (host-reset, unused) pool when the slot's are full.
    fn next_query(&mut self, ctx: &Context) -> Option<(vk::QueryPool, u32)> {
        let slot = self.current;
        if self.slots[slot].used >= self.slots[slot].pools.len() as u32 * POOL_QUERIES
            && self.add_pool(ctx, slot).is_err()
        {
            return None;
        }
        let s = &mut self.slots[slot];
        let q = s.used;
        s.used += 1;
        Some((s.pools[(q / POOL_QUERIES) as usize], q))
    }

    /// Open a named scope: a debug label and a timestamp, keyed by its path (through
    /// `Scopes`, whose guard closes it).
    fn open_scope(&mut self, ctx: &Context, cmd: vk::CommandBuffer, name: &str) {
        ctx.begin_label(cmd, name);
        let key = match self.stack.last() {
            Some((_, parent)) if parent != FRAME_SCOPE => format!("{parent}/{name}"),
            _ => name.to_string(),
        };
        let untimed = self.stack.len() > self.timed;
        let begin = (!untimed).then(|| self.next_query(ctx)).flatten();
        let end = (!untimed).then(|| self.next_query(ctx)).flatten();
        let (b, e) = match (begin, end) {
            (Some((pool, q)), Some(_)) => {
                unsafe {
                    ctx.device.cmd_write_timestamp2(
                        cmd,
                        vk::PipelineStageFlags2::ALL_COMMANDS,
                        pool,
                        q % POOL_QUERIES,
                    )
                };
                self.settle_timestamp(ctx, cmd);
                (q, q + 1)
            }
            // Deeper than --scopes times: the label alone.
            _ if untimed => (UNTIMED, UNTIMED),
            // No query pool could be made: keep the label, report at collect.
            _ => (u32::MAX, u32::MAX),
        };
        let parent = self.stack.last().map(|(i, _)| *i);
        let s = &mut self.slots[self.current];
        s.scopes.push((key.clone(), b, e));
        s.parents.push(parent);
        self.stack.push((s.scopes.len() - 1, key));
    }

    fn close_scope(&mut self, ctx: &Context, cmd: vk::CommandBuffer) {
        let Some((i, _)) = self.stack.pop() else {
            return;
        };
        let s = &self.slots[self.current];
        let (_, _, q) = s.scopes[i];
        if q != u32::MAX && q != UNTIMED {
            unsafe {
                ctx.device.cmd_write_timestamp2(
                    cmd,
                    vk::PipelineStageFlags2::ALL_COMMANDS,
                    s.pools[(q / POOL_QUERIES) as usize],
                    q % POOL_QUERIES,
                )
            };
            self.settle_timestamp(ctx, cmd);
        }
        ctx.end_label(cmd);
    }

    /// On llvmpipe: a stall right after a timestamp, so it resolves now (see `settle`).
    fn settle_timestamp(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        if !self.settle {
            return;
        }
        // lavapipe executes a pipeline barrier as a stall (flush and wait), which resolves
        // the timestamp just binned before any later work starts.
        ctx.profiler_stall(cmd);
    }

    /// Read `slot`'s results; call only after that slot's fence has signalled.
    pub fn collect(&mut self, ctx: &Context, slot: usize) -> Result<()> {
        let s = &mut self.slots[slot];
        let Some(frame) = s.frame.take() else {
            return Ok(());
        };
        if s.scopes.iter().any(|(_, q, _)| *q == u32::MAX) {
            return Err(Error::Memory(format!(
                "profiler: no query pool could be added for frame {frame}"
            )));
        }
        let mut raw = vec![0u64; s.used as usize];
        for (k, chunk) in raw.chunks_mut(POOL_QUERIES as usize).enumerate() {
            unsafe {
                ctx.device.get_query_pool_results(
                    s.pools[k],
                    0,
                    chunk,
                    vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
                )
            }
            .ctx("read timestamps")?;
        }
        let ms = |a: u32, b: u32| {
            let ticks = raw[b as usize].wrapping_sub(raw[a as usize]) & self.mask;
            ticks as f64 * self.period_ns / 1e6
        };
        // The frame scope is opened first: query 0 is the frame's first timestamp.
        let first = raw.first().copied().unwrap_or(0);
        let mut passes = Vec::new();
        let mut starts = Vec::new();
        let mut parents = Vec::new();
        // Scope index -> pass index (the frame scope is no pass).
        let mut pass_of = vec![None; s.scopes.len()];
        let mut frame_ms = 0.0;
        for (k, (name, a, b)) in s.scopes.iter().enumerate() {
            if *a == UNTIMED {
                continue; // deeper than --scopes times (so are its children)
            }
            if name == FRAME_SCOPE && s.parents[k].is_none() {
                frame_ms = ms(*a, *b);
            } else {
                pass_of[k] = Some(passes.len());
                parents.push(s.parents[k].and_then(|p| pass_of[p]));
                passes.push((name.clone(), ms(*a, *b)));
                starts.push(ms(0, *a));
            }
        }
        self.results.push(FrameTiming {
            frame,
            passes,
            frame_ms,
            starts,
            parents,
            gpu_ns: (first & self.mask) as f64 * self.period_ns,
            cpu_ns: s.cpu_ns.take(),
        });
        Ok(())
    }

    /// When the CPU recorded and submitted the frame in `slot` (CLOCK_MONOTONIC ns).
    pub fn note_cpu(&mut self, slot: usize, begin_ns: f64, end_ns: f64) {
        self.slots[slot].cpu_ns = Some((begin_ns, end_ns));
    }

    /// Drop a slot's recording that was never submitted.
    pub fn forget(&mut self, slot: usize) {
        self.slots[slot].frame = None;
        self.stack.clear();
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for s in self.slots.drain(..) {
            for pool in s.pools {
                unsafe { ctx.device.destroy_query_pool(pool, None) };
                ctx.count_object("query pool", -1);
            }
        }
    }
}

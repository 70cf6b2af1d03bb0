//! Buffer hazards of one command buffer, tracked from what each command reads and writes
//! (dispatches from their SPIR-V, `gpu::access`; copies, fills and updates; indirect
//! arguments), and the barrier a command needs placed before it: after a write, a later
//! read or write of that buffer gets one unless an earlier barrier already made the write
//! visible to it; after reads, a later write waits for them; reads after reads and
//! commands on other buffers get none. Barriers recorded by hand count too, so the tracker
//! places only what they leave out (zero where the hand placement is complete).
//! Draws get their barriers before their rendering scope begins: the pipelines drawn there
//! declare their uses first (`GraphicsPipeline::prepare`), and a draw in the scope finds
//! its uses declared. A draw that was not declared is tracked but never given a barrier
//! (none may be recorded inside a rendering scope): a hazard found there is counted in
//! `unplaced`. Host reads after the fence are uses of the host stage.
use super::sync::Access;
use ash::vk;
use std::collections::HashMap;

type Stages = vk::PipelineStageFlags2;
type Accesses = vk::AccessFlags2;

/// One buffer's use by a command: the stage, and its read and write access bits (empty when
/// it does not read, or does not write).
#[derive(Clone, Copy, Debug)]
pub struct BufferUse {
    pub buffer: vk::Buffer,
    /// The bytes [start, end) it touches (the whole buffer unless said).
    pub range: (u64, u64),
    pub stage: Stages,
    pub read: Accesses,
    pub write: Accesses,
}

impl BufferUse {
    pub fn compute(buffer: vk::Buffer, read: bool, write: bool) -> Self {
        let a = vk::AccessFlags2::SHADER_STORAGE_READ;
        let w = vk::AccessFlags2::SHADER_STORAGE_WRITE;
        Self::at(buffer, Stages::COMPUTE_SHADER, (read, a), (write, w))
    }

    pub fn transfer(buffer: vk::Buffer, write: bool) -> Self {
        let a = vk::AccessFlags2::TRANSFER_READ;
        let w = vk::AccessFlags2::TRANSFER_WRITE;
        Self::at(buffer, Stages::ALL_TRANSFER, (!write, a), (write, w))
    }

    /// The host reading the buffer (mapped) after the command buffer's fence.
    pub fn host(buffer: vk::Buffer) -> Self {
        let a = vk::AccessFlags2::HOST_READ;
        Self::at(buffer, Stages::HOST, (true, a), (false, Accesses::NONE))
    }

    pub fn indirect(buffer: vk::Buffer) -> Self {
        let a = vk::AccessFlags2::INDIRECT_COMMAND_READ;
        Self::at(
            buffer,
            Stages::DRAW_INDIRECT,
            (true, a),
            (false, Accesses::NONE),
        )
    }

    pub fn at(
        buffer: vk::Buffer,
        stage: Stages,
        (r, read): (bool, Accesses),
        (w, write): (bool, Accesses),
    ) -> Self {
        Self {
            buffer,
            range: (0, u64::MAX),
            stage,
            read: if r { read } else { Accesses::NONE },
            write: if w { write } else { Accesses::NONE },
        }
    }

    /// Only `size` bytes from `offset` (a copy's region, a descriptor's view).
    pub fn bytes(self, offset: u64, size: u64) -> Self {
        Self {
            range: (offset, offset.saturating_add(size)),
            ..self
        }
    }
}

/// `d` (a declared use) covers `u`: the same buffer, stage and accesses, over its bytes.
fn covers(d: &BufferUse, u: &BufferUse) -> bool {
    d.buffer == u.buffer
        && d.stage.contains(u.stage)
        && d.read.contains(u.read)
        && d.write.contains(u.write)
        && d.range.0 <= u.range.0
        && u.range.1 <= d.range.1
}

fn overlap(a: (u64, u64), b: (u64, u64)) -> bool {
    a.0 < b.1 && b.0 < a.1
}

fn hull(a: (u64, u64), b: (u64, u64)) -> (u64, u64) {
    (a.0.min(b.0), a.1.max(b.1))
}

/// Every stage a barrier's ALL_COMMANDS stands for here.
fn stages(s: Stages) -> Stages {
    if s.contains(Stages::ALL_COMMANDS) {
        return Stages::from_raw(u64::MAX);
    }
    s
}

/// The stages a barrier waits for when its source mask is `s`: execution dependencies
/// include the logically earlier stages (an indirect dispatch reads its arguments before
/// its shader runs; vertex shading precedes fragment shading).
fn earlier(s: Stages) -> Stages {
    let mut out = stages(s);
    let graphics = Stages::FRAGMENT_SHADER
        | Stages::EARLY_FRAGMENT_TESTS
        | Stages::LATE_FRAGMENT_TESTS
        | Stages::COLOR_ATTACHMENT_OUTPUT;
    if out.intersects(graphics) {
        out |= Stages::VERTEX_SHADER;
    }
    if out.intersects(Stages::COMPUTE_SHADER | Stages::VERTEX_SHADER) {
        out |= Stages::DRAW_INDIRECT;
    }
    out
}

/// The stages a barrier holds back when its destination mask is `s` (and the logically
/// later ones).
fn later(s: Stages) -> Stages {
    let mut out = stages(s);
    if out.contains(Stages::DRAW_INDIRECT) {
        out |= Stages::COMPUTE_SHADER | Stages::VERTEX_SHADER;
    }
    if out.contains(Stages::VERTEX_SHADER) {
        out |= Stages::FRAGMENT_SHADER;
    }
    out
}

/// MEMORY_READ and MEMORY_WRITE stand for every read and every write.
fn accesses(a: Accesses) -> Accesses {
    let mut out = a;
    if a.contains(Accesses::MEMORY_READ) {
        out |= Accesses::SHADER_STORAGE_READ
            | Accesses::TRANSFER_READ
            | Accesses::INDIRECT_COMMAND_READ
            | Accesses::HOST_READ;
    }
    if a.contains(Accesses::MEMORY_WRITE) {
        out |= Accesses::SHADER_STORAGE_WRITE | Accesses::TRANSFER_WRITE | Accesses::HOST_WRITE;
    }
    out
}

#[derive(Clone, Copy, Default)]
struct State {
    /// The last writes (their stages and bytes) and where they are visible.
    write: Option<Access>,
    written: (u64, u64),
    visible: Option<Access>,
    /// Stages that read since the last write (their bytes), and the stages ordered after.
    reads: Stages,
    read: (u64, u64),
    after_reads: Stages,
}

impl State {
    /// Record `u` (its hazards already ordered).
    fn record(&mut self, u: &BufferUse) {
        if !u.write.is_empty() {
            let w = Access {
                stage: u.stage,
                access: u.write,
            };
            match self.write {
                // Other bytes than a write still pending: both stay pending (a later
                // reader of either waits for both).
                Some(old) if !overlap(self.written, u.range) => {
                    (self.write, self.visible) = (Some(old | w), None);
                    self.written = hull(self.written, u.range);
                }
                _ => (self.write, self.written, self.visible) = (Some(w), u.range, None),
            }
            if overlap(self.read, u.range) {
                (self.reads, self.read, self.after_reads) = (Stages::NONE, (0, 0), Stages::NONE);
            }
        }
        if !u.read.is_empty() {
            self.read = match self.reads.is_empty() {
                true => u.range,
                false => hull(self.read, u.range),
            };
            self.reads |= u.stage;
            // This read is ordered before nothing yet (an earlier barrier covered only the
            // reads before it).
            self.after_reads = Stages::NONE;
        }
    }
}

/// Commands recorded into one command buffer so far: what a pass sequence costs the
/// device's front end (each barrier drains the compute pipe; an indirect dispatch with
/// zero groups still costs its launch and its barrier).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Recorded {
    /// Compute dispatches, direct and indirect.
    pub dispatches: u32,
    /// Of them, indirect (their group counts live on the device: may be empty).
    pub indirect: u32,
    /// Pipeline barriers (placed by the tracker or recorded by hand).
    pub barriers: u32,
    /// Buffer updates and fills (transfer commands).
    pub transfers: u32,
}

impl std::ops::Add for Recorded {
    type Output = Recorded;
    fn add(self, o: Recorded) -> Recorded {
        Recorded {
            dispatches: self.dispatches + o.dispatches,
            indirect: self.indirect + o.indirect,
            barriers: self.barriers + o.barriers,
            transfers: self.transfers + o.transfers,
        }
    }
}

impl std::ops::Sub for Recorded {
    type Output = Recorded;
    fn sub(self, o: Recorded) -> Recorded {
        Recorded {
            dispatches: self.dispatches - o.dispatches,
            indirect: self.indirect - o.indirect,
            barriers: self.barriers - o.barriers,
            transfers: self.transfers - o.transfers,
        }
    }
}

/// The hazards of one command buffer being recorded.
#[derive(Default)]
pub struct Tracker {
    buffers: HashMap<vk::Buffer, State>,
    /// The commands recorded so far.
    pub recorded: Recorded,
    /// Which recording this is: a command buffer begun again gets a new one.
    pub serial: u64,
    /// Barriers the tracker placed, and hazards it found where it may place none.
    pub placed: u32,
    pub unplaced: u32,
    /// Uses of the draws of the rendering scope being recorded: checked against what came
    /// before the scope, recorded at its end (draws of one scope are not ordered).
    deferred: Vec<BufferUse>,
    /// Uses of the next rendering scope's draws, declared (their barriers placed and the
    /// uses recorded) before it began.
    declared: Vec<BufferUse>,
}

impl Tracker {
    /// The barrier (from, to) a command with `uses` needs first, if any; the uses are
    /// recorded after it. `place`: whether the barrier will be recorded (else a hazard is
    /// counted in `unplaced`).
    pub fn before(&mut self, uses: &[BufferUse], place: bool) -> Option<(Access, Access)> {
        // A draw's uses declared before its scope are already recorded.
        // (Only draws inside a scope are filtered: dispatches take their uses as given.)
        let undeclared: Vec<BufferUse>;
        let uses = match place || self.declared.is_empty() {
            true => uses,
            false => {
                undeclared = uses
                    .iter()
                    .filter(|u| !self.declared.iter().any(|d| covers(d, u)))
                    .copied()
                    .collect();
                &undeclared[..]
            }
        };
        let none = Access {
            stage: Stages::NONE,
            access: Accesses::NONE,
        };
        let (mut from, mut to) = (none, none);
        for u in uses {
            let s = self.buffers.get(&u.buffer).copied().unwrap_or_default();
            let need = Access {
                stage: u.stage,
                access: u.read | u.write,
            };
            if let Some(w) = s.write.filter(|_| overlap(s.written, u.range)) {
                let seen = s.visible.is_some_and(|v| {
                    stages(v.stage).contains(need.stage) && accesses(v.access).contains(need.access)
                });
                if !seen {
                    (from, to) = (from | w, to | need);
                }
            }
            let ordered = s.after_reads.contains(u.stage);
            let after_read = !s.reads.is_empty() && overlap(s.read, u.range);
            if !u.write.is_empty() && after_read && !ordered {
                from.stage |= s.reads;
                to.stage |= u.stage;
            }
        }
        let barrier = (!from.stage.is_empty()).then_some((from, to));
        if let Some((f, t)) = barrier {
            if place {
                self.placed += 1;
                self.barrier(f, t);
            } else {
                self.unplaced += 1;
            }
        }
        if place {
            for u in uses {
                self.buffers.entry(u.buffer).or_default().record(u);
            }
        } else {
            self.deferred.extend_from_slice(uses);
        }
        barrier
    }

    /// The draws of the next rendering scope will have `uses`: the barrier they need is
    /// placed now (returned), and the scope's draws find them declared.
    pub fn declare(&mut self, uses: &[BufferUse]) -> Option<(Access, Access)> {
        let b = self.before(uses, true);
        self.declared.extend_from_slice(uses);
        b
    }

    /// The host reads `uses` (host-stage uses) after the fence: the barrier that makes
    /// their writes visible there. A buffer with no use in this command buffer gets one
    /// from every device write (its last write was in an earlier one).
    pub fn host_read(&mut self, uses: &[BufferUse]) -> Option<(Access, Access)> {
        let unknown = uses.iter().any(|u| !self.buffers.contains_key(&u.buffer));
        let placed = self.before(uses, true);
        if !unknown {
            return placed;
        }
        let all =
            super::sync::COMPUTE_WRITE | super::sync::TRANSFER_WRITE | super::sync::FRAGMENT_WRITE;
        let host = super::sync::HOST_READ;
        if placed.is_none() {
            self.placed += 1;
        }
        self.barrier(all, host);
        Some(match placed {
            Some((f, t)) => (f | all, t | host),
            None => (all, host),
        })
    }

    /// The rendering scope ended: its draws' uses are recorded.
    pub fn end_scope(&mut self) {
        self.declared.clear();
        for u in std::mem::take(&mut self.deferred) {
            self.buffers.entry(u.buffer).or_default().record(&u);
        }
    }

    /// A barrier from `from` to `to` was recorded (by hand, or placed by `before`).
    pub fn barrier(&mut self, from: Access, to: Access) {
        // Memory: only the stages named; execution: the logically earlier ones too.
        let (fs, fa, wait) = (
            stages(from.stage),
            accesses(from.access),
            earlier(from.stage),
        );
        for s in self.buffers.values_mut() {
            if let Some(w) = s.write {
                let direct = fs.contains(w.stage) && fa.contains(w.access);
                // Chained: an earlier barrier made the write visible to stages this one waits on.
                let chained = s.visible.is_some_and(|v| wait.intersects(stages(v.stage)));
                if direct || chained {
                    s.visible = Some(match s.visible {
                        Some(v) => v | to,
                        None => to,
                    });
                }
            }
            let direct = wait.contains(s.reads);
            let chained = wait.intersects(s.after_reads);
            if !s.reads.is_empty() && (direct || chained) {
                s.after_reads |= later(to.stage);
            }
        }
    }
}

/// The trackers of the command buffers being recorded (one per `begin`), in the context.
#[derive(Default)]
pub struct Trackers {
    open: HashMap<vk::CommandBuffer, Tracker>,
    /// Barriers placed and hazards left unplaced in the command buffers submitted so far.
    pub placed: u64,
    pub unplaced: u64,
    /// `FLUIDFORM_TRACK_DEBUG` set (read once, with the context): print each barrier placed.
    pub debug: bool,
    /// Recordings begun so far.
    serials: u64,
}

impl Trackers {
    pub fn new() -> Self {
        Self {
            debug: std::env::var_os("FLUIDFORM_TRACK_DEBUG").is_some(),
            ..Self::default()
        }
    }

    pub fn begin(&mut self, cmd: vk::CommandBuffer) {
        self.serials += 1;
        let serial = self.serials;
        self.open.insert(
            cmd,
            Tracker {
                serial,
                ..Tracker::default()
            },
        );
    }

    pub fn get(&mut self, cmd: vk::CommandBuffer) -> &mut Tracker {
        let next = self.serials + 1;
        let t = self.open.entry(cmd).or_insert_with(|| Tracker {
            serial: next,
            ..Tracker::default()
        });
        if t.serial == next {
            self.serials = next;
        }
        t
    }

    /// The command buffer is submitted: its counts join the totals.
    pub fn end(&mut self, cmd: vk::CommandBuffer) {
        if let Some(t) = self.open.remove(&cmd) {
            self.placed += t.placed as u64;
            self.unplaced += t.unplaced as u64;
        }
    }
}

//! `--control-every K`: the control's sums refreshed every K steps instead of every step.
//! A refresh step runs the whole control (densities at the control particles, the cell sums
//! and field, the eq. 7 walk) and stores each fluid particle's eq. 7 sum and mean control
//! velocity; the steps between gather those into their own particle order through the
//! step's sort permutation and apply them with their own density and velocity, reading the
//! stored field at their own position. The control target moves with the frame, so every
//! new pose (a frame's first step), a change in the particle count and an attach refresh too.
use crate::error::{Error, Result};
use crate::gpu::{Buffer, Context, Guard};
use crate::sph::solver::SphState;

/// Most steps between refreshes.
pub const MAX_EVERY: u32 = 1000;

/// Per fluid particle: eq. 7's sum (vec4) and the mean control velocity (vec4), twice: the
/// last step's order and this step's.
pub struct ForceCache {
    force: [Buffer; 2],
    vmean: [Buffer; 2],
    /// Which of the two holds the latest values.
    cur: usize,
    capacity: u64,
    /// Steps recorded since the last refresh, and the particle count then (the first step
    /// always refreshes: it has a new pose).
    since: u32,
    n: u32,
}

impl ForceCache {
    /// Buffers for `capacity` fluid particles.
    pub fn new(ctx: &Context, capacity: u64) -> Result<Self> {
        let buf = |name: &str| {
            ctx.storage_buffer(name, capacity.max(1) * 16)
                .map(|b| Guard::new(ctx, b))
        };
        let (f0, f1) = (buf("control force cache 0")?, buf("control force cache 1")?);
        let (v0, v1) = (buf("control vmean cache 0")?, buf("control vmean cache 1")?);
        Ok(Self {
            force: [f0.take(), f1.take()],
            vmean: [v0.take(), v1.take()],
            cur: 0,
            capacity,
            since: 0,
            n: 0,
        })
    }

    /// Whether the step about to be recorded for `st` refreshes (every `every` steps, and
    /// after a new pose: `posed`); counts the step, and between refreshes makes the other
    /// pair current (see `gathers`).
    pub fn step(&mut self, st: &SphState, every: u32, posed: bool) -> Result<bool> {
        if st.particles.capacity > self.capacity {
            return Err(Error::Bug(format!(
                "control force cache of {} particles for a state of {}",
                self.capacity, st.particles.capacity
            )));
        }
        let refresh = posed || st.n != self.n || self.since + 1 >= every.max(1);
        if refresh {
            (self.since, self.n) = (0, st.n);
        } else {
            self.since += 1;
            self.cur = 1 - self.cur;
        }
        Ok(refresh)
    }

    /// The buffers the force pass writes on a refresh (this step's order).
    pub fn current(&self) -> (&Buffer, &Buffer) {
        (&self.force[self.cur], &self.vmean[self.cur])
    }

    /// Between refreshes: (the last step's, this step's) buffers of the force and of vmean, to
    /// gather from the one into the other.
    pub fn gathers(&self) -> [(&Buffer, &Buffer); 2] {
        let (s, d) = (1 - self.cur, self.cur);
        [
            (&self.force[s], &self.force[d]),
            (&self.vmean[s], &self.vmean[d]),
        ]
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for b in self.force.iter_mut().chain(self.vmean.iter_mut()) {
            ctx.destroy_buffer(b);
        }
    }
}
crate::impl_destroy!(ForceCache);

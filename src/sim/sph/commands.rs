//! What a step costs the device's front end: its dispatches, barriers and transfers as
//! recorded (`gpu::Recorded`), the pressure solver's share, and the dispatches recorded
//! for iterations past a solve's stop, which run empty (their group count zeroed on the
//! device). On a GPU each dependent dispatch costs a launch and a barrier's drain whatever
//! its work: these counts, not the time of a pass, show what the testbed adds.
use crate::gpu::Recorded;
use serde::{Deserialize, Serialize};

/// What one step recorded.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StepCommands {
    /// The whole step: its parameters to its last pass, hooks included.
    pub step: Recorded,
    /// The pressure solver's passes, from the first after the arrange to the last (force
    /// hooks excluded).
    pub solver: Recorded,
    /// Iterations recorded per solve (density, divergence; 0 where there is none).
    pub iterations: [u32; 2],
    /// Dispatches of one recorded iteration (each runs empty once its solve has stopped).
    pub per_iteration: u32,
}

impl StepCommands {
    /// The dispatches that ran empty, given the iterations each solve used.
    pub fn empty(&self, used: [u32; 2]) -> u32 {
        (0..2)
            .map(|d| self.iterations[d].saturating_sub(used[d]) * self.per_iteration)
            .sum()
    }
}

/// A step's counts: dispatches, barriers, the solver's dispatches and barriers, empty
/// dispatches.
pub type StepCounts = [u32; 5];

/// A run's commands per step: means over its steps, the median step's (the usual step:
/// the first frame records the most iterations, before any count is back), and the last
/// step's.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CommandStats {
    pub steps: u64,
    /// Per count of [`StepCounts`], its median over the steps.
    pub median: StepCounts,
    pub dispatches: f64,
    pub barriers: f64,
    pub transfers: f64,
    /// The pressure solver's share (see [`StepCommands::solver`]).
    pub solver_dispatches: f64,
    pub solver_barriers: f64,
    /// Dispatches that ran empty (recorded iterations past their solve's stop).
    pub empty_dispatches: f64,
    pub last: StepCommands,
    pub last_empty: u32,
    /// Every step's commands and empty dispatches: the means and medians are taken from
    /// them in `finished`.
    #[serde(skip)]
    seen: Vec<(StepCommands, u32)>,
}

impl CommandStats {
    /// One more step, with the iterations its solves used.
    pub fn add(&mut self, c: &StepCommands, used: [u32; 2]) {
        let empty = c.empty(used);
        (self.last, self.last_empty) = (*c, empty);
        self.steps += 1;
        self.seen.push((*c, empty));
    }

    /// With the means and medians over the steps so far.
    pub fn finished(&self) -> Self {
        let counts: Vec<StepCounts> = (self.seen.iter())
            .map(|(c, e)| {
                let (s, v) = (c.step, c.solver);
                [s.dispatches, s.barriers, v.dispatches, v.barriers, *e]
            })
            .collect();
        let n = counts.len();
        let median = match n {
            0 => [0; 5],
            n => std::array::from_fn(|k| {
                let mut v: Vec<u32> = counts.iter().map(|c| c[k]).collect();
                *v.select_nth_unstable(n / 2).1
            }),
        };
        let mean =
            |f: &dyn Fn(usize) -> u32| (0..n).map(|i| f(i) as f64).sum::<f64>() / n.max(1) as f64;
        Self {
            median,
            dispatches: mean(&|i| counts[i][0]),
            barriers: mean(&|i| counts[i][1]),
            transfers: mean(&|i| self.seen[i].0.step.transfers),
            solver_dispatches: mean(&|i| counts[i][2]),
            solver_barriers: mean(&|i| counts[i][3]),
            empty_dispatches: mean(&|i| counts[i][4]),
            ..self.clone()
        }
    }
}

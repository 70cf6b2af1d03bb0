//! A row's statistics under the measurement protocol: the median of its per-round medians,
//! the interquartile range of its frames, and a 95% interval for that median from a seeded
//! bootstrap over the rounds (a round is one stretch of device state, so resampling rounds
//! rather than frames carries a slow stretch into the interval). Verdicts compare intervals:
//! an effect counts only where the intervals do not overlap.
use rand::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};

/// Bootstrap resamples behind an interval.
pub const RESAMPLES: usize = 2000;

#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Interval {
    /// Median of the per-round medians (ms).
    pub median: f64,
    /// Interquartile range of every timed frame (ms).
    pub q1: f64,
    pub q3: f64,
    /// 95% bootstrap interval of the median (ms).
    pub lo: f64,
    pub hi: f64,
}

impl Interval {
    /// The interval of `rounds` (each round's frame values), bootstrap seeded by `seed`.
    pub fn of_rounds(rounds: &[Vec<f64>], seed: u64) -> Option<Self> {
        let meds: Vec<f64> = rounds.iter().filter_map(|r| median(r)).collect();
        let all: Vec<f64> = rounds.iter().flatten().copied().collect();
        let (lo, hi) = bootstrap_median(&meds, RESAMPLES, seed)?;
        Some(Self {
            median: median(&meds)?,
            q1: quantile(&all, 0.25)?,
            q3: quantile(&all, 0.75)?,
            lo,
            hi,
        })
    }

    /// Relative half-width of the interval (0.05: ±5%).
    pub fn rel_width(&self) -> f64 {
        0.5 * (self.hi - self.lo) / self.median.abs().max(1e-12)
    }

    /// How `self` stands against `other`: below, above, or overlapping.
    pub fn against(&self, other: &Interval) -> Standing {
        if self.hi < other.lo {
            Standing::Below
        } else if self.lo > other.hi {
            Standing::Above
        } else {
            Standing::Overlap
        }
    }

    /// "0.712 ms [0.70, 0.73]".
    pub fn text(&self) -> String {
        format!("{:.3} ms [{:.3}, {:.3}]", self.median, self.lo, self.hi)
    }
}

/// What a finding compares: a row's interval, and whether the protocol flagged the row
/// (a round stayed off after its rerun), in which case it decides nothing.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Estimate {
    pub interval: Interval,
    pub flagged: bool,
}

impl Estimate {
    /// "0.712 ms [0.70, 0.73]", with " flagged" after a flagged row's.
    pub fn text(&self) -> String {
        match self.flagged {
            true => format!("{} flagged", self.interval.text()),
            false => self.interval.text(),
        }
    }
}

/// Where one interval stands against another.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Standing {
    Below,
    Above,
    Overlap,
}

/// Median (mean of the middle two for even counts); None when empty.
pub fn median(v: &[f64]) -> Option<f64> {
    quantile(v, 0.5)
}

/// Linear-interpolated quantile `q` in [0, 1] (type 7, R's default); None when empty.
pub fn quantile(v: &[f64], q: f64) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(|a, b| a.total_cmp(b));
    let h = (s.len() - 1) as f64 * q.clamp(0.0, 1.0);
    let (i, f) = (h.floor() as usize, h - h.floor());
    Some(match s.get(i + 1) {
        Some(&next) => s[i] + f * (next - s[i]),
        None => s[i],
    })
}

/// The 95% percentile-bootstrap interval of the median of `v`: `resamples` resamples with
/// replacement, seeded by `seed`. One value gives a zero-width interval.
pub fn bootstrap_median(v: &[f64], resamples: usize, seed: u64) -> Option<(f64, f64)> {
    if v.is_empty() {
        return None;
    }
    let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
    let mut meds = Vec::with_capacity(resamples);
    let mut draw = vec![0.0; v.len()];
    for _ in 0..resamples.max(1) {
        for d in draw.iter_mut() {
            *d = v[rng.random_range(0..v.len())];
        }
        meds.push(median(&draw)?);
    }
    Some((quantile(&meds, 0.025)?, quantile(&meds, 0.975)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_of_a_known_list() {
        let v = [4.0, 1.0, 3.0, 2.0, 5.0];
        assert_eq!(median(&v), Some(3.0));
        assert_eq!(quantile(&v, 0.25), Some(2.0));
        assert_eq!(quantile(&[1.0, 2.0], 0.5), Some(1.5));
        assert_eq!(median(&[]), None);
    }

    #[test]
    fn standing_needs_separate_intervals() {
        let a = Interval {
            median: 1.0,
            lo: 0.9,
            hi: 1.1,
            ..Default::default()
        };
        let b = Interval {
            median: 1.3,
            lo: 1.2,
            hi: 1.4,
            ..Default::default()
        };
        let c = Interval {
            median: 1.05,
            lo: 1.0,
            hi: 1.2,
            ..Default::default()
        };
        assert_eq!(a.against(&b), Standing::Below);
        assert_eq!(b.against(&a), Standing::Above);
        assert_eq!(a.against(&c), Standing::Overlap);
    }
}

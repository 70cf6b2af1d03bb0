//! Where a number comes from: the build (commit, compiler), when it was measured (UTC), and
//! how (repetitions, warm-up). Every table page and `protocol.json` carry it; the device
//! and driver sit beside it in each summary's `device`.
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Provenance {
    pub commit: String,
    pub rustc: String,
    /// UTC, `YYYY-MM-DDTHH:MM:SSZ`.
    pub date: String,
    pub frames: u64,
    pub warmup: u64,
}

impl Provenance {
    pub fn now(frames: u64, warmup: u64) -> Self {
        Self {
            commit: env!("FLUIDFORM_COMMIT").into(),
            rustc: env!("FLUIDFORM_RUSTC").into(),
            date: utc_now(),
            frames,
            warmup,
        }
    }
}

/// Now in UTC as `YYYY-MM-DDTHH:MM:SSZ`.
pub fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    let s = secs % 86_400;
    format!(
        "{}T{:02}:{:02}:{:02}Z",
        crate::bench::plot::date_of(secs / 86_400),
        s / 3600,
        s / 60 % 60,
        s % 60
    )
}

//! Where a number comes from: the build (commit, compiler), when it was measured (UTC), and
//! how (repetitions, warm-up). Every summary.json, table page and `protocol.json` carry it;
//! the device and driver sit beside it in each summary's `device`. The binary names its
//! build once at start (`set_build`); a library user that does not reads "unknown".
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

static BUILD: OnceLock<(String, String)> = OnceLock::new();

/// The commit and compiler the binary was built with (set once; later calls are ignored).
pub fn set_build(commit: &str, rustc: &str) {
    let _ = BUILD.set((commit.to_string(), rustc.to_string()));
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Provenance {
    pub commit: String,
    pub rustc: String,
    /// UTC, `YYYY-MM-DDTHH:MM:SSZ`.
    pub date: String,
    /// Timed frames and warm-up frames per configuration, where the command has them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frames: Option<u64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub warmup: Option<u64>,
}

impl Provenance {
    pub fn now(frames: Option<u64>, warmup: Option<u64>) -> Self {
        let (commit, rustc) = BUILD
            .get()
            .cloned()
            .unwrap_or_else(|| ("unknown".into(), "unknown".into()));
        Self {
            commit,
            rustc,
            date: utc_now(),
            frames,
            warmup,
        }
    }
}

fn now_secs() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0)
}

/// Now in UTC as `YYYY-MM-DDTHH:MM:SSZ`.
pub fn utc_now() -> String {
    let secs = now_secs();
    let s = secs % 86_400;
    format!(
        "{}T{:02}:{:02}:{:02}Z",
        date_of(secs / 86_400),
        s / 3600,
        s / 60 % 60,
        s % 60
    )
}

/// Today (UTC) as YYYY-MM-DD.
pub fn today() -> String {
    date_of(now_secs() / 86_400)
}

/// The date (YYYY-MM-DD) `days` after 1970-01-01 (Howard Hinnant's civil-from-days).
pub fn date_of(days: u64) -> String {
    let z = days as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + (m <= 2) as i64;
    format!("{y:04}-{m:02}-{d:02}")
}

#[cfg(test)]
mod tests {
    #[test]
    fn civil_dates() {
        assert_eq!(super::date_of(0), "1970-01-01");
        assert_eq!(super::date_of(20_819), "2027-01-01");
        assert_eq!(super::date_of(11_016), "2000-02-29");
    }
}

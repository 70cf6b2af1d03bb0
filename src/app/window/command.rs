//! What the viewer can be told, by a key, a control of the overlay, or a script
//! (`--at FRAME:COMMAND`): one text form, parsed here, carried out by the session.
use std::path::PathBuf;

#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// `set FLAG VALUE`: a switch of `run` (without dashes), as on its command line.
    Set(String, String),
    /// `unset FLAG`: back to the scene's or the parser's default.
    Unset(String),
    /// `cycle FLAG`: the switch's next value (keys).
    Cycle(String),
    Pause,
    Resume,
    TogglePause,
    /// One frame's simulation, then paused.
    Step,
    /// The scene rebuilt from its start with the current switches.
    Reset,
    /// Simulated time per frame, times the scene's.
    Speed(f64),
    /// `speed xK`: the speed times K (keys: x2, x0.5).
    SpeedTimes(f64),
    /// `seek T`: jump to scene time T (s) by re-simulating from the start.
    Seek(f64),
    /// `screenshot FILE [WxH]`: the picture as PNG, at the window's size or at WxH.
    Screenshot(PathBuf, Option<(u32, u32)>),
    /// `record DIR`: every frame to DIR as PNGs; `record stop` writes DIR/animation.png.
    Record(PathBuf),
    RecordStop,
    CameraHome,
    CameraFly(bool),
    /// `resize W H`: ask the window for this inner size.
    Resize(u32, u32),
    Minimize(bool),
    /// Print (and copy) the `fluidform run` command line of the current switches.
    Copy,
    TogglePanel,
    Quit,
}

impl Command {
    pub fn parse(text: &str) -> Result<Self, String> {
        let words: Vec<&str> = text.split_whitespace().collect();
        let num = |s: &str| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("'{s}' is not a number"))
        };
        let size = |w: &str, h: &str| -> Result<(u32, u32), String> {
            match (w.parse::<u32>(), h.parse::<u32>()) {
                (Ok(w), Ok(h)) if w > 0 && h > 0 => Ok((w, h)),
                _ => Err(format!("'{w} {h}' is not a size in pixels")),
            }
        };
        Ok(match words.as_slice() {
            ["set", flag, value @ ..] if !value.is_empty() => {
                Self::Set(flag.trim_start_matches('-').into(), value.join(" "))
            }
            ["unset", flag] => Self::Unset(flag.trim_start_matches('-').into()),
            ["cycle", flag] => Self::Cycle(flag.trim_start_matches('-').into()),
            ["pause"] => Self::Pause,
            ["resume"] => Self::Resume,
            ["toggle-pause"] => Self::TogglePause,
            ["step"] => Self::Step,
            ["reset"] => Self::Reset,
            ["speed", x] if x.starts_with('x') => match num(&x[1..])? {
                v if v > 0.0 => Self::SpeedTimes(v),
                v => return Err(format!("speed x{v}: must be above 0")),
            },
            ["speed", x] => match num(x)? {
                v if v > 0.0 && v <= 16.0 => Self::Speed(v),
                v => return Err(format!("speed {v}: must be in (0, 16]")),
            },
            ["seek", t] => match num(t)? {
                v if v >= 0.0 => Self::Seek(v),
                v => return Err(format!("seek {v}: time must be at least 0")),
            },
            ["screenshot", file] => Self::Screenshot(file.into(), None),
            ["screenshot", file, wh] => {
                let (w, h) = wh.split_once(['x', 'X']).ok_or("size must be WxH")?;
                Self::Screenshot(file.into(), Some(size(w, h)?))
            }
            ["record", "stop"] => Self::RecordStop,
            ["record", dir] => Self::Record(dir.into()),
            ["camera", "home"] => Self::CameraHome,
            ["camera", "fly"] => Self::CameraFly(true),
            ["camera", "orbit"] => Self::CameraFly(false),
            ["resize", w, h] => {
                let (w, h) = size(w, h)?;
                Self::Resize(w, h)
            }
            ["minimize"] => Self::Minimize(true),
            ["restore"] => Self::Minimize(false),
            ["copy"] => Self::Copy,
            ["panel"] => Self::TogglePanel,
            ["quit"] => Self::Quit,
            _ => {
                return Err(format!(
                    "unknown viewer command '{text}' (see `fluidform view --help`)"
                ))
            }
        })
    }
}

/// `--at FRAME:COMMAND`: a command carried out before frame FRAME.
pub fn parse_at(s: &str) -> Result<(u64, Command), String> {
    let (f, c) = s
        .split_once(':')
        .ok_or_else(|| format!("'{s}': expected FRAME:COMMAND, e.g. 3:set list sbuffer"))?;
    let f = f
        .trim()
        .parse::<u64>()
        .map_err(|_| format!("'{f}' is not a frame number"))?;
    Ok((f, Command::parse(c)?))
}

/// The keys, as `--help` and the overlay list them.
pub const KEYS: &[(&str, &str)] = &[
    ("Space", "pause / resume"),
    ("N", "one frame's simulation (paused)"),
    ("R", "reset the scene"),
    ("+ / -", "simulation speed x2 / /2"),
    ("L", "next list mode (--list)"),
    ("B", "next density function (--density)"),
    ("M", "next material (--material)"),
    ("H", "camera home (the scene's)"),
    ("F", "fly mode on/off (W A S D, E up, C down)"),
    ("mouse", "left drag orbit/look, right drag pan, wheel zoom"),
    ("P", "screenshot to view_NNNN.png"),
    ("V", "start/stop recording to view_recording/"),
    ("Tab", "hide/show the panel"),
    ("Esc / Q", "quit"),
];

/// The key list as one block of text.
pub fn keys_help() -> String {
    let mut s = String::from("Keys:\n");
    for (k, what) in KEYS {
        s.push_str(&format!("  {k:<8} {what}\n"));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_forms_keys_and_scripts_use() {
        assert_eq!(
            Command::parse("set list sbuffer"),
            Ok(Command::Set("list".into(), "sbuffer".into()))
        );
        assert_eq!(
            Command::parse("set --density murakami"),
            Ok(Command::Set("density".into(), "murakami".into()))
        );
        assert_eq!(
            Command::parse("screenshot a.png 64x48"),
            Ok(Command::Screenshot("a.png".into(), Some((64, 48))))
        );
        assert_eq!(parse_at("3:pause"), Ok((3, Command::Pause)));
        assert!(Command::parse("speed 0").is_err());
        assert!(Command::parse("resize 0 5").is_err());
        assert!(Command::parse("fly away").is_err());
        assert!(parse_at("x:pause").is_err());
    }
}

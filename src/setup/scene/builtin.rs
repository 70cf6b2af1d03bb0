//! The built-in scenes: TOML files under scenes/, embedded in the binary and read by the
//! same code as a user's (`load.rs`). `fluidform scene list` and `scene show NAME` print
//! them, to copy and edit.

/// One embedded scene file.
pub struct BuiltIn {
    pub name: &'static str,
    pub text: &'static str,
}

macro_rules! scene {
    ($name:literal) => {
        BuiltIn {
            name: $name,
            text: include_str!(concat!("../../../scenes/", $name, ".toml")),
        }
    };
}

/// Every built-in, fluid scenes first, then particle scenes (`orbits`, the test scene that
/// makes its particles in code, is not a file: see `crate::orbits`).
pub const BUILT_IN: &[BuiltIn] = &[
    scene!("demo"),
    scene!("dam-break"),
    scene!("drop"),
    scene!("resting-block"),
    scene!("walker"),
    scene!("character"),
    scene!("giraffe"),
    scene!("union"),
    scene!("morph"),
    scene!("two-groups"),
    scene!("trail"),
    scene!("game"),
    scene!("fountain"),
    scene!("smoke"),
    scene!("flock"),
    scene!("rain"),
];

pub fn find(name: &str) -> Option<&'static BuiltIn> {
    BUILT_IN.iter().find(|b| b.name == name)
}

pub fn names() -> Vec<&'static str> {
    BUILT_IN.iter().map(|b| b.name).collect()
}

impl BuiltIn {
    /// The file's opening comment, joined into one line (what `scene list` prints).
    pub fn summary(&self) -> String {
        let lines = self.text.lines().map(str::trim);
        let comment: Vec<&str> = lines
            .take_while(|l| l.starts_with('#'))
            .map(|l| l.trim_start_matches('#').trim())
            .collect();
        comment.join(" ")
    }
}

/// `fluidform scene list`: a line per built-in (name, kind, opening comment), then orbits.
pub fn listing() -> String {
    use super::load::{kind_of, SceneKind};
    let mut out = String::new();
    for b in BUILT_IN {
        let kind = match kind_of(b.text) {
            SceneKind::Fluid => "fluid",
            SceneKind::Particles => "particles",
        };
        out += &format!("{:<14} {kind:<10} {}\n", b.name, b.summary());
    }
    out += &format!(
        "{:<14} {:<10} particles orbiting an attractor, made in code (no file)\n",
        "orbits", "test"
    );
    out
}

/// `fluidform scene show NAME`: the built-in's TOML.
pub fn shown(name: &str) -> crate::error::Result<&'static str> {
    use crate::error::Error;
    match find(name) {
        Some(b) => Ok(b.text),
        None if name == "orbits" => Err(Error::Param(
            "orbits makes its particles in code: it has no scene file".into(),
        )),
        None => Err(Error::Param(format!(
            "no built-in scene '{name}' (fluidform scene list: {})",
            names().join(", ")
        ))),
    }
}

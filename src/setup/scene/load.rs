//! Reading scenes: a user's TOML file and a built-in's embedded one go through the same
//! parse, with the same checks; errors name the line, the column and the key's path.
use super::builtin;
use super::particles::ParticleScene;
use super::schema::Scene;
use crate::error::{Error, Result};
use serde::de::DeserializeOwned;
use std::path::Path;

/// What a scene's TOML describes: fluid (a `[domain]`) or particle systems alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneKind {
    Fluid,
    Particles,
}

/// Which kind `text` is: particle scenes have `[[system]]` and no `[domain]` or `[pool]` (SPH
/// scenes may hold systems too; a liquid character's domain may be fitted). Text too
/// malformed to parse counts as a particle scene when it declares them so, and its error is
/// the particle scene's.
pub fn kind_of(text: &str) -> SceneKind {
    let declares = |table: &str| text.lines().any(|l| l.trim_start().starts_with(table));
    let particles = match text.parse::<toml::Table>() {
        Ok(t) => t.contains_key("system") && !t.contains_key("domain") && !t.contains_key("pool"),
        Err(_) => declares("[[system]]") && !declares("[domain]") && !declares("[pool]"),
    };
    match particles {
        true => SceneKind::Particles,
        false => SceneKind::Fluid,
    }
}

/// `text` read as a `T`; an error names `origin`, the line and column, and the key's path.
pub fn parse<T: DeserializeOwned>(origin: &str, text: &str) -> Result<T> {
    let de = toml::Deserializer::parse(text).map_err(|e| toml_error(origin, text, &e, ""))?;
    serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        let path = match path.as_str() {
            "." | "" => String::new(),
            p => format!(" {p}:"),
        };
        toml_error(origin, text, e.inner(), &path)
    })
}

/// A scene file's parse error as one line: where (line, column, the key's path), then what
/// (the parser's own text draws the line).
pub fn toml_error(origin: &str, text: &str, e: &toml::de::Error, path: &str) -> Error {
    let at = e.span().map(|r| {
        let before = &text[..r.start.min(text.len())];
        let line = before.matches('\n').count() + 1;
        let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
        format!(" line {line} column {col}:")
    });
    Error::Param(format!(
        "scene {origin}:{}{path} {}",
        at.unwrap_or_default(),
        e.message().trim().replace('\n', " ")
    ))
}

/// The text of a built-in scene or of the file `name_or_path`, with the origin errors
/// name and the folder its relative paths start from (None for a built-in); None when it
/// is neither.
fn source(name_or_path: &str) -> Result<Option<(String, String, Option<&Path>)>> {
    if let Some(b) = builtin::find(name_or_path) {
        return Ok(Some((format!("built-in {}", b.name), b.text.into(), None)));
    }
    let path = Path::new(name_or_path);
    if !path.is_file() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(path).map_err(|e| Error::Io {
        path: name_or_path.into(),
        source: e,
    })?;
    let dir = path.parent().unwrap_or(Path::new("."));
    Ok(Some((format!("file {name_or_path}"), text, Some(dir))))
}

impl Scene {
    /// A built-in fluid scene by name, or a fluid scene file.
    pub fn load(name_or_path: &str) -> Result<Self> {
        let Some((origin, text, dir)) = source(name_or_path)? else {
            return Err(Error::Param(format!(
                "unknown scene '{name_or_path}': not a built-in ({}, orbits) nor an existing file",
                builtin::names().join(", ")
            )));
        };
        Self::from_text(&origin, &text, dir)
    }

    /// The built-in fluid scene `name` (`fluidform scene list`).
    pub fn built_in(name: &str) -> Result<Self> {
        match builtin::find(name) {
            Some(b) if kind_of(b.text) == SceneKind::Fluid => {
                Self::from_text(&format!("built-in {name}"), b.text, None)
                    .map_err(|e| Error::Bug(format!("the built-in scene {name}: {e}")))
            }
            _ => Err(Error::Param(format!("no built-in fluid scene '{name}'"))),
        }
    }

    /// The dam break's scene reduced to a box from the origin to `domain` holding `blocks`
    /// of `fluid`, with no balls or colliders (experiments and tests).
    pub fn water_box(
        fluid: crate::sph::FluidParams,
        domain: [f32; 3],
        blocks: Vec<super::schema::Block>,
    ) -> Result<Self> {
        let mut s = Self::built_in("dam-break")?;
        s.name = "water box".into();
        s.domain = super::schema::Domain {
            min: [0.0; 3],
            max: domain,
        };
        s.fluid = fluid;
        s.blocks = blocks;
        s.balls.clear();
        s.colliders.clear();
        Ok(s)
    }

    /// A scene from its TOML `text`; character files are named relative to `dir`.
    pub fn from_text(origin: &str, text: &str, dir: Option<&Path>) -> Result<Self> {
        let mut s: Scene = parse(origin, text)?;
        // A liquid character's file that leaves [fluid] out gets the built-in liquid
        // characters' water (Kelager's defaults take 10 ms ideal-gas steps).
        let has_fluid = toml::from_str::<toml::Table>(text).is_ok_and(|t| t.contains_key("fluid"));
        if !has_fluid && (s.control.is_some() || !s.targets.is_empty()) {
            s.fluid = parse(origin, RELEASED_WATER)?;
        }
        if let Some(dir) = dir {
            let chars = s.character.iter_mut();
            for c in chars.chain(s.targets.iter_mut().map(|t| &mut t.character)) {
                let f = Path::new(&c.file);
                if !c.file.starts_with("builtin:") && f.is_relative() {
                    c.file = dir.join(f).display().to_string();
                }
            }
        }
        if s.character.is_some() && s.has_fluid() {
            s.look.water();
        }
        super::around::fit_around(&mut s)?;
        s.validate()?;
        Ok(s)
    }
}

/// The water of scenes that release their control targets (the built-in `character`'s
/// `[fluid]`): a metre's collapse hits the pool at about 4.4 m/s, and weakly compressible
/// SPH wants c >= 10 v; c = 40 m/s, 24 steps of 0.45 ms a frame, walls with a little
/// friction (a drained pool's film races along a frictionless floor's edges), and a
/// viscosity of 20 (Kelager's 3.5 let the water held in a shape circulate: CesiumMan's
/// speed excess 1.71 -> 0.88 m/s, a standing figure's 2.5 -> 1.5 m/s, fill and iou held;
/// results/<device>/control-fidelity.md).
const RELEASED_WATER: &str = r#"
eos = "tait"
sound_speed = 40.0
clamp_negative_pressure = true
dt = 0.00045
substeps = 24
friction = 0.02
viscosity = 20.0
"#;

impl ParticleScene {
    /// A built-in particle scene, or a TOML file with `[[system]]` tables; None for any
    /// other scene (the caller tries the fluid scenes).
    pub fn find(name_or_path: &str) -> Result<Option<Self>> {
        let Some((origin, text, dir)) = source(name_or_path)? else {
            return Ok(None);
        };
        if kind_of(&text) != SceneKind::Particles {
            return Ok(None);
        }
        let mut s: Self = parse(&origin, &text)?;
        if s.name.is_empty() {
            s.name = Path::new(name_or_path)
                .file_stem()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
        }
        if let (Some(c), Some(dir)) = (&mut s.character, dir) {
            let f = Path::new(&c.file);
            if !c.file.starts_with("builtin:") && f.is_relative() {
                c.file = dir.join(f).display().to_string();
            }
        }
        s.validate()?;
        Ok(Some(s))
    }

    /// The built-in particle scene `name`.
    pub fn built_in(name: &str) -> Result<Self> {
        match builtin::find(name).map(|b| kind_of(b.text)) {
            Some(SceneKind::Particles) => Self::find(name)?
                .ok_or_else(|| Error::Bug(format!("the built-in particle scene {name}"))),
            _ => Err(Error::Param(format!("no built-in particle scene '{name}'"))),
        }
    }
}

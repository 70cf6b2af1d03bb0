//! `fluidform inspect FILE`: the character's report, and with `--picture PNG` its rest pose
//! from the front and the side (character::picture), the views and the up axis named on it.
use crate::bench::plot::{err, font};
use crate::character::{anim::Up, picture, Character};
use crate::error::Result;
use plotters::prelude::*;
use std::path::Path;

/// `fluidform inspect FILE [--up AXIS] [--picture PNG] [--json]`: the report to print
/// (text or JSON), the picture drawn when asked.
pub fn inspect(file: &str, up: Option<Up>, picture: Option<&Path>, json: bool) -> Result<String> {
    let ch = crate::character::load(file)?;
    let u = up.unwrap_or_default();
    let report = crate::character::inspect::inspect(&ch, u, up.is_some())?;
    if let Some(p) = picture {
        inspect_png(&ch, u, p)?;
    }
    Ok(match json {
        true => {
            serde_json::to_string_pretty(&report)
                .map_err(|e| crate::error::Error::Param(e.to_string()))?
                + "\n"
        }
        false => report.text(),
    })
}

/// Draw `ch` turned by `up` into `path` (PNG).
pub fn inspect_png(ch: &Character, up: Up, path: &Path) -> Result<()> {
    font()?;
    let mut img = picture::draw(ch, up.matrix())?;
    let (w, h) = img.dimensions();
    {
        let root = BitMapBackend::with_buffer(&mut img, (w, h)).into_drawing_area();
        let style = ("sans-serif", 15).into_font().color(&BLACK);
        let v = picture::VIEW as i32;
        let labels = [
            (8, 6, format!("front (from +Z)   up = \"{}\"", up.name())),
            (v + 8, 6, "side (from +X, front to the left)".to_string()),
            (
                8,
                24,
                "red: skeleton   brown: the floor it stands on".to_string(),
            ),
        ];
        for (x, y, t) in labels {
            root.draw(&Text::new(t, (x, y), style.clone()))
                .map_err(|e| err(path, e))?;
        }
        root.present().map_err(|e| err(path, e))?;
    }
    img.save(path).map_err(|e| err(path, e))
}

//! An animated PNG (APNG) of a run's saved frames, written frame by frame as they are
//! retired: every current browser plays it, and each frame keeps PNG's lossless colour.
use crate::error::{Error, Result};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

pub struct Animation {
    writer: Option<png::Writer<BufWriter<File>>>,
    path: PathBuf,
    size: (u32, u32),
}

fn err(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Image {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

impl Animation {
    /// An animation of exactly `frames` RGBA8 frames of `width` x `height`, shown at `fps`.
    pub fn create(path: &Path, width: u32, height: u32, frames: u32, fps: u16) -> Result<Self> {
        let file = File::create(path).map_err(|e| Error::Io {
            path: path.display().to_string(),
            source: e,
        })?;
        let mut enc = png::Encoder::new(BufWriter::new(file), width, height);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_animated(frames.max(1), 0)
            .map_err(|e| err(path, e))?;
        enc.set_frame_delay(1, fps.max(1))
            .map_err(|e| err(path, e))?;
        let writer = enc.write_header().map_err(|e| err(path, e))?;
        Ok(Self {
            writer: Some(writer),
            path: path.to_path_buf(),
            size: (width, height),
        })
    }

    /// Append the next frame.
    pub fn add(&mut self, rgba: &[u8], width: u32, height: u32) -> Result<()> {
        if (width, height) != self.size {
            return Err(err(&self.path, "a frame of another size"));
        }
        let w = self
            .writer
            .as_mut()
            .ok_or_else(|| err(&self.path, "finished"))?;
        w.write_image_data(rgba).map_err(|e| err(&self.path, e))
    }

    /// Close the file (every announced frame must have been added).
    pub fn finish(mut self) -> Result<PathBuf> {
        if let Some(w) = self.writer.take() {
            w.finish().map_err(|e| err(&self.path, e))?;
        }
        Ok(self.path)
    }
}

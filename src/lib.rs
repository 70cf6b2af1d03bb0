//! fluidform: a Rust + Vulkan research testbed for liquid characters.
//! See README.md for the command line and outputs.
pub mod animation;
pub mod bench;
pub mod character;
pub mod config;
pub mod control;
pub mod emission;
pub mod error;
pub mod experiment;
pub mod export;
pub mod gpu;
pub mod kinds;
pub mod particles;
pub mod primitives;
pub mod progress;
pub mod psys;
pub mod render;
pub mod report;
pub mod run;
pub mod scene;
pub mod session;
pub mod shaders;
pub mod sph;
pub mod surface;
pub mod viewer;
pub mod window;

pub use error::{Error, Result};

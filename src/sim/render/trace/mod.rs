//! An independent shading reference: a small CPU ray tracer over analytic spheres, in
//! f64, sharing no code with the metaball shaders or their CPU marcher. Its optics come
//! from textbook sources (`optics`), its environment is the renderer's procedural sky as
//! specified (`env`), and a metaball is the sphere where its density function (PAPERS.md
//! section 4) equals the threshold. Tests render the same camera with both and compare.
pub mod env;
pub mod optics;
pub mod tracer;

pub use env::Env;
pub use tracer::{iso_radius, Look, Reference, Sphere};

//! Built-in scenes. Until the fluid lands, `orbits` is the default test scene.
pub mod orbits;

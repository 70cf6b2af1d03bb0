//! Scene parts beside the SPH scenes: the `orbits` test scene and characters.
pub mod character;
pub mod emission;
pub mod fit;
pub mod orbits;
pub mod targets;

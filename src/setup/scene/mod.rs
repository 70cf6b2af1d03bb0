//! Scenes: the schema and its built-ins, and the descriptions of the parts a scene plays
//! beside the fluid (characters, control targets, emission); they play in `run`. The `orbits` test scene is made in code
//! (`crate::orbits`).
pub mod around;
pub mod builtin;
pub mod character;
pub mod emission;
pub mod fit;
pub mod load;
pub mod particles;
pub mod schema;

pub use schema::Scene;

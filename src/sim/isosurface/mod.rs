//! Polygon surfaces of the fluid: marching cubes over a density grid (`cubes`, with its
//! case table built from the cube's faces in `table`), and the mesh files other tools read
//! (`files`: OBJ, binary PLY). The CPU version here is the reference a GPU pass is checked
//! against.
pub mod cubes;
pub mod files;
pub mod table;

pub use cubes::{density_grid, density_on, march, Grid, Mesh};

/// The fluid's surface level: half the rest density (the mesh export's and the GPU
/// marching cubes').
pub const ISO: f32 = 0.5;

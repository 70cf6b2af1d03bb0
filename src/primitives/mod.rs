//! Reusable GPU algorithms, each with a CPU reference in `cpu`: prefix sum, bounds
//! reduction, Morton codes, sorting networks, atomic-grid counting sort, neighbour search.
pub mod bounds;
pub mod counting;
pub mod cpu;
pub mod morton;
pub mod neighbors;
pub mod scan;
pub mod sort;

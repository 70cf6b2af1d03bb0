//! A uniform hash grid of point indices on the CPU (the fidelity metrics' densities and
//! neighbour counts, the shape's fill at control particles).
use glam::{IVec3, Vec3};
use std::collections::HashMap;

/// A uniform hash grid of particle indices (cell = h).
pub struct Grid {
    cell: f32,
    cells: HashMap<IVec3, Vec<u32>>,
}

impl Grid {
    pub fn new(pos: &[Vec3], keep: impl Fn(usize) -> bool, cell: f32) -> Self {
        let mut cells: HashMap<IVec3, Vec<u32>> = HashMap::new();
        for (i, p) in pos.iter().enumerate().filter(|(i, _)| keep(*i)) {
            cells
                .entry((*p / cell).floor().as_ivec3())
                .or_default()
                .push(i as u32);
        }
        Self { cell, cells }
    }

    /// Every stored index within the 27 cells about `p`.
    pub fn near(&self, p: Vec3) -> impl Iterator<Item = u32> + '_ {
        let c = (p / self.cell).floor().as_ivec3();
        (0..27).flat_map(move |k| {
            let d = IVec3::new(k % 3 - 1, (k / 3) % 3 - 1, k / 9 - 1);
            self.cells.get(&(c + d)).into_iter().flatten().copied()
        })
    }
}

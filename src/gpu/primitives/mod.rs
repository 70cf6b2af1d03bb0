//! Reusable GPU algorithms, each with a CPU reference in `cpu`: prefix sum, bounds
//! reduction, Morton codes, sorting networks, atomic-grid counting sort, neighbour search.
pub mod bounds;
pub mod counting;
pub mod cpu;
pub mod morton;
mod nb_passes;
pub mod neighbors;
pub mod scan;
pub mod sort;

crate::impl_destroy!(
    scan::ScanPass,
    scan::ScanScratch,
    sort::NetworkSort,
    counting::CountingSort,
    counting::CountingBuffers,
    counting::GatherPass,
    bounds::BoundsPass,
    bounds::BoundsBuffers,
    morton::MortonPass,
    neighbors::NeighborSearch,
    neighbors::NeighborBuffers,
);

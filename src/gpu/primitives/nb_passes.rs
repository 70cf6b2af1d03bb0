//! The neighbour search's passes as declarations, with the key every pass that includes
//! neighbors.glsl is built with.
use super::neighbors::{NbKeysIo, NbQueryIo, NbRangesIo, NeighborSearch};
use crate::kinds::{Neighbors, SortAlgo};
use crate::pass::{Defines, PassKey};

/// A neighbour search's shader variant: its strategy and whether its sort counts cells.
/// Every pass that includes neighbors.glsl is keyed by it (or by a key holding it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NbKey {
    pub strategy: Neighbors,
    pub sort: SortAlgo,
}

impl PassKey for NbKey {
    /// Every strategy with every sort it accepts (Morton's 30-bit codes take no counting).
    fn all() -> Vec<Self> {
        let mut v = Vec::new();
        for strategy in Neighbors::all() {
            for sort in [SortAlgo::Counting, SortAlgo::OddEven, SortAlgo::Bitonic] {
                if !(*strategy == Neighbors::Morton && sort == SortAlgo::Counting) {
                    v.push(Self {
                        strategy: *strategy,
                        sort,
                    });
                }
            }
        }
        v
    }
    fn defines(&self) -> Defines {
        NeighborSearch::defines_for(self.strategy, self.sort)
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect()
    }
}

/// The cell-key pass's variants: every search but Morton's, which makes its keys itself.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CellKeys(pub NbKey);

impl PassKey for CellKeys {
    fn all() -> Vec<Self> {
        let v = NbKey::all().into_iter();
        v.filter(|k| k.strategy != Neighbors::Morton)
            .map(Self)
            .collect()
    }
    fn defines(&self) -> Defines {
        self.0.defines()
    }
}

crate::compute_pass!(pub CELL_KEYS: NbKeysIo, CellKeys = "cell keys", "primitives/nb_keys.comp");
crate::compute_pass!(pub CELL_RANGES: NbRangesIo, NbKey = "cell ranges", "primitives/nb_ranges.comp");
crate::compute_pass!(pub NEIGHBOR_QUERY: NbQueryIo, NbKey = "neighbor query", "primitives/nb_query.comp");

//! Fixed-radius neighbour search, `--neighbors morton|grid|hash` (with `--sort`):
//! - grid: uniform-grid cell keys, counting sort (seed 002) by default;
//! - hash: hashed cell keys (Teschner) sorted by a network sort (Le Grand's baseline);
//! - morton: Morton codes in the GPU-reduced bounding box, odd-even sort, and a per-query
//!   code range from the query box's corners (seed 000).
//!
//! Build: keys -> sort -> cell ranges. Query: reorder positions, lists per particle.
//! Other passes (SPH) iterate neighbours with glsl/primitives/neighbors.glsl and the
//! same bindings via `defines()` and `cell_buffers()`.
use super::bounds::{BoundsBuffers, BoundsPass};
use super::counting::{CountingBuffers, CountingSort, GatherPass};
use super::morton::MortonPass;
pub use super::nb_passes::{CellKeys, NbKey};
use super::nb_passes::{CELL_KEYS, CELL_RANGES, NEIGHBOR_QUERY};
use super::scan::{ScanPass, ScanVariant};
use super::sort::{Network, NetworkSort};
use crate::error::{Error, Result};
use crate::kinds::{Neighbors, SortAlgo};
use crate::Open;
use crate::{Buffer, ComputePipeline, Context, Guard, Scopes};
use ash::vk;
use bytemuck::{Pod, Zeroable};

const KEYS_SCOPE: crate::ScopeName = crate::ScopeName::new("keys");
const QUERY_SCOPE: crate::ScopeName = crate::ScopeName::new("query");
const RANGES_SCOPE: crate::ScopeName = crate::ScopeName::new("ranges");
const REORDER_SCOPE: crate::ScopeName = crate::ScopeName::new("reorder");
const SORT_SCOPE: crate::ScopeName = crate::ScopeName::new("sort");

/// A uniform grid: origin, cell size (>= search radius) and cell counts per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridSpec {
    pub origin: [f32; 3],
    pub cell: f32,
    pub dims: [u32; 3],
}

/// Most grid cells a `grid` search may use.
pub const MAX_CELLS: u64 = 1 << 26;

impl GridSpec {
    /// The grid of cells of size `cell` covering the box [lo, hi].
    pub fn covering(lo: [f32; 3], hi: [f32; 3], cell: f32) -> Result<Self> {
        if !(cell > 0.0 && cell.is_finite()) {
            return Err(Error::Param(format!(
                "grid cell size must be positive, got {cell}"
            )));
        }
        let mut dims = [1u32; 3];
        for k in 0..3 {
            let ext = hi[k] - lo[k];
            if !(ext >= 0.0 && ext.is_finite()) {
                return Err(Error::Param(format!("invalid grid box {lo:?}..{hi:?}")));
            }
            dims[k] = ((ext / cell).ceil() as u64).clamp(1, 1 << 20) as u32;
        }
        Self {
            origin: lo,
            cell,
            dims,
        }
        .checked()
    }

    /// The same box in cells of half the size (twice the cells per axis, same origin).
    pub fn halved(&self) -> Result<Self> {
        Self {
            cell: 0.5 * self.cell,
            dims: self.dims.map(|d| 2 * d),
            ..*self
        }
        .checked()
    }

    /// This grid, or an error when it has more than MAX_CELLS cells.
    fn checked(self) -> Result<Self> {
        if self.cells() > MAX_CELLS {
            let d = self.dims;
            return Err(Error::Param(format!(
                "a grid of {}x{}x{} cells exceeds {MAX_CELLS}: raise the cell size (radius)",
                d[0], d[1], d[2]
            )));
        }
        Ok(self)
    }

    pub fn cells(&self) -> u64 {
        self.dims.iter().map(|&d| d as u64).product()
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct NeighborPush {
    pub origin_cell: [f32; 4],
    pub dims: [u32; 4],
    pub radius: f32,
    pub n: u32,
    pub max_neighbors: u32,
    pub pad: u32,
}
const _: () = assert!(std::mem::size_of::<NeighborPush>() == 48);

crate::gpu_interface! {
    /// glsl/primitives/nb_keys.comp
    pub NbKeysIo / NbKeysBufs: "NBK", push NeighborPush {
        pos = 0, keys = 1, vals = 2, counts = 3, rank = 4,
    }
}

crate::gpu_interface! {
    /// glsl/primitives/nb_ranges.comp; push: n.
    pub NbRangesIo / NbRangesBufs: "NBR", push u32 { keys = 0, start = 1, end = 2 }
}

crate::gpu_interface! {
    /// glsl/primitives/nb_query.comp (neighbors.glsl's cell bindings are nb_*).
    pub NbQueryIo / NbQueryBufs: "NBQ", push NeighborPush {
        pos = 0, nb_keys = 1, nb_start = 2, nb_end = 3, nb_box = 4,
        counts = 5, list = 6, visited = 7,
    }
}

/// The default sort of each strategy.
pub fn default_sort(strategy: Neighbors) -> SortAlgo {
    match strategy {
        Neighbors::Grid => SortAlgo::Counting,
        Neighbors::Hash => SortAlgo::Bitonic,
        Neighbors::Morton => SortAlgo::OddEven,
    }
}

enum Sorter {
    Network(NetworkSort),
    Counting(CountingSort),
}

impl crate::Destroy for Sorter {
    fn destroy(&mut self, ctx: &Context) {
        match self {
            Sorter::Counting(c) => c.destroy(ctx),
            Sorter::Network(s) => s.destroy(ctx),
        }
    }
}

/// Pipelines of one strategy + sort.
pub struct NeighborSearch {
    pub strategy: Neighbors,
    pub sort: SortAlgo,
    scan: ScanPass,
    sorter: Sorter,
    keys: Option<ComputePipeline<NbKeysIo>>,
    bounds: Option<BoundsPass>,
    morton: Option<MortonPass>,
    ranges: ComputePipeline<NbRangesIo>,
    gather: GatherPass,
    query: ComputePipeline<NbQueryIo>,
}

/// Sized buffers for up to `capacity` particles.
pub struct NeighborBuffers {
    keys: Buffer,
    vals: Buffer,
    /// Keys in sorted order (cell ids, hashes or Morton codes).
    pub sorted_keys: Buffer,
    /// Sorted slot -> original particle index.
    pub perm: Buffer,
    /// Positions in sorted order.
    pub sorted_pos: Buffer,
    starts: Buffer,
    ends: Buffer,
    counting: Option<CountingBuffers>,
    bounds: Option<BoundsBuffers>,
    /// Query results (sorted order): neighbour count, list, candidates visited.
    pub counts: Buffer,
    pub list: Buffer,
    pub visited: Buffer,
    pub capacity: u64,
    pub table: u32,
    pub max_neighbors: u32,
}

impl NeighborBuffers {
    pub fn destroy(&mut self, ctx: &Context) {
        for b in [
            &mut self.keys,
            &mut self.vals,
            &mut self.sorted_keys,
            &mut self.perm,
            &mut self.sorted_pos,
            &mut self.starts,
            &mut self.ends,
            &mut self.counts,
            &mut self.list,
            &mut self.visited,
        ] {
            ctx.destroy_buffer(b);
        }
        if let Some(c) = &mut self.counting {
            c.destroy(ctx);
        }
        if let Some(b) = &mut self.bounds {
            b.destroy(ctx);
        }
    }

    /// Cell buffers for neighbors.glsl: (starts, ends-or-counts).
    pub fn cell_buffers(&self) -> (&Buffer, &Buffer) {
        match &self.counting {
            Some(c) => (&c.starts, &c.counts),
            None => (&self.starts, &self.ends),
        }
    }

    /// The bounding box buffer for morton (a dummy for the others).
    pub fn box_buffer(&self) -> &Buffer {
        self.bounds
            .as_ref()
            .map(|b| &b.result)
            .unwrap_or(&self.starts)
    }
}

impl NeighborSearch {
    pub fn new(ctx: &Context, strategy: Neighbors, sort: Option<SortAlgo>) -> Result<Self> {
        let sort = sort.unwrap_or(default_sort(strategy));
        if sort == SortAlgo::None {
            return Err(Error::Param(
                "--sort none applies only to particle-system sprites: the neighbour search needs a sort (odd-even, bitonic or counting)".into(),
            ));
        }
        if strategy == Neighbors::Morton && sort == SortAlgo::Counting {
            return Err(Error::Param(
                "--neighbors morton sorts 30-bit codes: use --sort odd-even or bitonic (counting needs bounded cell keys)".into(),
            ));
        }
        let key = NbKey { strategy, sort };
        let morton = strategy == Neighbors::Morton;
        // Each part is released if a later one fails.
        let scan = Guard::new(ctx, ScanPass::new(ctx, ScanVariant::Auto)?);
        let sorter = Guard::new(
            ctx,
            match sort {
                SortAlgo::Counting => Sorter::Counting(CountingSort::new(ctx)?),
                SortAlgo::OddEven => Sorter::Network(NetworkSort::new(ctx, Network::OddEven)?),
                SortAlgo::Bitonic => Sorter::Network(NetworkSort::new(ctx, Network::Bitonic)?),
                SortAlgo::None => unreachable!("refused above"),
            },
        );
        let keys = Guard::new(
            ctx,
            match morton {
                true => None,
                false => Some(CELL_KEYS.pipeline(ctx, &CellKeys(key), 128, &[])?),
            },
        );
        let bounds = Guard::new(ctx, morton.then(|| BoundsPass::new(ctx)).transpose()?);
        let morton_pass = Guard::new(ctx, morton.then(|| MortonPass::new(ctx)).transpose()?);
        let ranges = Guard::new(ctx, CELL_RANGES.pipeline(ctx, &key, 128, &[])?);
        let gather = Guard::new(ctx, GatherPass::new(ctx)?);
        let query = NEIGHBOR_QUERY.pipeline(ctx, &key, 128, &[])?;
        Ok(Self {
            strategy,
            sort,
            scan: scan.take(),
            sorter: sorter.take(),
            keys: keys.take(),
            bounds: bounds.take(),
            morton: morton_pass.take(),
            ranges: ranges.take(),
            gather: gather.take(),
            query,
        })
    }

    pub fn defines_for(strategy: Neighbors, sort: SortAlgo) -> Vec<(&'static str, String)> {
        // The strategy's values, emitted for neighbors.glsl's #if chains (an exhaustive
        // match: a new strategy cannot fall back to another's code).
        let code = |n: Neighbors| match n {
            Neighbors::Grid => 0u32,
            Neighbors::Hash => 1,
            Neighbors::Morton => 2,
        };
        let mut d: Vec<(&'static str, String)> = [
            (Neighbors::Grid, "NB_GRID"),
            (Neighbors::Hash, "NB_HASH"),
            (Neighbors::Morton, "NB_MORTON"),
        ]
        .iter()
        .map(|(n, name)| (*name, code(*n).to_string()))
        .collect();
        let s = code(strategy);
        d.extend([
            ("NB_STRATEGY", s.to_string()),
            (
                "NB_CELL_COUNTS",
                ((sort == SortAlgo::Counting) as u32).to_string(),
            ),
        ]);
        d
    }

    /// The search's shader variant.
    pub fn key(&self) -> NbKey {
        NbKey {
            strategy: self.strategy,
            sort: self.sort,
        }
    }

    pub fn buffers(
        &self,
        ctx: &Context,
        capacity: u64,
        grid: &GridSpec,
        max_neighbors: u32,
    ) -> Result<NeighborBuffers> {
        let cap = capacity.max(1);
        let table = (cap.next_power_of_two()).min(1 << 26) as u32;
        let cells = match self.strategy {
            Neighbors::Grid => grid.cells(),
            Neighbors::Hash => table as u64,
            Neighbors::Morton => 1,
        };
        let list_bytes = cap * max_neighbors.max(1) as u64 * 4;
        if list_bytes > ctx.max_storage_range() {
            return Err(Error::Memory(format!(
                "neighbour lists of {max_neighbors} for {cap} particles need {list_bytes} bytes, more than one \
                 storage binding may address on this device ({}); lower max_neighbors",
                ctx.max_storage_range()
            )));
        }
        // Guarded: a failure halfway (the lists, last, are the large ones) releases the rest.
        let buf = |name: &str, bytes| ctx.storage_buffer(name, bytes).map(|b| Guard::new(ctx, b));
        let keys = buf("nb keys", cap * 4)?;
        let vals = buf("nb values", cap * 4)?;
        let sorted_keys = buf("nb sorted keys", cap * 4)?;
        let perm = buf("nb permutation", cap * 4)?;
        let sorted_pos = buf("nb sorted positions", cap * 16)?;
        // One bin past the cells: dead slots' key (nb_keys.comp), after every live particle.
        let bins = cells + 1;
        let starts = buf("nb cell starts", bins * 4)?;
        let ends = buf("nb cell ends", bins * 4)?;
        let counting = Guard::new(
            ctx,
            match self.sort {
                SortAlgo::Counting => {
                    Some(CountingBuffers::new(ctx, &self.scan, cap, bins as u32)?)
                }
                _ => None,
            },
        );
        let bounds = Guard::new(
            ctx,
            match self.strategy {
                Neighbors::Morton => Some(BoundsBuffers::new(ctx, cap)?),
                _ => None,
            },
        );
        let counts = buf("nb counts", cap * 4)?;
        let list = buf("nb lists", list_bytes)?;
        let visited = ctx.storage_buffer("nb visited", cap * 4)?;
        Ok(NeighborBuffers {
            keys: keys.take(),
            vals: vals.take(),
            sorted_keys: sorted_keys.take(),
            perm: perm.take(),
            sorted_pos: sorted_pos.take(),
            starts: starts.take(),
            ends: ends.take(),
            counting: counting.take(),
            bounds: bounds.take(),
            counts: counts.take(),
            list: list.take(),
            visited,
            capacity,
            table,
            max_neighbors,
        })
    }

    pub fn push(b: &NeighborBuffers, grid: &GridSpec, radius: f32, n: u32) -> NeighborPush {
        NeighborPush {
            origin_cell: [grid.origin[0], grid.origin[1], grid.origin[2], grid.cell],
            dims: [grid.dims[0], grid.dims[1], grid.dims[2], b.table],
            radius,
            n,
            max_neighbors: b.max_neighbors,
            pad: 0,
        }
    }

    /// Record keys, sort (b.sorted_keys, b.perm) and cell ranges for `n` positions (vec4).
    #[allow(clippy::too_many_arguments)]
    pub fn record_build(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        b: &NeighborBuffers,
        pos: &Buffer,
        n: u32,
        grid: &GridSpec,
    ) -> Result<()> {
        if n as u64 > b.capacity {
            return Err(Error::Param(format!(
                "neighbour search of {n} particles exceeds capacity {}",
                b.capacity
            )));
        }
        let push = Self::push(b, grid, grid.cell, n);
        // Keys into (keys, vals) for counting, straight into the sorted arrays otherwise.
        let counting = matches!(self.sorter, Sorter::Counting(_));
        let (kd, vd) = if counting {
            (&b.keys, &b.vals)
        } else {
            (&b.sorted_keys, &b.perm)
        };
        {
            let _scope = scopes.open(ctx, cmd, KEYS_SCOPE);
            if let (Some(bounds), Some(morton), Some(bb)) = (&self.bounds, &self.morton, &b.bounds)
            {
                bounds.record(ctx, cmd, pos, n as u64, bb)?;
                morton.record(ctx, cmd, pos, &bb.result, kd, vd, n);
            } else if let Some(keys) = &self.keys {
                // With the counting sort the keys pass counts too (NB_CELL_COUNTS); a network
                // sort's keys pass binds the keys again in their place, unused.
                let (counts, rank) = match &b.counting {
                    Some(cb) if counting => {
                        ctx.fill(cmd, &cb.counts, 0);
                        (&cb.counts, &cb.rank)
                    }
                    _ => (kd, vd),
                };
                let bufs = NbKeysBufs {
                    pos,
                    keys: kd,
                    vals: vd,
                    counts,
                    rank,
                };
                keys.dispatch(ctx, cmd, &bufs, &push, n as u64);
            }
        }
        {
            let _scope = scopes.open(ctx, cmd, SORT_SCOPE);
            match &self.sorter {
                Sorter::Counting(c) => {
                    let cb = b.counting.as_ref().expect("counting buffers");
                    c.record_counted(
                        ctx,
                        cmd,
                        &self.scan,
                        cb,
                        &b.keys,
                        &b.vals,
                        &b.sorted_keys,
                        &b.perm,
                        n as u64,
                    )?;
                }
                Sorter::Network(s) => {
                    s.record(ctx, cmd, &b.sorted_keys, &b.perm, n as u64)?;
                }
            }
        }
        if !counting && self.strategy != Neighbors::Morton {
            {
                let _scope = scopes.open(ctx, cmd, RANGES_SCOPE);
                ctx.fill(cmd, &b.starts, 0);
                ctx.fill(cmd, &b.ends, 0);
                let bufs = NbRangesBufs {
                    keys: &b.sorted_keys,
                    start: &b.starts,
                    end: &b.ends,
                };
                self.ranges.dispatch(ctx, cmd, &bufs, &n, n as u64);
            }
        }
        Ok(())
    }

    /// Record the neighbour lists of all `n` particles within `radius` (<= grid.cell for
    /// grid and hash), after `record_build` on the same positions.
    #[allow(clippy::too_many_arguments)]
    pub fn record_query(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        b: &NeighborBuffers,
        pos: &Buffer,
        n: u32,
        grid: &GridSpec,
        radius: f32,
    ) -> Result<()> {
        if self.strategy != Neighbors::Morton && radius > grid.cell {
            return Err(Error::Param(format!(
                "search radius {radius} exceeds the grid cell {}",
                grid.cell
            )));
        }
        let push = Self::push(b, grid, radius, n);
        let (starts, ends) = b.cell_buffers();
        {
            let _scope = scopes.open(ctx, cmd, REORDER_SCOPE);
            self.gather.record(ctx, cmd, &b.perm, pos, &b.sorted_pos, n);
        }
        {
            let _scope = scopes.open(ctx, cmd, QUERY_SCOPE);
            let bufs = NbQueryBufs {
                pos: &b.sorted_pos,
                nb_keys: &b.sorted_keys,
                nb_start: starts,
                nb_end: ends,
                nb_box: b.box_buffer(),
                counts: &b.counts,
                list: &b.list,
                visited: &b.visited,
            };
            self.query.dispatch(ctx, cmd, &bufs, &push, n as u64);
        }
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.scan.destroy(ctx);
        match &mut self.sorter {
            Sorter::Counting(c) => c.destroy(ctx),
            Sorter::Network(s) => s.destroy(ctx),
        }
        if let Some(k) = &mut self.keys {
            k.destroy(ctx);
        }
        if let Some(b) = &mut self.bounds {
            b.destroy(ctx);
        }
        if let Some(m) = &mut self.morton {
            m.destroy(ctx);
        }
        self.ranges.destroy(ctx);
        self.gather.destroy(ctx);
        self.query.destroy(ctx);
    }
}

//! The renderer's GPU counters (mirror of `RenderStats` in glsl/render/metaball/common.glsl,
//! field offsets tested) and the per-frame statistics built from them.
use bytemuck::{Pod, Zeroable};
use serde::{Deserialize, Serialize};

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq, Eq)]
pub struct GpuStats {
    /// A-buffer node counter: entries the A-buffer pushed (fragments).
    pub abuffer_nodes: u32,
    pub longest: u32,
    pub overflow: u32,
    pub offscreen_samples: u32,
    /// The S-buffer's total, copied from the end of its scanned offsets.
    pub sbuffer_fragments: u32,
    pub budget_pixels: u32,
    /// Marching cubes: triangles the frame made.
    pub triangles: u32,
    /// Rays marched, primary and secondary.
    pub rays: u32,
    /// 64-bit totals as [lo, hi]: samples taken (refinement included), metaball terms
    /// summed (field and gradient), metaballs the primary rays' lists offer.
    pub steps: [u32; 2],
    pub evals: [u32; 2],
    pub candidates: [u32; 2],
    /// Per-tile lists: the frame's (tile, metaball) pairs.
    pub pairs: u32,
    pub pad: u32,
}

/// A (lo, hi) pair as one number.
pub fn wide(v: [u32; 2]) -> u64 {
    v[0] as u64 | (v[1] as u64) << 32
}

/// The march's counter slots after the stats (glsl/render/metaball/common.glsl): each
/// workgroup adds its counts to slot (group % SLOTS), one cache line each, and the host sums
/// them: the frame's counter atomics spread over 64 lines instead of meeting on one.
pub const MARCH_SLOTS: usize = 64;
pub const MARCH_SLOT_WORDS: usize = 32;

impl GpuStats {
    pub const SIZE: u64 = std::mem::size_of::<GpuStats>() as u64;
    /// The stats buffer: the stats, then the march's counter slots.
    pub const BUFFER_SIZE: u64 = Self::SIZE + (MARCH_SLOTS * MARCH_SLOT_WORDS * 4) as u64;

    /// The stats of a read-back stats buffer, the march's slots summed into them.
    pub fn read(raw: &[u8]) -> Self {
        let mut st: GpuStats = bytemuck::pod_read_unaligned(&raw[..Self::SIZE as usize]);
        let (mut steps, mut evals, mut candidates) =
            (wide(st.steps), wide(st.evals), wide(st.candidates));
        // A slot's words: rays, longest list, off-screen samples, then the (lo, hi) totals
        // of steps, evaluations and candidates (march.comp's add_sums; Serial reads the rest).
        let word = |slot: usize, k: usize| Self::slot_word(raw, slot, k);
        for k in 0..MARCH_SLOTS {
            st.rays += word(k, 0);
            st.longest = st.longest.max(word(k, 1));
            st.offscreen_samples += word(k, 2);
            steps += wide([word(k, 3), word(k, 4)]);
            evals += wide([word(k, 5), word(k, 6)]);
            candidates += wide([word(k, 7), word(k, 8)]);
        }
        let split = |v: u64| [v as u32, (v >> 32) as u32];
        (st.steps, st.evals, st.candidates) = (split(steps), split(evals), split(candidates));
        st
    }
    /// The 32-bit word k of counter slot `slot` in a read-back stats buffer.
    fn slot_word(raw: &[u8], slot: usize, k: usize) -> u32 {
        let at = Self::SIZE as usize + (slot * MARCH_SLOT_WORDS + k) * 4;
        u32::from_le_bytes([raw[at], raw[at + 1], raw[at + 2], raw[at + 3]])
    }

    /// Where the S-buffer's total is copied.
    pub const SBUFFER_FRAGMENTS_OFFSET: u64 =
        std::mem::offset_of!(GpuStats, sbuffer_fragments) as u64;
}

/// The march's serial chains and passed-over samples, summed from the counter slots
/// (words 9..15: the (lo, hi) total of every invocation's evaluations, the longest chain,
/// the invocations that evaluated, the (lo, hi) total of samples passed over in empty
/// cells; march_counters.glsl).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Serial {
    pub max: u32,
    pub invocations: u64,
    pub sum: u64,
    pub skipped: u64,
}

impl Serial {
    pub fn read(raw: &[u8]) -> Self {
        let word = |slot: usize, k: usize| GpuStats::slot_word(raw, slot, k);
        let mut s = Self::default();
        for k in 0..MARCH_SLOTS {
            s.sum += wide([word(k, 9), word(k, 10)]);
            s.max = s.max.max(word(k, 11));
            s.invocations += word(k, 12) as u64;
            s.skipped += wide([word(k, 13), word(k, 14)]);
        }
        s
    }
}

/// One frame's list statistics (the thesis's memory column is `list_bytes`).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct FrameStats {
    /// Billboard fragments: list entries of the frame.
    pub fragments: u64,
    /// Longest per-pixel list met by a primary ray.
    pub longest: u32,
    /// List entries that did not fit (the frame must be redone).
    pub overflow: u32,
    /// Secondary-ray samples that left the screen.
    pub offscreen_samples: u32,
    /// Pixels whose rays were cut short: a loop stopped before its own exit condition, as
    /// llvmpipe's loop budget (about 65535 iterations per batch) does. Nonzero: wrong frame.
    pub budget_pixels: u32,
    /// Bytes the list structure needs for this frame (S: offsets + list, sorted: plus the
    /// metaball depths; A: heads + nodes + counter; none: 0).
    pub list_bytes: u64,
    /// Marching cubes: the frame's triangles (else 0).
    #[serde(default)]
    pub triangles: u64,
    /// Per-tile lists (tiles, compute-built S-buffers): the frame's (tile, metaball) pairs.
    #[serde(default)]
    pub pairs: u64,
    /// The march's per-ray counters: rays marched (primary and secondary), samples taken
    /// (refinement included), metaball terms summed (density and gradient), and metaballs
    /// the primary rays' lists offered (none: every metaball to every pixel).
    #[serde(default)]
    pub march: MarchCounts,
}

#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct MarchCounts {
    pub rays: u64,
    pub steps: u64,
    pub evaluations: u64,
    pub candidates: u64,
    /// The most field and gradient evaluations one invocation made one after another in
    /// the frame: the longest serial chain, which sets the march's time on a wide device.
    #[serde(default)]
    pub serial_max: u64,
    /// Their mean over the invocations that evaluated at all.
    #[serde(default)]
    pub serial_mean: f64,
    /// Grid samples of secondary rays passed over in cells the occupancy grid proves
    /// empty, not evaluated (not in `steps`; --occupancy).
    #[serde(default)]
    pub skipped: u64,
}

impl MarchCounts {
    pub fn of(st: &GpuStats, serial: &Serial) -> Self {
        Self {
            rays: st.rays as u64,
            steps: wide(st.steps),
            evaluations: wide(st.evals),
            candidates: wide(st.candidates),
            serial_max: serial.max as u64,
            serial_mean: serial.sum as f64 / serial.invocations.max(1) as f64,
            skipped: serial.skipped,
        }
    }

    /// (steps, evaluations, candidates) per pixel of a frame of `pixels`.
    pub fn per_pixel(&self, pixels: u64) -> (f64, f64, f64) {
        let p = pixels.max(1) as f64;
        (
            self.steps as f64 / p,
            self.evaluations as f64 / p,
            self.candidates as f64 / p,
        )
    }
}

//! The control force's GPU interface: its bindings (glsl/control/common.glsl) and its
//! parameter block, one definition for every pass that binds them.
use crate::primitives::neighbors::NeighborPush;
use bytemuck::{Pod, Zeroable};

crate::gpu_interface! {
    /// glsl/control/common.glsl: the SPH bindings, then the control set's.
    pub ControlIo / ControlBufs: "CTL", push NeighborPush {
        params = 0, nb_keys = 1, nb_start = 2, nb_end = 3, nb_box = 4,
        pos = 5, vel = 6, rho_p = 7, acc = 8, vhalf = 9, colliders = 10,
        control = 11, cpos = 12, cprev = 13, crho = 14, cstart = 15, ccount = 16, attr = 17,
        cagg = 18, cfield = 19, cforce = 20, cvmean = 21, cvw = 22,
    }
}

/// glsl/control/common.glsl `ControlParams`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct ControlGpuParams {
    pub grid: [f32; 4],
    pub dims: [u32; 4],
    pub pressure: f32,
    pub radius: f32,
    pub spiky_grad: f32,
    pub velocity: f32,
    pub adaptive: u32,
    pub low: f32,
    pub high: f32,
    pub up: f32,
    pub down: f32,
    pub inv_frame: f32,
    pub group: u32,
    /// Control particles this step: m for bound sets, the GPU's count for rays.
    pub live: u32,
    /// Deficit attraction (m/s^2), its reach (metres, and in control-grid cells), damping.
    pub attraction: f32,
    pub reach: f32,
    pub reach_cells: u32,
    pub damping: f32,
}
const _: () = assert!(std::mem::size_of::<ControlGpuParams>() == 96);
/// Byte offset of `live` (the rays placement copies its count there).
pub const LIVE_OFFSET: u64 = std::mem::offset_of!(ControlGpuParams, live) as u64;

//! The fluid's parameters as the shaders read them (SphParams in glsl/sph/common.glsl).
use super::kernel::{proto_grad2, Kernels};
use super::params::{Eos, FluidParams};
use bytemuck::{Pod, Zeroable};

/// Mirror of `SphParams` in glsl/sph/common.glsl (std430).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SphGpuParams {
    pub gravity: [f32; 4],
    pub domain_min: [f32; 4],
    pub domain_max: [f32; 4],
    pub h: f32,
    pub mass: f32,
    pub rest_density: f32,
    pub stiffness: f32,
    pub viscosity: f32,
    pub tension: f32,
    pub tension_threshold: f32,
    pub gamma: f32,
    pub eos: u32,
    pub clamp_negative: u32,
    pub colliders: u32,
    /// Live particles: slots at and past it are dead (an emitter's) and skipped. The host
    /// sets the state's count; an emitter overwrites it on the GPU after each birth pass.
    pub live: u32,
    pub poly6: f32,
    pub poly6_grad: f32,
    pub spiky_grad: f32,
    pub visc_lap: f32,
    /// `Solver` as u32.
    pub solver: u32,
    pub min_iter: u32,
    pub max_iter: u32,
    pub density_target: f32,
    pub divergence_target: f32,
    /// sum over a full neighbourhood at the rest spacing of |V grad W_spiky|^2, V = m / rho_0
    /// (PCISPH's delta, DFSPH's and PBF's denominators are relative to it).
    pub proto_grad2: f32,
    pub pbf_relaxation: f32,
    pub scorr_k: f32,
    pub scorr_n: f32,
    /// 1 / W(scorr_dq h), the fluid's kernel
    pub scorr_inv_w: f32,
    pub xsph: f32,
    pub vorticity: f32,
    /// DFSPH's neighbour list length (0: off; see `FluidParams::list_len`).
    pub list_max: u32,
    /// `Kernel` as u32, and cubic's or wendland's normalisation (`kernel::norm`).
    pub kernel: u32,
    pub kernel_k: f32,
    /// DFSPH: a particle with fewer fluid neighbours is left out of the divergence solve.
    pub min_neighbors: u32,
    /// DFSPH: the divergence solve's least iterations.
    pub div_min_iter: u32,
    /// The previous step's dt (the warm starts rescale by it; cfl.comp keeps it).
    pub dt_prev: f32,
    /// Above 0: each step's dt comes from its own velocities on the GPU (glsl/sph/cfl.comp),
    /// min(dt_max, cfl h / max(v_max, cfl_speed)).
    pub cfl: f32,
    pub dt_max: f32,
    pub cfl_speed: f32,
    /// The walls' terms take a particle this much farther than it is (`kernel::wall_offset`).
    pub wall_offset: f32,
    pub pad1: u32,
    pub pad2: u32,
}
const _: () = assert!(std::mem::size_of::<SphGpuParams>() == 208);

/// A rest lattice's sums under the fluid's kernel, for [`SphGpuParams`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LatticeTerms {
    key: [u32; 5],
    proto_grad2: f32,
    neighbours: u32,
    wall_offset: f32,
}

impl LatticeTerms {
    /// What the terms depend on: kernel, support, spacing, mass, rest density.
    fn key(f: &FluidParams) -> [u32; 5] {
        let b = f32::to_bits;
        let k = f.kernel() as u32;
        [k, b(f.h), b(f.spacing()), b(f.mass), b(f.rest_density)]
    }

    pub fn of(f: &FluidParams) -> Self {
        Self {
            key: Self::key(f),
            proto_grad2: proto_grad2(f) as f32,
            neighbours: super::kernel::lattice_neighbours(f) as u32,
            wall_offset: super::kernel::wall_offset(f) as f32,
        }
    }
}

impl SphGpuParams {
    /// Byte offset of `live` (the emitter copies its GPU-side count there).
    pub const LIVE_OFFSET: u64 = std::mem::offset_of!(SphGpuParams, live) as u64;

    pub fn new(f: &FluidParams, lo: [f32; 3], hi: [f32; 3], dt: f32, colliders: u32) -> Self {
        Self::with_lattice(f, &LatticeTerms::of(f), (lo, hi), dt, colliders)
    }

    /// [`new`](Self::new) with the rest-lattice terms already summed (a state keeps them:
    /// they are fixed by the kernel, support and spacing, and cost a bisection).
    pub fn with_lattice(
        f: &FluidParams,
        t: &LatticeTerms,
        (lo, hi): ([f32; 3], [f32; 3]),
        dt: f32,
        colliders: u32,
    ) -> Self {
        let t = match t.key == LatticeTerms::key(f) {
            true => *t,
            false => LatticeTerms::of(f),
        };
        let h = f.h;
        let k = Kernels::new(h as f64);
        let incompressible = f.solver != crate::sph::Solver::Wcsph;
        let c = f.convergence();
        let dq = (f.pbf.scorr_dq * h) as f64;
        let w_dq = super::kernel::Smoothing::of(f).w_r2(dq * dq);
        Self {
            gravity: [f.gravity[0], f.gravity[1], f.gravity[2], dt],
            domain_min: [lo[0], lo[1], lo[2], f.restitution],
            domain_max: [hi[0], hi[1], hi[2], f.friction],
            h,
            mass: f.mass,
            rest_density: f.rest_density,
            // The pressure solvers replace the equation of state (forces.comp then adds
            // no pressure term); pbf replaces the viscous force by XSPH.
            stiffness: if incompressible {
                0.0
            } else {
                f.eos_constant()
            },
            viscosity: if f.solver == crate::sph::Solver::Pbf {
                0.0
            } else {
                f.viscosity
            },
            tension: f.surface_tension,
            tension_threshold: f.tension_threshold,
            gamma: f.gamma,
            eos: if incompressible {
                Eos::Ideal as u32
            } else {
                f.eos as u32
            },
            clamp_negative: f.clamp_negative_pressure as u32,
            colliders,
            live: u32::MAX,
            poly6: k.poly6 as f32,
            poly6_grad: k.poly6_grad as f32,
            spiky_grad: k.spiky_grad as f32,
            visc_lap: k.visc_lap as f32,
            solver: f.solver as u32,
            min_iter: c.min_iterations,
            max_iter: c.max_iterations,
            density_target: c.density_error * c.stop_fraction,
            divergence_target: c.divergence_error,
            proto_grad2: t.proto_grad2,
            pbf_relaxation: f.pbf.relaxation,
            scorr_k: f.pbf.scorr_k,
            scorr_n: f.pbf.scorr_n,
            scorr_inv_w: (1.0 / w_dq) as f32,
            xsph: f.pbf.xsph,
            vorticity: f.pbf.vorticity,
            list_max: f.list_len(),
            kernel: f.kernel() as u32,
            kernel_k: super::kernel::norm(f.kernel(), h as f64) as f32,
            min_neighbors: f.dfsph.min_neighbors.unwrap_or(5 * t.neighbours / 8),
            div_min_iter: f.dfsph.divergence_min_iterations,
            dt_prev: dt,
            cfl: f.cfl.unwrap_or(0.0),
            dt_max: f.dt_max.unwrap_or(f.dt),
            cfl_speed: f.sound(),
            wall_offset: t.wall_offset,
            pad1: 0,
            pad2: 0,
        }
    }
}

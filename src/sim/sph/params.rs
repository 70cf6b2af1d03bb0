//! Fluid parameters (Kelager 2006's water by default) and their GPU mirror.
use crate::error::{Error, Result};
use crate::sph::Solver;
use serde::{Deserialize, Serialize};

pub use super::collider::{Collider, GpuCollider, MAX_COLLIDERS};
pub use super::dfsph::{DfsphParams, DEFAULT_NEIGHBOR_LIST, MAX_NEIGHBOR_LIST};
pub use super::kernel::{proto_grad2, Kernels};
pub use super::pbf::PbfParams;
pub use super::pcisph::PcisphParams;
pub use super::pressure::Convergence;
use super::Kernel;

/// The CFL number a configuration without a table of its own takes (each pressure solver
/// has its own: pcisph.rs, dfsph.rs, pbf.rs).
pub const OWN_CFL: f32 = 0.4;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[repr(u32)]
pub enum Eos {
    /// p = k (rho - rho_0) (Kelager's ideal-gas form).
    Ideal = 0,
    /// p = B ((rho / rho_0)^gamma - 1), B = rho_0 c^2 / gamma (weakly compressible).
    Tait = 1,
}

/// The fluid's enum defines for glsl/sph/common.glsl: `EOS_*` and `KERNEL_*`.
pub fn defines() -> Vec<(String, String)> {
    let mut v = Eos::defines();
    v.extend(super::kernel::defines());
    v
}

impl Eos {
    /// `EOS_IDEAL`, `EOS_TAIT` for glsl/sph/common.glsl.
    pub fn defines() -> Vec<(String, String)> {
        crate::gpu::interface::enum_defines(
            "EOS",
            &[("ideal", Eos::Ideal as u32), ("tait", Eos::Tait as u32)],
        )
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FluidParams {
    /// rho_0, kg/m^3
    pub rest_density: f32,
    /// Particle mass, kg
    pub mass: f32,
    /// mu, Pa s
    pub viscosity: f32,
    /// sigma, N/m
    pub surface_tension: f32,
    /// l: surface tension acts where |grad c| >= l
    pub tension_threshold: f32,
    /// k of the ideal-gas equation of state, J
    pub stiffness: f32,
    pub eos: Eos,
    /// Tait: speed of sound c, m/s
    pub sound_speed: f32,
    /// Tait exponent
    pub gamma: f32,
    /// Clamp negative pressures to zero (no tensile attraction at the free surface)
    pub clamp_negative_pressure: bool,
    /// Support radius h, m
    pub h: f32,
    /// Time step, s
    pub dt: f32,
    /// Steps per frame: a frame advances dt * substeps
    pub substeps: u32,
    /// CFL number: when set, each step is min(dt_max, cfl * h / max(c, v_max)) with v_max
    /// the step's own largest speed, on the GPU (c: wcsph's speed of sound; sph/cfl.rs), and
    /// a frame takes as many steps as cover it (leftover time carries: `stepper::Stepper`)
    pub cfl: Option<f32>,
    pub gravity: [f32; 3],
    /// Normal velocity kept (reversed) at a wall, 0..1
    pub restitution: f32,
    /// Tangential velocity lost at a wall, 0..1
    pub friction: f32,
    /// The pressure solver (`--solver`).
    pub solver: crate::sph::Solver,
    /// With `cfl`: the largest step, s (default: `dt`). The frame time stays dt * substeps.
    pub dt_max: Option<f32>,
    /// `[fluid.pcisph]`, `[fluid.dfsph]`, `[fluid.pbf]`: each solver's own settings.
    pub pcisph: PcisphParams,
    pub dfsph: DfsphParams,
    pub pbf: PbfParams,
    /// The smoothing kernel (`--kernel`, src/sim/sph/kernel.rs): default muller (the thesis's)
    /// for wcsph and pbf (its paper's), cubic for pcisph and dfsph (their error targets
    /// then hold: one kernel for densities and gradients).
    pub kernel: Option<Kernel>,
    /// Support of the cubic and Wendland kernels in rest spacings (default: cubic 2,
    /// wendland 3; see `kernel::default_support`): h becomes support times the spacing.
    /// Muller's support is `h` (set, it too follows `support`).
    pub support: Option<f32>,
    /// Particle spacing at rest, m (`--fluid spacing=S`): when set, the mass becomes
    /// rho_0 S^3 and h, dt and the steps per frame scale with S from the values given, so
    /// the frame time, h in spacings and the CFL number stay as they were.
    pub spacing: Option<f32>,
}

impl Default for FluidParams {
    fn default() -> Self {
        Self {
            rest_density: 998.29,
            mass: 0.02,
            viscosity: 3.5,
            surface_tension: 0.0728,
            tension_threshold: 7.065,
            stiffness: 3.0,
            eos: Eos::Ideal,
            sound_speed: 20.0,
            gamma: 7.0,
            clamp_negative_pressure: false,
            h: 0.0457,
            dt: 0.01,
            substeps: 1,
            cfl: None,
            gravity: [0.0, -9.82, 0.0],
            restitution: 0.0,
            friction: 0.0,
            solver: crate::sph::Solver::Wcsph,
            dt_max: None,
            pcisph: PcisphParams::default(),
            dfsph: DfsphParams::default(),
            pbf: PbfParams::default(),
            kernel: None,
            support: None,
            spacing: None,
        }
    }
}

/// Most steps one frame may be split into.
pub const MAX_SUBSTEPS: u32 = 1000;
/// Most iterations one pressure solve may take (each is recorded, skipped once converged).
pub const MAX_ITERATIONS: u32 = 500;

impl FluidParams {
    pub fn validate(&self) -> Result<()> {
        self.validate_solver()?;
        let positive = [
            ("rest_density", self.rest_density),
            ("mass", self.mass),
            ("h", self.h),
            ("dt", self.dt),
            ("sound_speed", self.sound_speed),
        ];
        for (name, v) in positive {
            if !(v > 0.0 && v.is_finite()) {
                return Err(Error::Param(format!(
                    "fluid.{name} must be positive, got {v}"
                )));
            }
        }
        let non_negative = [
            ("viscosity", self.viscosity),
            ("surface_tension", self.surface_tension),
            ("tension_threshold", self.tension_threshold),
            ("stiffness", self.stiffness),
        ];
        for (name, v) in non_negative {
            if !(v >= 0.0 && v.is_finite()) {
                return Err(Error::Param(format!("fluid.{name} must be >= 0, got {v}")));
            }
        }
        for (name, v) in [
            ("restitution", self.restitution),
            ("friction", self.friction),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(Error::Param(format!(
                    "fluid.{name} must be in 0..=1, got {v}"
                )));
            }
        }
        if !(self.gamma >= 1.0 && self.gamma <= 10.0) {
            return Err(Error::Param(format!(
                "fluid.gamma must be in 1..=10, got {}",
                self.gamma
            )));
        }
        if self.substeps == 0 || self.substeps > MAX_SUBSTEPS {
            return Err(Error::Param(format!(
                "fluid.substeps must be in 1..={MAX_SUBSTEPS}, got {}",
                self.substeps
            )));
        }
        if let Some(c) = self.cfl {
            if !(c > 0.0 && c <= 1.0) {
                return Err(Error::Param(format!(
                    "fluid.cfl must be in (0, 1], got {c}"
                )));
            }
        }
        if self.gravity.iter().any(|g| !g.is_finite()) {
            return Err(Error::Param("fluid.gravity must be finite".into()));
        }
        Ok(())
    }

    fn validate_solver(&self) -> Result<()> {
        self.pcisph.validate()?;
        self.dfsph.validate()?;
        self.pbf.validate()?;
        if let Some(d) = self.dt_max {
            if !(d > 0.0 && d.is_finite()) {
                return Err(Error::Param(format!(
                    "fluid.dt_max must be positive, got {d}"
                )));
            }
            if self.cfl.is_none() && self.own_step().is_none() {
                return Err(Error::Param(
                    "fluid.dt_max needs a CFL-limited step: fluid.cfl, or the solver's own (without it every step is dt)".into(),
                ));
            }
        }
        Ok(())
    }

    /// When the chosen solver's pressure solve stops (wcsph solves none: pcisph's defaults
    /// fill the GPU's fields).
    pub fn convergence(&self) -> Convergence {
        match self.solver {
            Solver::Wcsph => PcisphParams::default().convergence(),
            Solver::Pcisph => self.pcisph.convergence(),
            Solver::Dfsph => self.dfsph.convergence(),
            Solver::Pbf => self.pbf.convergence(),
        }
    }

    /// Apply `KEY=VALUE` overrides (TOML values; a bare word is a string), checked like
    /// a scene file's `[fluid]` table: unknown keys and invalid values are errors.
    /// The parameters with `KEY=VALUE` `overrides` (`--fluid`) and `solver` applied, and
    /// the solver's own step (its table's `cfl` and `dt_max`) where `[fluid]` sets no `cfl`.
    pub fn with_overrides(&self, overrides: &[String], solver: Option<Solver>) -> Result<Self> {
        let mut out = self.with_values(overrides)?;
        out.solver = solver.unwrap_or(out.solver);
        let mut out = out.with_own_step();
        out.validate()?;
        out.resolve_spacing()?;
        if overrides
            .iter()
            .any(|o| o.split('=').next().map(str::trim) == Some("h"))
            && out.kernel() != Kernel::Muller
        {
            return Err(Error::Param(format!(
                "--fluid h= sets the muller kernel's support; the {} kernel's is --fluid \
                 support= (in rest spacings)",
                out.kernel().as_str()
            )));
        }
        out.resolve_support()?;
        Ok(out)
    }

    /// The step the solver takes by its own table, `cfl` and `dt_max` each where `[fluid]`
    /// (or --fluid) sets none: wcsph keeps the fixed `dt`, its stable step at its speed of
    /// sound.
    pub fn with_own_step(mut self) -> Self {
        if let Some((cfl, dt_max)) = self.own_step() {
            self.cfl = Some(self.cfl.unwrap_or(cfl));
            self.dt_max = Some(self.dt_max.unwrap_or(dt_max));
        }
        self
    }

    /// The chosen solver's own (cfl, dt_max): None for wcsph and for a table whose `cfl`
    /// is 0 (fixed steps of `dt`).
    pub fn own_step(&self) -> Option<(f32, f32)> {
        let own = match self.solver {
            Solver::Wcsph => None,
            Solver::Pcisph => Some((self.pcisph.cfl, self.pcisph.dt_max)),
            Solver::Dfsph => Some((self.dfsph.cfl, self.dfsph.dt_max)),
            Solver::Pbf => Some((self.pbf.cfl, self.pbf.dt_max)),
        };
        own.filter(|&(cfl, _)| cfl > 0.0)
    }

    /// One line on the step and stopping rule a run takes (printed at its start).
    pub fn describe_step(&self) -> String {
        let step = match (self.cfl, self.dt_max) {
            (Some(c), m) => format!(
                "CFL {c}, steps up to {:.2} ms",
                m.unwrap_or(self.dt) * 1000.0
            ),
            (None, _) => format!(
                "fixed steps of {:.3} ms, {} a frame",
                self.dt * 1000.0,
                self.substeps
            ),
        };
        let stop = match self.solver {
            Solver::Wcsph => String::new(),
            Solver::Pbf if self.pbf.iterations > 0 => {
                format!(", {} iterations a step", self.pbf.iterations)
            }
            _ => format!(
                ", iterating to a mean density error of {}%",
                self.convergence().density_error * 100.0
            ),
        };
        let solver = self.solver.as_str();
        let how = match self.solver {
            Solver::Wcsph => "--fluid cfl= for a CFL-limited step".to_string(),
            _ => format!("its own by [fluid.{solver}]; --fluid cfl=, dt_max= override"),
        };
        format!("solver {solver}: {step}{stop} ({how})")
    }

    /// The parameters with `overrides` parsed in (checked by the caller).
    fn with_values(&self, overrides: &[String]) -> Result<Self> {
        if overrides.is_empty() {
            return Ok(self.clone());
        }
        let mut value = toml::Value::try_from(self)
            .map_err(|e| Error::Param(format!("fluid parameters: {e}")))?;
        let table = value
            .as_table_mut()
            .expect("a struct serialises to a table");
        for o in overrides {
            let (k, v) = o
                .split_once('=')
                .ok_or_else(|| Error::Param(format!("--fluid {o}: expected KEY=VALUE")))?;
            let (k, v) = (k.trim(), v.trim());
            let parsed = toml::from_str::<toml::Table>(&format!("x = {v}"))
                .ok()
                .and_then(|mut t| t.remove("x"))
                .unwrap_or_else(|| toml::Value::String(v.to_string()));
            for path in override_paths(k) {
                set_path(table, &path, parsed.clone())?;
            }
        }
        value.try_into().map_err(|e| {
            let e = e.to_string().replace('\n', " ");
            Error::Param(format!("--fluid: {}", e.trim()))
        })
    }

    /// Every iterative solver's density error target set to `e`.
    pub fn with_density_error(mut self, e: f32) -> Self {
        self.pcisph.density_error = e;
        self.dfsph.density_error = e;
        self.pbf.density_error = e;
        self
    }

    /// The neighbour list length the solver uses: dfsph's `neighbor_list`, else 0.
    pub fn list_len(&self) -> u32 {
        match self.solver {
            Solver::Dfsph => self.dfsph.neighbor_list,
            Solver::Wcsph | Solver::Pcisph | Solver::Pbf => 0,
        }
    }

    /// The kernel in use: `kernel`, else muller for wcsph and pbf, cubic for the others.
    pub fn kernel(&self) -> Kernel {
        self.kernel.unwrap_or(match self.solver {
            // PBF keeps its paper's pair: with the cubic its step strayed 3% from its f64
            // reference (its neighbour sets are the step's start's; tests/solvers.rs).
            Solver::Wcsph | Solver::Pbf => Kernel::Muller,
            Solver::Pcisph | Solver::Dfsph => Kernel::Cubic,
        })
    }

    /// h = support x spacing where the kernel has a support in spacings (`support`, else
    /// its default); muller without `support` keeps h. Applying it again changes nothing.
    pub fn resolve_support(&mut self) -> Result<()> {
        let Some(k) = self
            .support
            .or(super::kernel::default_support(self.kernel()))
        else {
            return Ok(());
        };
        if !(1.0..=4.0).contains(&k) {
            return Err(Error::Param(format!(
                "fluid.support must be in 1..=4 rest spacings, got {k}"
            )));
        }
        self.h = k * self.spacing();
        Ok(())
    }

    /// The parameters with the kernel's support applied (see `resolve_support`).
    pub fn resolved(&self) -> Result<Self> {
        let mut f = self.clone();
        f.resolve_support()?;
        Ok(f)
    }

    /// Lattice spacing at rest density: (m / rho_0)^(1/3).
    pub fn spacing(&self) -> f32 {
        (self.mass / self.rest_density).cbrt()
    }

    /// The equation of state's stiffness constant (k, or Tait's B).
    pub fn eos_constant(&self) -> f32 {
        match self.eos {
            Eos::Ideal => self.stiffness,
            Eos::Tait => self.rest_density * self.sound_speed * self.sound_speed / self.gamma,
        }
    }

    /// Speed of sound used by the CFL limit: the equation of state's for wcsph; the
    /// incompressible solvers have none (their CFL limit is the largest speed alone).
    pub fn sound(&self) -> f32 {
        if self.solver != crate::sph::Solver::Wcsph {
            return 0.0;
        }
        match self.eos {
            Eos::Ideal => self.stiffness.sqrt(),
            Eos::Tait => self.sound_speed,
        }
    }
}

/// The table paths a `--fluid KEY` sets: `a.b` as written; the solver settings by their
/// earlier flat names (`density_error` and the iteration bounds: every iterative solver's;
/// `neighbor_list`, `divergence_error`: dfsph's; `pbf_iterations`, `xsph`, ...: pbf's).
fn override_paths(key: &str) -> Vec<Vec<String>> {
    let one = |t: &str, k: &str| vec![vec![t.to_string(), k.to_string()]];
    match key {
        "density_error" | "min_iterations" | "max_iterations" => ["pcisph", "dfsph", "pbf"]
            .iter()
            .map(|t| vec![t.to_string(), key.to_string()])
            .collect(),
        "divergence_error" | "neighbor_list" => one("dfsph", key),
        "pbf_iterations" => one("pbf", "iterations"),
        "pbf_relaxation" => one("pbf", "relaxation"),
        "scorr_k" | "scorr_n" | "scorr_dq" | "xsph" | "vorticity" => one("pbf", key),
        _ => vec![key.split('.').map(str::to_string).collect()],
    }
}

/// Sets `value` at `path` under `table`, refusing a path through a value that is not a table.
fn set_path(table: &mut toml::Table, path: &[String], value: toml::Value) -> Result<()> {
    let (last, tables) = path.split_last().expect("a key has one part at least");
    let mut t = table;
    for (i, k) in tables.iter().enumerate() {
        t = match t.get_mut(k).and_then(toml::Value::as_table_mut) {
            Some(sub) => sub,
            None => {
                return Err(Error::Param(format!(
                    "--fluid {}: fluid.{} is not a table",
                    path.join("."),
                    tables[..=i].join(".")
                )))
            }
        };
    }
    t.insert(last.clone(), value);
    Ok(())
}

pub use super::gpu_params::{LatticeTerms, SphGpuParams};

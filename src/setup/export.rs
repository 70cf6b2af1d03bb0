//! Particle export for the tools researchers already use: binary PLY (Blender, splashsurf,
//! ParaView) or legacy VTK (ParaView) files of position, velocity, density, pressure and
//! group every K frames, and particles.csv with per-frame aggregates. The copies are
//! recorded into the frame's own commands, so each file holds exactly that frame's state.
use crate::config::ExportFormat;
use crate::error::{Error, Result};
use crate::gpu::vk;
use crate::gpu::{Buffer, Context, Guard, MemoryLocation};
use crate::sph::SphState;
use std::io::Write;
use std::path::{Path, PathBuf};

/// One slot's host copies: positions, velocities, (density, pressure), attributes.
struct Copies {
    pos: Buffer,
    vel: Buffer,
    rho_p: Buffer,
    attr: Buffer,
}

impl Copies {
    fn destroy(&mut self, ctx: &Context) {
        for b in [
            &mut self.pos,
            &mut self.vel,
            &mut self.rho_p,
            &mut self.attr,
        ] {
            ctx.destroy_buffer(b);
        }
    }
}

crate::impl_destroy!(Copies);

/// The particles of one frame, in the state's (sorted) order.
pub struct Snapshot<'a> {
    pub pos: &'a [[f32; 4]],
    pub vel: &'a [[f32; 4]],
    pub rho_p: &'a [[f32; 2]],
    pub attr: &'a [[f32; 4]],
}

impl Snapshot<'_> {
    pub fn group(&self, i: usize) -> u32 {
        self.attr[i][3].to_bits()
    }
}

pub struct ParticleExport {
    /// Particle files, and surface meshes, per exported frame.
    format: Option<ExportFormat>,
    mesh: Option<crate::config::MeshFormat>,
    /// Smoothing length, rest density and spacing of the surface's density grid.
    fluid: (f32, f32, f32),
    every: u64,
    out: PathBuf,
    mass: f32,
    slots: Vec<Copies>,
    /// Simulated time of the frame recorded into each slot.
    times: Vec<f64>,
    csv: std::io::BufWriter<std::fs::File>,
    /// Files written so far.
    pub files: Vec<PathBuf>,
}

fn io(path: &Path) -> impl Fn(std::io::Error) -> Error + '_ {
    move |e| Error::Io {
        path: path.display().to_string(),
        source: e,
    }
}

impl ParticleExport {
    pub fn new(
        ctx: &Context,
        (format, mesh): (Option<ExportFormat>, Option<crate::config::MeshFormat>),
        every: u64,
        out: &Path,
        st: &SphState,
        slots: usize,
    ) -> Result<Self> {
        let n = st.n as u64;
        let host = |name: &str, bytes: u64| {
            ctx.create_buffer(
                name,
                bytes,
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )
        };
        let mut copies = Guard::new(ctx, Vec::new());
        for _ in 0..slots {
            let pos = Guard::new(ctx, host("export positions", n * 16)?);
            let vel = Guard::new(ctx, host("export velocities", n * 16)?);
            let rho_p = Guard::new(ctx, host("export densities", n * 8)?);
            let attr = host("export attributes", n * 16)?;
            copies.push(Copies {
                pos: pos.take(),
                vel: vel.take(),
                rho_p: rho_p.take(),
                attr,
            });
        }
        let path = out.join("particles.csv");
        let mut csv = std::io::BufWriter::new(std::fs::File::create(&path).map_err(io(&path))?);
        writeln!(
            csv,
            "frame,time,count,com_x,com_y,com_z,min_x,min_y,min_z,max_x,max_y,max_z,front_x,kinetic_energy"
        )
        .map_err(io(&path))?;
        let f = &st.fluid;
        Ok(Self {
            format,
            mesh,
            fluid: (f.h, f.rest_density, f.spacing()),
            every: every.max(1),
            out: out.to_path_buf(),
            mass: st.fluid.mass,
            times: vec![0.0; slots],
            slots: copies.take(),
            csv,
            files: Vec::new(),
        })
    }

    pub fn due(&self, frame: u64) -> bool {
        frame.is_multiple_of(self.every)
    }

    /// Record the copies of the state at the end of `frame` (after its last step, whose
    /// writes the caller made visible to transfers).
    pub fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        st: &SphState,
        slot: usize,
        time: f64,
    ) {
        self.times[slot] = time;
        let c = &self.slots[slot];
        let n = st.n as u64;
        ctx.copy(cmd, st.pos(), 0, &c.pos, 0, n * 16);
        ctx.copy(cmd, st.vel(), 0, &c.vel, 0, n * 16);
        ctx.copy(cmd, st.rho_p(), 0, &c.rho_p, 0, n * 8);
        ctx.copy(cmd, st.attr(), 0, &c.attr, 0, n * 16);
        ctx.host_reads(cmd, &[&c.pos, &c.vel, &c.rho_p, &c.attr]);
    }

    /// After the slot's fence: write the frame's file and its particles.csv row.
    pub fn retire(&mut self, frame: u64, slot: usize) -> Result<()> {
        let time = self.times[slot];
        let c = &self.slots[slot];
        fn cast(b: &Buffer) -> &[u8] {
            b.mapped().expect("host-visible export buffer")
        }
        let all = Snapshot {
            pos: bytemuck::cast_slice(cast(&c.pos)),
            vel: bytemuck::cast_slice(cast(&c.vel)),
            rho_p: bytemuck::cast_slice(cast(&c.rho_p)),
            attr: bytemuck::cast_slice(cast(&c.attr)),
        };
        // Live particles only: an emitter's dead slots (pos.w < 0) are left out.
        use crate::sph::solver::{live_mask, pick};
        let keep = live_mask(all.pos);
        let (pos, vel, rho_p, attr) = (
            pick(all.pos, &keep),
            pick(all.vel, &keep),
            pick(all.rho_p, &keep),
            pick(all.attr, &keep),
        );
        let snap = Snapshot {
            pos: &pos,
            vel: &vel,
            rho_p: &rho_p,
            attr: &attr,
        };
        let file = match self.format {
            Some(ExportFormat::Ply) => Some((format!("particles_{frame:04}.ply"), ply(&snap))),
            Some(ExportFormat::Vtk) => {
                Some((format!("particles_{frame:04}.vtk"), vtk(&snap, frame)))
            }
            None => None,
        };
        if let Some((name, bytes)) = file {
            let path = self.out.join(name);
            std::fs::write(&path, bytes).map_err(io(&path))?;
            self.files.push(path);
        }
        if let Some(m) = self.mesh {
            self.files.push(self.surface(&snap, frame, m)?);
        }
        let row = aggregates(&snap, self.mass);
        let csv_path = self.out.join("particles.csv");
        writeln!(
            self.csv,
            "{frame},{time:.6},{},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6e}",
            snap.pos.len(),
            row.com[0],
            row.com[1],
            row.com[2],
            row.min[0],
            row.min[1],
            row.min[2],
            row.max[0],
            row.max[1],
            row.max[2],
            row.max[0],
            row.kinetic
        )
        .map_err(io(&csv_path))?;
        self.csv.flush().map_err(io(&csv_path))
    }

    /// The frame's surface (marching cubes over the SPH density at half the spacing, iso
    /// half the rest density) as surface_NNNN.obj or .ply.
    fn surface(
        &self,
        snap: &Snapshot,
        frame: u64,
        f: crate::config::MeshFormat,
    ) -> Result<PathBuf> {
        use crate::config::MeshFormat;
        use crate::isosurface::{density_grid, files, march, ISO};
        let (h, rest, spacing) = self.fluid;
        let pos: Vec<[f32; 3]> = snap.pos.iter().map(|p| [p[0], p[1], p[2]]).collect();
        let mesh = march(&density_grid(&pos, h, self.mass, rest, 0.5 * spacing), ISO);
        let path = self.out.join(match f {
            MeshFormat::Obj => format!("surface_{frame:04}.obj"),
            MeshFormat::Ply => format!("surface_{frame:04}.ply"),
        });
        match f {
            MeshFormat::Obj => files::write_obj(&path, &mesh)?,
            MeshFormat::Ply => files::write_ply(&path, &mesh)?,
        }
        Ok(path)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for c in &mut self.slots {
            c.destroy(ctx);
        }
    }
}

/// Centre of mass, extent and kinetic energy (0.5 m |v|^2 summed) of a snapshot; the
/// front along +x is `max[0]`.
pub struct Aggregates {
    pub com: [f64; 3],
    pub min: [f32; 3],
    pub max: [f32; 3],
    pub kinetic: f64,
}

pub fn aggregates(s: &Snapshot, mass: f32) -> Aggregates {
    let n = s.pos.len().max(1) as f64;
    let mut com = [0.0f64; 3];
    let (mut min, mut max) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    let mut kinetic = 0.0f64;
    for (p, v) in s.pos.iter().zip(s.vel) {
        for k in 0..3 {
            com[k] += p[k] as f64 / n;
            min[k] = min[k].min(p[k]);
            max[k] = max[k].max(p[k]);
        }
        let v2 = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) as f64;
        kinetic += 0.5 * mass as f64 * v2;
    }
    Aggregates {
        com,
        min,
        max,
        kinetic,
    }
}

/// Binary little-endian PLY: x y z vx vy vz density pressure (float) and group (uint).
pub fn ply(s: &Snapshot) -> Vec<u8> {
    let n = s.pos.len();
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\ncomment fluidform SPH particles\nelement vertex {n}\n\
         property float x\nproperty float y\nproperty float z\n\
         property float vx\nproperty float vy\nproperty float vz\n\
         property float density\nproperty float pressure\nproperty uint group\nend_header\n"
    )
    .into_bytes();
    out.reserve(n * 36);
    for i in 0..n {
        let p = s.pos[i];
        let v = s.vel[i];
        for x in [
            p[0],
            p[1],
            p[2],
            v[0],
            v[1],
            v[2],
            s.rho_p[i][0],
            s.rho_p[i][1],
        ] {
            out.extend_from_slice(&x.to_le_bytes());
        }
        out.extend_from_slice(&s.group(i).to_le_bytes());
    }
    out
}

/// Legacy VTK polydata (binary, big-endian as the format requires): points, one vertex
/// cell each, and velocity, density, pressure and group as point data.
pub fn vtk(s: &Snapshot, frame: u64) -> Vec<u8> {
    let n = s.pos.len();
    let mut out = Vec::with_capacity(n * 60 + 512);
    let text = |t: String, out: &mut Vec<u8>| out.extend_from_slice(t.as_bytes());
    text(
        format!(
            "# vtk DataFile Version 3.0\nfluidform particles, frame {frame}\nBINARY\n\
             DATASET POLYDATA\nPOINTS {n} float\n"
        ),
        &mut out,
    );
    let floats = |out: &mut Vec<u8>, v: &mut dyn Iterator<Item = f32>| {
        for x in v {
            out.extend_from_slice(&x.to_be_bytes());
        }
    };
    floats(&mut out, &mut s.pos.iter().flat_map(|p| [p[0], p[1], p[2]]));
    text(format!("\nVERTICES {n} {}\n", 2 * n), &mut out);
    for i in 0..n as i32 {
        out.extend_from_slice(&1i32.to_be_bytes());
        out.extend_from_slice(&i.to_be_bytes());
    }
    text(
        format!("\nPOINT_DATA {n}\nVECTORS velocity float\n"),
        &mut out,
    );
    floats(&mut out, &mut s.vel.iter().flat_map(|v| [v[0], v[1], v[2]]));
    text(
        "\nSCALARS density float 1\nLOOKUP_TABLE default\n".into(),
        &mut out,
    );
    floats(&mut out, &mut s.rho_p.iter().map(|r| r[0]));
    text(
        "\nSCALARS pressure float 1\nLOOKUP_TABLE default\n".into(),
        &mut out,
    );
    floats(&mut out, &mut s.rho_p.iter().map(|r| r[1]));
    text(
        "\nSCALARS group int 1\nLOOKUP_TABLE default\n".into(),
        &mut out,
    );
    for i in 0..n {
        out.extend_from_slice(&(s.group(i) as i32).to_be_bytes());
    }
    out.push(b'\n');
    out
}

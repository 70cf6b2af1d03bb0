//! A scene's emitter: the source (the UV atlas of RenderToUV, or the vertices: the
//! baseline seed 002 argues against), the Emit pass hooked into the SPH step before
//! arrange, and the per-slot life attribute in the particle registry. Each frame the
//! source takes the skinned surface at the frame's end (the previous one kept); each step
//! emits over its share of the frame interval, and copies the GPU-side alive count into
//! the step's parameters, so no pass waits on the CPU.
use super::emit::{EmitGpuParams, EmitInput, EmitPass, EmitSettings};
use super::layout::UvLayout;
use super::uv::UvSurface;
use crate::emission::EmitterKind;
use crate::error::{Error, Result};
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{Buffer, Context, Guard, Scopes};
use crate::sph::hooks::SphHook;
use crate::sph::params::SphGpuParams;
use crate::sph::store::{AttrId, AttributeDecl};
use crate::sph::SphState;

const VERTICES_SCOPE: crate::gpu::ScopeName = crate::gpu::ScopeName::new("vertices");

/// The vertex emitter's source: the skinned positions of this frame and the last.
pub struct VertexSource {
    pub pos: [Buffer; 2],
    /// 0 .. vertices (every vertex is a source).
    pub valid: Buffer,
    pub vertices: u32,
    current: usize,
}

#[allow(clippy::large_enum_variant)] // one per scene
pub enum EmitSource {
    Uv(Box<UvSurface>, UvLayout),
    Vertices(VertexSource),
}

impl EmitSource {
    /// For a mesh of `rest` vertex positions: its UV atlas (`layout`) at `size`, or
    /// its vertices.
    pub fn new(
        ctx: &Context,
        kind: EmitterKind,
        layout: Option<UvLayout>,
        rest: &[glam::Vec3],
        size: [u32; 2],
    ) -> Result<Self> {
        Ok(match kind {
            EmitterKind::Uv => {
                let layout = layout
                    .ok_or_else(|| Error::Param("the UV emitter needs a UV layout".into()))?;
                EmitSource::Uv(Box::new(UvSurface::new(ctx, &layout, rest, size)?), layout)
            }
            EmitterKind::Vertices => {
                let n = rest.len() as u64;
                let buf =
                    |name: &str, bytes| ctx.storage_buffer(name, bytes).map(|b| Guard::new(ctx, b));
                let p0 = buf("emit vertices 0", n * 16)?;
                let p1 = buf("emit vertices 1", n * 16)?;
                let mut valid = buf("emit vertex list", n.max(1) * 4)?;
                let iota: Vec<u32> = (0..n as u32).collect();
                ctx.upload(&mut valid, 0, &iota)?;
                EmitSource::Vertices(VertexSource {
                    pos: [p0.take(), p1.take()],
                    valid: valid.take(),
                    vertices: n as u32,
                    current: 0,
                })
            }
        })
    }

    pub fn kind(&self) -> EmitterKind {
        match self {
            EmitSource::Uv(..) => EmitterKind::Uv,
            EmitSource::Vertices(_) => EmitterKind::Vertices,
        }
    }

    /// Histogram bins: layout triangles or vertices.
    pub fn primitives(&self) -> u32 {
        match self {
            EmitSource::Uv(_, l) => l.triangles() as u32,
            EmitSource::Vertices(v) => v.vertices,
        }
    }

    /// Points a birth may pick: covered texels or vertices.
    pub fn sources(&self) -> u32 {
        match self {
            EmitSource::Uv(uv, _) => uv.valid_count,
            EmitSource::Vertices(v) => v.vertices,
        }
    }

    /// Take the skinned surface (`verts`, visible to vertex shaders, compute and copies)
    /// as the current frame; the current one becomes the previous.
    pub fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        verts: &Buffer,
    ) -> Result<()> {
        match self {
            EmitSource::Uv(uv, _) => uv.record(ctx, cmd, scopes, verts),
            EmitSource::Vertices(v) => {
                let next = 1 - v.current;
                {
                    let _scope = scopes.open(ctx, cmd, VERTICES_SCOPE);
                    ctx.copy(cmd, verts, 0, &v.pos[next], 0, v.vertices as u64 * 16);
                }
                v.current = next;
                Ok(())
            }
        }
    }

    /// (current, previous, source list).
    pub fn frames(&self) -> (&Buffer, &Buffer, &Buffer) {
        match self {
            EmitSource::Uv(uv, _) => {
                let c = uv.current();
                (&uv.pos[c], &uv.pos[1 - c], &uv.valid)
            }
            EmitSource::Vertices(v) => {
                let c = v.current;
                (&v.pos[c], &v.pos[1 - c], &v.valid)
            }
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        match self {
            EmitSource::Uv(uv, _) => uv.destroy(ctx),
            EmitSource::Vertices(v) => {
                let [a, b] = &mut v.pos;
                for x in [a, b, &mut v.valid] {
                    ctx.destroy_buffer(x);
                }
            }
        }
    }
}
crate::impl_destroy!(EmitSource);

/// The life attribute: x age (s, negative: dead), y 1 for a permanent particle.
pub const LIFE: AttributeDecl = AttributeDecl {
    name: "emission life",
    bytes: 16,
    reorder: true,
};

/// Births' random offset, in rest spacings (emit.comp's `jitter`).
pub const JITTER: f32 = 0.01;

pub struct Emitter {
    pub pass: EmitPass,
    pub source: EmitSource,
    pub settings: EmitSettings,
    life: AttrId,
    seed: u64,
    step: u64,
    /// Fractional births carried to the next step (a rate limit).
    carry: f64,
    /// (this step within the frame, steps in the frame).
    substep: (u32, u32),
    frame_dt: f32,
}

impl Emitter {
    /// Register the life attribute in `st` (slots whose initial pos.w < 0 start dead; the
    /// others are permanent, or with `recycle` alive at ages spread over (0, limit)) and
    /// make the pass for `source`.
    pub fn new(
        ctx: &Context,
        st: &mut SphState,
        initial: &[[f32; 4]],
        source: EmitSource,
        (settings, recycle): (EmitSettings, bool),
        seed: u64,
    ) -> Result<Self> {
        settings.validate()?;
        let source = Guard::new(ctx, source);
        let pass = Guard::new(
            ctx,
            EmitPass::new(ctx, source.kind() == EmitterKind::Uv, source.primitives())?,
        );
        let life = st.particles.register(ctx, LIFE)?;
        let init: Vec<[f32; 4]> = initial
            .iter()
            .enumerate()
            .map(|(i, p)| match (p[3] < 0.0, recycle) {
                (true, _) => [-1.0, 0.0, 0.0, 0.0],
                (false, false) => [0.0, 1.0, 0.0, 0.0],
                (false, true) => {
                    // A golden-ratio sequence: ages evenly over (0, limit), no two alike.
                    let u = ((i as f64 + 0.5) * 0.618_033_988_749_895).fract() as f32;
                    [u * settings.limit, 0.0, 0.0, 0.0]
                }
            })
            .collect();
        st.particles.upload(ctx, life, &init)?;
        Ok(Self {
            pass: pass.take(),
            source: source.take(),
            settings,
            life,
            seed,
            step: 0,
            carry: 0.0,
            substep: (0, 1),
            frame_dt: 0.0,
        })
    }

    /// Before a frame of `steps` steps over `frame_dt` seconds (after the source took the
    /// frame's surface).
    pub fn begin_frame(&mut self, steps: u32, frame_dt: f32) {
        self.substep = (0, steps.max(1));
        self.frame_dt = frame_dt;
    }

    /// This step's budget: every due slot (Algorithm 1) or the rate's share.
    fn budget(&mut self, dt: f32) -> u32 {
        match self.settings.rate {
            None => u32::MAX,
            Some(r) => {
                let want = r as f64 * dt as f64 + self.carry;
                let whole = want.floor();
                self.carry = want - whole;
                whole.min(u32::MAX as f64) as u32
            }
        }
    }

    /// Record one step's births and copy the alive count into the step's parameters.
    pub fn record_step(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        st: &SphState,
    ) -> Result<()> {
        let step = self.step;
        self.step += 1;
        let (k, steps) = self.substep;
        self.substep = (k + 1, steps);
        let frame_dt = self.frame_dt;
        let budget = self.budget(st.dt);
        let s = &self.settings;
        let mixed = (self.seed ^ step.wrapping_mul(0x9E37_79B9_7F4A_7C15)) as u32;
        let p = EmitGpuParams {
            n: st.n,
            sources: self.source.sources(),
            budget,
            seed: mixed ^ (step >> 32) as u32,
            limit: s.limit,
            dt: st.dt,
            dtau: s.dtau,
            k: if frame_dt > 0.0 {
                s.transfer / frame_dt
            } else {
                0.0
            },
            tau_lo: (k.min(steps - 1)) as f32 / steps as f32,
            tau_hi: (k.min(steps - 1) + 1) as f32 / steps as f32,
            frame_dt,
            jitter: JITTER * st.fluid.spacing(),
        };
        let (cur, prev, valid) = self.source.frames();
        let input = EmitInput {
            cur,
            prev,
            valid,
            sources: p.sources,
            pos: st.pos(),
            vel: st.vel(),
            vhalf: st.particles.get(crate::sph::solver::VHALF),
            life: st.particles.get(self.life),
        };
        self.pass.record(ctx, cmd, &p, &input);
        ctx.copy(
            cmd,
            &self.pass.counts,
            EmitPass::ALIVE_OFFSET,
            st.params(),
            SphGpuParams::LIVE_OFFSET,
            4,
        );
        Ok(())
    }

    /// The life attribute of every slot (current order).
    pub fn read_life(&self, ctx: &Context, st: &SphState) -> Result<Vec<[f32; 4]>> {
        st.particles.read(ctx, self.life, st.n as usize)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pass.destroy(ctx);
        self.source.destroy(ctx);
    }
}

/// The emitter is the SPH step's pre-arrange hook (scope `sph/emit`); the scene owns it
/// and lends it to each frame's steps.
impl SphHook for Emitter {
    fn scope(&self) -> crate::gpu::ScopeName {
        super::emit::EMIT.scope()
    }

    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        _: &mut dyn Scopes,
        st: &SphState,
    ) -> Result<()> {
        self.record_step(ctx, cmd, st)
    }

    fn destroy(&mut self, ctx: &Context) {
        Emitter::destroy(self, ctx);
    }
}

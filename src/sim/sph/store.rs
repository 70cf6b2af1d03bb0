//! Particle state as a registry of per-particle attributes. An attribute is declared once
//! (name, bytes per particle, whether it follows the particle through a reorder); upload,
//! reorder, grow, readback and destroy iterate the registry, so a new attribute is one
//! `register` call. Buffers hold `capacity` particles; the live count is apart from it, on
//! the host (`live`) and on the GPU (`count`: the count and indirect-dispatch arguments that
//! GPU passes such as emission and death can change with no CPU round trip).
use crate::error::{Error, Result};
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{Buffer, ComputePipeline, Context, Destroy, Guard, Scopes};
use crate::primitives::counting::GatherPass;
use bytemuck::{Pod, Zeroable};

const REORDER_SCOPE: crate::gpu::ScopeName = crate::gpu::ScopeName::new("reorder");

/// How an attribute is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AttributeDecl {
    pub name: &'static str,
    /// Bytes per particle (16 for a vec4).
    pub bytes: u32,
    /// Reordered with the particles (double-buffered, vec4 only); otherwise scratch that
    /// is recomputed in sorted order every step.
    pub reorder: bool,
}

/// Index of a registered attribute.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AttrId(pub usize);

struct Attribute {
    decl: AttributeDecl,
    /// Two buffers when reordered (current = `ParticleStore::cur`), else one.
    bufs: Vec<Buffer>,
}

/// The GPU-side live count (mirrors `LiveCount` in glsl/common/live.glsl): the count, the
/// capacity, and VkDispatchIndirectCommand group counts for `local_size` invocations.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq, Eq)]
pub struct LiveCount {
    pub n: u32,
    pub capacity: u32,
    pub local_size: u32,
    pub pad: u32,
    pub groups: [u32; 3],
    pub pad2: u32,
}
const _: () = assert!(std::mem::size_of::<LiveCount>() == 32);

/// Group counts split over y past 65535, as glsl/common/live_args.comp writes them.
fn split_groups(total: u32) -> [u32; 3] {
    let gx = total.min(crate::gpu::pipeline::MAX_GROUPS_X);
    [gx, if gx == 0 { 1 } else { total.div_ceil(gx) }, 1]
}

impl LiveCount {
    /// Byte offset of the indirect-dispatch arguments.
    pub const ARGS_OFFSET: u64 = std::mem::offset_of!(LiveCount, groups) as u64;
}

crate::gpu_interface! {
    /// glsl/common/live_args.comp: group counts from the GPU-side count.
    pub LiveArgsIo / LiveArgsBufs: "LIVE", push () { count = 0 }
}

crate::gpu::compute_pass!(pub LIVE_ARGS: LiveArgsIo, () = "live args", "common/live_args.comp");

/// Writes the indirect-dispatch arguments from the GPU-side count.
pub struct LiveArgsPass {
    pipeline: ComputePipeline<LiveArgsIo>,
}

impl LiveArgsPass {
    pub fn new(ctx: &Context) -> Result<Self> {
        Ok(Self {
            pipeline: LIVE_ARGS.pipeline(ctx, &(), 1, &[])?,
        })
    }

    /// groups = ceil(n / local_size) for the count in `count` (after whatever set n).
    pub fn record(&self, ctx: &Context, cmd: vk::CommandBuffer, count: &Buffer) {
        self.pipeline
            .dispatch_groups(ctx, cmd, &LiveArgsBufs { count }, &(), 1);
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}

pub struct ParticleStore {
    attrs: Vec<Attribute>,
    cur: usize,
    pub capacity: u64,
    /// Live particles as the host knows them (passes dispatched with a host count).
    pub live: u32,
    /// `LiveCount` on the GPU.
    pub count: Buffer,
    name: String,
}

impl ParticleStore {
    /// An empty store of `capacity` particles; `name` prefixes buffer names.
    pub fn new(ctx: &Context, name: &str, capacity: u64) -> Result<Self> {
        if capacity == 0 || capacity > u32::MAX as u64 {
            return Err(Error::Param(format!(
                "{name}: particle capacity {capacity} outside 1..=2^32-1"
            )));
        }
        Ok(Self {
            attrs: Vec::new(),
            cur: 0,
            capacity,
            live: 0,
            count: ctx.indirect_buffer(&format!("{name} live count"), 32)?,
            name: name.to_string(),
        })
    }

    /// Declare an attribute; its buffers hold `capacity` particles.
    pub fn register(&mut self, ctx: &Context, decl: AttributeDecl) -> Result<AttrId> {
        if self.attrs.iter().any(|a| a.decl.name == decl.name) {
            return Err(Error::Param(format!(
                "{}: attribute '{}' registered twice",
                self.name, decl.name
            )));
        }
        if decl.reorder && decl.bytes != 16 {
            return Err(Error::Param(format!(
                "{}: reordered attribute '{}' must be a vec4 (16 bytes), not {}",
                self.name, decl.name, decl.bytes
            )));
        }
        let bufs = Self::alloc(ctx, &self.name, decl, self.capacity)?;
        self.attrs.push(Attribute { decl, bufs });
        Ok(AttrId(self.attrs.len() - 1))
    }

    fn alloc(ctx: &Context, store: &str, d: AttributeDecl, cap: u64) -> Result<Vec<Buffer>> {
        let bytes = cap * d.bytes as u64;
        let mut bufs = Guard::new(ctx, Vec::new());
        if d.reorder {
            bufs.push(ctx.storage_buffer(&format!("{store} {} A", d.name), bytes)?);
            bufs.push(ctx.storage_buffer(&format!("{store} {} B", d.name), bytes)?);
        } else {
            bufs.push(ctx.storage_buffer(&format!("{store} {}", d.name), bytes)?);
        }
        Ok(bufs.take())
    }

    /// The attribute's buffer in the current particle order.
    pub fn get(&self, id: AttrId) -> &Buffer {
        let a = &self.attrs[id.0];
        if a.decl.reorder {
            &a.bufs[self.cur]
        } else {
            &a.bufs[0]
        }
    }

    pub fn decl(&self, id: AttrId) -> AttributeDecl {
        self.attrs[id.0].decl
    }

    /// Every attribute in registration order.
    pub fn ids(&self) -> impl Iterator<Item = AttrId> {
        (0..self.attrs.len()).map(AttrId)
    }

    /// Set the live count on the host and the GPU (upload: outside command recording).
    pub fn set_live(&mut self, ctx: &Context, n: u32, local_size: u32) -> Result<()> {
        if n as u64 > self.capacity {
            return Err(Error::Param(format!(
                "{}: {n} live particles exceed the capacity {}",
                self.name, self.capacity
            )));
        }
        self.live = n;
        let c = LiveCount {
            n,
            capacity: self.capacity as u32,
            local_size,
            pad: 0,
            groups: split_groups(n.div_ceil(local_size.max(1))),
            pad2: 0,
        };
        ctx.upload(&mut self.count, 0, &[c])
    }

    /// Upload the first particles of an attribute (in the current order).
    pub fn upload<T: Pod>(&mut self, ctx: &Context, id: AttrId, data: &[T]) -> Result<()> {
        let a = &mut self.attrs[id.0];
        let i = if a.decl.reorder { self.cur } else { 0 };
        ctx.upload(&mut a.bufs[i], 0, data)
    }

    /// The first `n` particles of an attribute, in the current order.
    pub fn read<T: Pod>(&self, ctx: &Context, id: AttrId, n: usize) -> Result<Vec<T>> {
        ctx.readback(self.get(id), 0, n)
    }

    /// Record moving every reordered attribute into sorted order: `dst[i] = src[perm[i]]`.
    pub fn record_reorder(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        gather: &GatherPass,
        perm: &Buffer,
    ) {
        let (a, b) = (self.cur, 1 - self.cur);
        {
            let _scope = scopes.open(ctx, cmd, REORDER_SCOPE);
            let pairs: Vec<_> = (self.attrs.iter().filter(|x| x.decl.reorder))
                .map(|x| (&x.bufs[a], &x.bufs[b]))
                .collect();
            gather.record_many(ctx, cmd, perm, &pairs, self.live);
        }
        self.cur = b;
    }

    /// Reallocate every attribute for `capacity` particles, keeping the live ones. The
    /// old buffers are destroyed: call it when no frame in flight uses them (after
    /// `Context::wait_idle`).
    pub fn grow(&mut self, ctx: &Context, capacity: u64) -> Result<()> {
        if capacity > u32::MAX as u64 {
            return Err(Error::Param(format!(
                "{}: particle capacity {capacity} over 2^32-1",
                self.name
            )));
        }
        if capacity < self.live as u64 {
            return Err(Error::Param(format!(
                "{}: cannot shrink below the {} live particles",
                self.name, self.live
            )));
        }
        let mut fresh = Guard::new(ctx, Vec::new());
        for a in &self.attrs {
            fresh.push(Self::alloc(ctx, &self.name, a.decl, capacity)?);
        }
        let live = self.live as u64;
        let cur = self.cur;
        ctx.one_shot(|cmd| {
            for (a, new) in self.attrs.iter().zip(fresh.iter()) {
                let i = if a.decl.reorder { cur } else { 0 };
                ctx.copy(cmd, &a.bufs[i], 0, &new[i], 0, live * a.decl.bytes as u64);
            }
        })?;
        for (a, new) in self.attrs.iter_mut().zip(fresh.take()) {
            a.bufs.destroy(ctx);
            a.bufs = new;
        }
        self.capacity = capacity;
        let mut c: LiveCount = ctx.readback(&self.count, 0, 1)?[0];
        c.capacity = capacity as u32;
        ctx.upload(&mut self.count, 0, &[c])
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for a in &mut self.attrs {
            a.bufs.destroy(ctx);
        }
        ctx.destroy_buffer(&mut self.count);
    }
}

crate::impl_destroy!(ParticleStore, LiveArgsPass);

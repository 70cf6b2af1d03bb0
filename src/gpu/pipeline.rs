//! Compute and graphics pipelines of a checked interface (gpu/interface.rs). Storage buffers
//! are bound with push descriptors, so a pass owns only layouts and pipelines and any buffer
//! (of any size) can be bound per dispatch.
//! Specialization constant 0 is the workgroup size (`layout(local_size_x_id = 0) in;`),
//! constants 1.. are the pass's own.
use super::access::{buffer_uses, Use};
use super::interface::{check, BindingDecl, Interface, Reflected};
use super::pipelines::{Built, PipelineKey};
use super::track::BufferUse;
use super::{Buffer, Context};
use crate::error::{Error, Result, VkContext};
use ash::vk;
use std::collections::BTreeMap;
use std::marker::PhantomData;

/// The tracker's view of a dispatch's or draw's bound buffers: each binding the stage's
/// SPIR-V touches, over the bytes its descriptor views.
pub(crate) fn bound_uses<'a>(
    buffers: &'a [(u32, vk::DescriptorBufferInfo)],
    uses: &'a BTreeMap<u32, Use>,
    stage: vk::PipelineStageFlags2,
) -> impl Iterator<Item = BufferUse> + 'a {
    let (read, write) = (
        vk::AccessFlags2::SHADER_STORAGE_READ,
        vk::AccessFlags2::SHADER_STORAGE_WRITE,
    );
    buffers.iter().filter_map(move |(b, info)| {
        let u = uses.get(b)?;
        let at = BufferUse::at(info.buffer, stage, (u.read, read), (u.write, write));
        Some(at.bytes(info.offset, info.range))
    })
}

/// Most workgroups one dimension of a dispatch may have on every Vulkan device.
pub const MAX_GROUPS_X: u32 = 65535;

pub(crate) fn shader_module(ctx: &Context, spv: &[u32], name: &str) -> Result<vk::ShaderModule> {
    let info = vk::ShaderModuleCreateInfo::default().code(spv);
    let m = unsafe { ctx.device.create_shader_module(&info, None) }
        .ctx(&format!("shader module {name}"))?;
    ctx.set_name(m, name);
    Ok(m)
}

/// Set layout of the interface's storage buffers for push descriptors, and a pipeline
/// layout with `push_size` bytes of push constants.
pub(crate) fn layouts(
    ctx: &Context,
    decls: &[BindingDecl],
    push_size: u32,
    stages: vk::ShaderStageFlags,
    name: &str,
) -> Result<(vk::DescriptorSetLayout, vk::PipelineLayout)> {
    let bindings: Vec<_> = decls
        .iter()
        .map(|d| {
            vk::DescriptorSetLayoutBinding::default()
                .binding(d.binding)
                .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                .descriptor_count(1)
                .stage_flags(stages)
        })
        .collect();
    let info = vk::DescriptorSetLayoutCreateInfo::default()
        .flags(vk::DescriptorSetLayoutCreateFlags::PUSH_DESCRIPTOR_KHR)
        .bindings(&bindings);
    let set_layout = unsafe { ctx.device.create_descriptor_set_layout(&info, None) }
        .ctx(&format!("{name} set layout"))?;
    ctx.set_name(set_layout, &format!("{name} set layout"));
    let ranges = [vk::PushConstantRange {
        stage_flags: stages,
        offset: 0,
        size: push_size,
    }];
    let sets = [set_layout];
    let mut pl = vk::PipelineLayoutCreateInfo::default().set_layouts(&sets);
    if push_size > 0 {
        pl = pl.push_constant_ranges(&ranges);
    }
    let layout = match unsafe { ctx.device.create_pipeline_layout(&pl, None) } {
        Ok(l) => l,
        Err(e) => {
            unsafe { ctx.device.destroy_descriptor_set_layout(set_layout, None) };
            return Err(e).ctx(&format!("{name} pipeline layout"));
        }
    };
    ctx.set_name(layout, &format!("{name} pipeline layout"));
    Ok((set_layout, layout))
}

pub(crate) fn push_buffers(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    bind: vk::PipelineBindPoint,
    layout: vk::PipelineLayout,
    buffers: &[(u32, vk::DescriptorBufferInfo)],
) {
    let writes: Vec<_> = buffers
        .iter()
        .map(|(binding, info)| {
            vk::WriteDescriptorSet::default()
                .dst_binding(*binding)
                .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                .buffer_info(std::slice::from_ref(info))
        })
        .collect();
    if !writes.is_empty() {
        unsafe {
            ctx.push_descriptor
                .cmd_push_descriptor_set(cmd, bind, layout, 0, &writes)
        };
    }
}

/// The interface's binding defines followed by the pass's own.
pub(crate) fn all_defines<I: Interface>(own: &[(&str, String)]) -> Vec<(String, String)> {
    let mut d = I::defines();
    d.extend(own.iter().map(|(k, v)| (k.to_string(), v.clone())));
    d
}

/// Owned defines as the `(&str, String)` pairs a `ComputeDesc` takes.
pub fn as_refs(d: &[(String, String)]) -> Vec<(&str, String)> {
    d.iter().map(|(k, v)| (k.as_str(), v.clone())).collect()
}

/// Compile `files` with `defines` and check what they declare against `I`.
pub(crate) fn checked_stages<I: Interface>(
    ctx: &Context,
    pass: &str,
    files: &[&str],
    defines: &[(&str, String)],
) -> Result<Vec<std::sync::Arc<Vec<u32>>>> {
    let mut declared = Vec::new();
    let mut spv = Vec::new();
    for f in files {
        declared.push(ctx.shaders.declared(f, defines)?);
        spv.push(ctx.shaders.compile(f, defines)?);
    }
    let stages: Vec<(&str, &Reflected)> = files
        .iter()
        .zip(&declared)
        .map(|(f, r)| (*f, r.as_ref()))
        .collect();
    check(pass, &stages, I::BINDINGS, std::mem::size_of::<I::Push>())?;
    Ok(spv)
}

/// Where a compute shader comes from and how it is specialised.
pub struct ComputeDesc<'a> {
    /// Name for debug labels and object names.
    pub name: &'a str,
    /// Path under glsl/.
    pub shader: &'a str,
    pub defines: &'a [(&'a str, String)],
    /// Workgroup size in x (specialization constant 0).
    pub local_size: u32,
    /// Specialization constants 1, 2, ...
    pub spec: &'a [u32],
}

impl<'a> ComputeDesc<'a> {
    /// A pipeline with no specialization constants but the workgroup size.
    pub fn plain(
        name: &'a str,
        shader: &'a str,
        defines: &'a [(&'a str, String)],
        local_size: u32,
    ) -> Self {
        Self {
            name,
            shader,
            defines,
            local_size,
            spec: &[],
        }
    }
}

/// A compute pipeline of interface `I`: dispatches take `I::Bufs` and `I::Push`.
pub struct ComputePipeline<I: Interface> {
    pub pipeline: vk::Pipeline,
    pub layout: vk::PipelineLayout,
    pub set_layout: vk::DescriptorSetLayout,
    pub local_size: u32,
    pub name: String,
    /// What the shader does with each binding (from its SPIR-V): the barrier tracker's input.
    uses: BTreeMap<u32, Use>,
    interface: PhantomData<I>,
}

impl<I: Interface> ComputePipeline<I> {
    pub fn new(ctx: &Context, d: &ComputeDesc) -> Result<Self> {
        if d.local_size == 0 || d.local_size > ctx.limits.max_compute_work_group_invocations {
            return Err(Error::Param(format!(
                "{}: workgroup size {} is outside 1..={}",
                d.name, d.local_size, ctx.limits.max_compute_work_group_invocations
            )));
        }
        let defines = all_defines::<I>(d.defines);
        let mut fixed = vec![d.local_size as i64];
        fixed.extend(d.spec.iter().map(|v| *v as i64));
        let key = PipelineKey::new(std::any::type_name::<I>(), &[d.shader], &defines, fixed);
        let b = match ctx.pipelines.acquire(&key) {
            Some(b) => b,
            None => Self::build(ctx, d, &defines, key)?,
        };
        Ok(Self {
            pipeline: b.pipeline,
            layout: b.layout,
            set_layout: b.set_layout,
            local_size: d.local_size,
            name: d.name.to_string(),
            uses: b.uses[0].1.clone(),
            interface: PhantomData,
        })
    }

    /// A new pipeline of `d`, kept under `key`.
    fn build(
        ctx: &Context,
        d: &ComputeDesc,
        defines: &[(String, String)],
        key: PipelineKey,
    ) -> Result<Built> {
        let spv = checked_stages::<I>(ctx, d.name, &[d.shader], &as_refs(defines))?;
        let push_size = std::mem::size_of::<I::Push>() as u32;
        let (set_layout, layout) = layouts(
            ctx,
            I::BINDINGS,
            push_size,
            vk::ShaderStageFlags::COMPUTE,
            d.name,
        )?;
        let module = match shader_module(ctx, &spv[0], d.shader) {
            Ok(m) => m,
            Err(e) => {
                destroy_layouts(ctx, layout, set_layout);
                return Err(e);
            }
        };
        let mut values = vec![d.local_size];
        values.extend_from_slice(d.spec);
        let entries: Vec<_> = (0..values.len() as u32)
            .map(|i| vk::SpecializationMapEntry {
                constant_id: i,
                offset: i * 4,
                size: 4,
            })
            .collect();
        let spec = vk::SpecializationInfo::default()
            .map_entries(&entries)
            .data(bytemuck::cast_slice(&values));
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(c"main")
            .specialization_info(&spec);
        let info = vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layout);
        let r = unsafe {
            ctx.device
                .create_compute_pipelines(ctx.pipeline_cache, &[info], None)
        };
        unsafe { ctx.device.destroy_shader_module(module, None) };
        let uses = vec![(
            vk::PipelineStageFlags2::COMPUTE_SHADER,
            buffer_uses(&spv[0]),
        )];
        keep(ctx, key, d.name, r, (layout, set_layout), uses)
    }

    /// Bind the pipeline, push its descriptors and constants, after the barrier its buffers'
    /// hazards need (and `args`', read as indirect arguments).
    fn bind(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        bufs: &I::Bufs<'_>,
        push: &I::Push,
        args: Option<&Buffer>,
    ) {
        let buffers = I::buffers(bufs);
        let stage = vk::PipelineStageFlags2::COMPUTE_SHADER;
        let mut uses: Vec<BufferUse> = bound_uses(&buffers, &self.uses, stage).collect();
        uses.extend(args.map(|a| BufferUse::indirect(a.raw)));
        ctx.track(cmd, &uses, true);
        unsafe {
            ctx.device
                .cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
            push_buffers(
                ctx,
                cmd,
                vk::PipelineBindPoint::COMPUTE,
                self.layout,
                &buffers,
            );
            let bytes = bytemuck::bytes_of(push);
            if !bytes.is_empty() {
                ctx.device.cmd_push_constants(
                    cmd,
                    self.layout,
                    vk::ShaderStageFlags::COMPUTE,
                    0,
                    bytes,
                );
            }
        }
    }

    /// Dispatch `groups` workgroups (split over y when more than 65535; shaders linearise
    /// with `global_id()` from common/index.glsl).
    pub fn dispatch_groups(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        bufs: &I::Bufs<'_>,
        push: &I::Push,
        groups: u64,
    ) {
        if groups == 0 {
            return;
        }
        let gx = groups.min(MAX_GROUPS_X as u64) as u32;
        let gy = groups.div_ceil(gx as u64) as u32;
        self.bind(ctx, cmd, bufs, push, None);
        ctx.count_dispatch(cmd, false);
        unsafe { ctx.device.cmd_dispatch(cmd, gx, gy, 1) };
    }

    /// Dispatch one invocation per element (bounds-checked in the shader).
    pub fn dispatch(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        bufs: &I::Bufs<'_>,
        push: &I::Push,
        elements: u64,
    ) {
        self.dispatch_groups(
            ctx,
            cmd,
            bufs,
            push,
            elements.div_ceil(self.local_size as u64),
        );
    }

    /// Dispatch with the group counts a GPU pass wrote into `args` at byte `offset`
    /// (a VkDispatchIndirectCommand): element counts that live on the GPU.
    pub fn dispatch_indirect(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        bufs: &I::Bufs<'_>,
        push: &I::Push,
        args: &Buffer,
        offset: u64,
    ) {
        self.bind(ctx, cmd, bufs, push, Some(args));
        ctx.count_dispatch(cmd, true);
        unsafe { ctx.device.cmd_dispatch_indirect(cmd, args.raw, offset) };
    }

    /// Give up this holder's share: the last holder destroys the pipeline and layouts.
    pub fn destroy(&mut self, ctx: &Context) {
        release(ctx, self.pipeline, self.layout, self.set_layout);
        self.pipeline = vk::Pipeline::null();
        self.layout = vk::PipelineLayout::null();
        self.set_layout = vk::DescriptorSetLayout::null();
    }
}

/// The driver's answer `created` named, counted and kept under `key` with its layouts and
/// the stages' binding uses; on an error the layouts are destroyed.
pub(crate) fn keep(
    ctx: &Context,
    key: PipelineKey,
    name: &str,
    created: std::result::Result<Vec<vk::Pipeline>, (Vec<vk::Pipeline>, vk::Result)>,
    (layout, set_layout): (vk::PipelineLayout, vk::DescriptorSetLayout),
    uses: Vec<(vk::PipelineStageFlags2, BTreeMap<u32, Use>)>,
) -> Result<Built> {
    let pipeline = match created.map_err(|(_, e)| e).ctx(&format!("{name} pipeline")) {
        Ok(p) => p[0],
        Err(e) => {
            destroy_layouts(ctx, layout, set_layout);
            return Err(e);
        }
    };
    ctx.set_name(pipeline, name);
    ctx.count_object("pipeline", 1);
    let built = Built {
        pipeline,
        layout,
        set_layout,
        uses,
    };
    ctx.pipelines.insert(key, built.clone());
    Ok(built)
}

/// One holder fewer of `pipeline`; the last destroys it and its layouts.
pub(crate) fn release(
    ctx: &Context,
    pipeline: vk::Pipeline,
    layout: vk::PipelineLayout,
    set_layout: vk::DescriptorSetLayout,
) {
    if pipeline == vk::Pipeline::null() || !ctx.pipelines.release(pipeline) {
        return;
    }
    unsafe { ctx.device.destroy_pipeline(pipeline, None) };
    ctx.count_object("pipeline", -1);
    destroy_layouts(ctx, layout, set_layout);
}

pub(crate) fn destroy_layouts(
    ctx: &Context,
    layout: vk::PipelineLayout,
    set: vk::DescriptorSetLayout,
) {
    unsafe {
        ctx.device.destroy_pipeline_layout(layout, None);
        ctx.device.destroy_descriptor_set_layout(set, None);
    }
}

impl<I: Interface> super::Destroy for ComputePipeline<I> {
    fn destroy(&mut self, ctx: &Context) {
        ComputePipeline::destroy(self, ctx)
    }
}

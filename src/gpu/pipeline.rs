//! Compute and graphics pipelines. Storage buffers are bound with push descriptors, so a
//! pass owns only layouts and pipelines and any buffer (of any size) can be bound per dispatch.
//! Specialization constant 0 is the workgroup size (`layout(local_size_x_id = 0) in;`),
//! constants 1.. are the pass's own.
use super::Context;
use crate::error::{Error, Result, VkContext};
use ash::vk;

/// Most workgroups one dimension of a dispatch may have on every Vulkan device.
pub const MAX_GROUPS_X: u32 = 65535;

fn shader_module(ctx: &Context, spv: &[u32], name: &str) -> Result<vk::ShaderModule> {
    let info = vk::ShaderModuleCreateInfo::default().code(spv);
    let m = unsafe { ctx.device.create_shader_module(&info, None) }
        .ctx(&format!("shader module {name}"))?;
    ctx.set_name(m, name);
    Ok(m)
}

/// Set layout of `count` storage buffers (bindings 0..count) for push descriptors,
/// and a pipeline layout with `push_size` bytes of push constants.
fn layouts(
    ctx: &Context,
    count: u32,
    push_size: u32,
    stages: vk::ShaderStageFlags,
    name: &str,
) -> Result<(vk::DescriptorSetLayout, vk::PipelineLayout)> {
    let bindings: Vec<_> = (0..count)
        .map(|i| {
            vk::DescriptorSetLayoutBinding::default()
                .binding(i)
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
    let layout = unsafe { ctx.device.create_pipeline_layout(&pl, None) }
        .ctx(&format!("{name} pipeline layout"))?;
    ctx.set_name(layout, &format!("{name} pipeline layout"));
    Ok((set_layout, layout))
}

fn push_buffers(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    bind: vk::PipelineBindPoint,
    layout: vk::PipelineLayout,
    infos: &[vk::DescriptorBufferInfo],
) {
    let writes: Vec<_> = infos
        .iter()
        .enumerate()
        .map(|(i, info)| {
            vk::WriteDescriptorSet::default()
                .dst_binding(i as u32)
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
    pub buffers: u32,
    pub push_size: u32,
}

impl<'a> ComputeDesc<'a> {
    /// A pipeline with no specialization constants but the workgroup size.
    pub fn plain(
        name: &'a str,
        shader: &'a str,
        defines: &'a [(&'a str, String)],
        local_size: u32,
        buffers: u32,
        push_size: u32,
    ) -> Self {
        Self {
            name,
            shader,
            defines,
            local_size,
            spec: &[],
            buffers,
            push_size,
        }
    }
}

pub struct ComputePipeline {
    pub pipeline: vk::Pipeline,
    pub layout: vk::PipelineLayout,
    pub set_layout: vk::DescriptorSetLayout,
    pub local_size: u32,
    pub buffers: u32,
    pub name: String,
}

impl ComputePipeline {
    pub fn new(ctx: &Context, d: &ComputeDesc) -> Result<Self> {
        if d.local_size == 0 || d.local_size > ctx.limits.max_compute_work_group_invocations {
            return Err(Error::Param(format!(
                "{}: workgroup size {} is outside 1..={}",
                d.name, d.local_size, ctx.limits.max_compute_work_group_invocations
            )));
        }
        let spv = ctx.shaders.compile(d.shader, d.defines)?;
        let module = shader_module(ctx, &spv, d.shader)?;
        let (set_layout, layout) = layouts(
            ctx,
            d.buffers,
            d.push_size,
            vk::ShaderStageFlags::COMPUTE,
            d.name,
        )?;
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
                .create_compute_pipelines(vk::PipelineCache::null(), &[info], None)
        };
        unsafe { ctx.device.destroy_shader_module(module, None) };
        let pipeline = r.map_err(|(_, e)| e).ctx(&format!("{} pipeline", d.name))?[0];
        ctx.set_name(pipeline, d.name);
        Ok(Self {
            pipeline,
            layout,
            set_layout,
            local_size: d.local_size,
            buffers: d.buffers,
            name: d.name.to_string(),
        })
    }

    /// Bind, push descriptors and constants, dispatch `groups` workgroups (split over y when
    /// more than 65535; shaders linearise with `global_id()` from common/index.glsl).
    pub fn dispatch_groups<P: bytemuck::Pod>(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        infos: &[vk::DescriptorBufferInfo],
        push: &P,
        groups: u64,
    ) {
        debug_assert_eq!(
            infos.len() as u32,
            self.buffers,
            "{}: buffer count",
            self.name
        );
        if groups == 0 {
            return;
        }
        let gx = groups.min(MAX_GROUPS_X as u64) as u32;
        let gy = groups.div_ceil(gx as u64) as u32;
        unsafe {
            ctx.device
                .cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
            push_buffers(ctx, cmd, vk::PipelineBindPoint::COMPUTE, self.layout, infos);
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
            ctx.device.cmd_dispatch(cmd, gx, gy, 1);
        }
    }

    /// Dispatch one invocation per element (bounds-checked in the shader).
    pub fn dispatch<P: bytemuck::Pod>(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        buffers: &[&super::Buffer],
        push: &P,
        elements: u64,
    ) {
        let infos: Vec<_> = buffers.iter().map(|b| b.info()).collect();
        self.dispatch_groups(
            ctx,
            cmd,
            &infos,
            push,
            elements.div_ceil(self.local_size as u64),
        );
    }

    pub fn destroy(&mut self, ctx: &Context) {
        unsafe {
            ctx.device.destroy_pipeline(self.pipeline, None);
            ctx.device.destroy_pipeline_layout(self.layout, None);
            ctx.device
                .destroy_descriptor_set_layout(self.set_layout, None);
        }
        self.pipeline = vk::Pipeline::null();
    }
}

/// A graphics pipeline for dynamic rendering with storage buffers read by its shaders.
pub struct GraphicsDesc<'a> {
    pub name: &'a str,
    pub vertex: &'a str,
    pub fragment: &'a str,
    pub defines: &'a [(&'a str, String)],
    pub buffers: u32,
    pub push_size: u32,
    /// None: no colour attachment (passes that only write storage buffers).
    pub color_format: Option<vk::Format>,
    pub depth_format: Option<vk::Format>,
    pub blend: bool,
    pub topology: vk::PrimitiveTopology,
}

pub struct GraphicsPipeline {
    pub pipeline: vk::Pipeline,
    pub layout: vk::PipelineLayout,
    pub set_layout: vk::DescriptorSetLayout,
    pub name: String,
}

impl GraphicsPipeline {
    pub fn new(ctx: &Context, d: &GraphicsDesc) -> Result<Self> {
        let vs = ctx.shaders.compile(d.vertex, d.defines)?;
        let fs = ctx.shaders.compile(d.fragment, d.defines)?;
        let vsm = shader_module(ctx, &vs, d.vertex)?;
        let fsm = shader_module(ctx, &fs, d.fragment)?;
        let stages_flags = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
        let (set_layout, layout) = layouts(ctx, d.buffers, d.push_size, stages_flags, d.name)?;
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vsm)
                .name(c"main"),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(fsm)
                .name(c"main"),
        ];
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default();
        let ia = vk::PipelineInputAssemblyStateCreateInfo::default().topology(d.topology);
        let viewport = vk::PipelineViewportStateCreateInfo::default()
            .viewport_count(1)
            .scissor_count(1);
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(vk::CullModeFlags::NONE)
            .line_width(1.0);
        let ms = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(d.depth_format.is_some())
            .depth_write_enable(d.depth_format.is_some())
            .depth_compare_op(vk::CompareOp::LESS);
        let attachment = [vk::PipelineColorBlendAttachmentState::default()
            .blend_enable(d.blend)
            .src_color_blend_factor(vk::BlendFactor::SRC_ALPHA)
            .dst_color_blend_factor(vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
            .color_blend_op(vk::BlendOp::ADD)
            .src_alpha_blend_factor(vk::BlendFactor::ONE)
            .dst_alpha_blend_factor(vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
            .alpha_blend_op(vk::BlendOp::ADD)
            .color_write_mask(vk::ColorComponentFlags::RGBA)];
        let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(
            if d.color_format.is_some() {
                &attachment[..]
            } else {
                &[]
            },
        );
        let dyn_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dyn_states);
        let formats: Vec<vk::Format> = d.color_format.into_iter().collect();
        let mut rendering =
            vk::PipelineRenderingCreateInfo::default().color_attachment_formats(&formats);
        if let Some(df) = d.depth_format {
            rendering = rendering.depth_attachment_format(df);
        }
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&ia)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&ms)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(layout)
            .push_next(&mut rendering);
        let r = unsafe {
            ctx.device
                .create_graphics_pipelines(vk::PipelineCache::null(), &[info], None)
        };
        unsafe {
            ctx.device.destroy_shader_module(vsm, None);
            ctx.device.destroy_shader_module(fsm, None);
        }
        let pipeline = r.map_err(|(_, e)| e).ctx(&format!("{} pipeline", d.name))?[0];
        ctx.set_name(pipeline, d.name);
        Ok(Self {
            pipeline,
            layout,
            set_layout,
            name: d.name.to_string(),
        })
    }

    /// Bind the pipeline, its buffers and push constants (inside a rendering scope).
    pub fn bind<P: bytemuck::Pod>(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        buffers: &[&super::Buffer],
        push: &P,
    ) {
        let infos: Vec<_> = buffers.iter().map(|b| b.info()).collect();
        unsafe {
            ctx.device
                .cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
            push_buffers(
                ctx,
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.layout,
                &infos,
            );
            let bytes = bytemuck::bytes_of(push);
            if !bytes.is_empty() {
                ctx.device.cmd_push_constants(
                    cmd,
                    self.layout,
                    vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                    0,
                    bytes,
                );
            }
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        unsafe {
            ctx.device.destroy_pipeline(self.pipeline, None);
            ctx.device.destroy_pipeline_layout(self.layout, None);
            ctx.device
                .destroy_descriptor_set_layout(self.set_layout, None);
        }
        self.pipeline = vk::Pipeline::null();
    }
}

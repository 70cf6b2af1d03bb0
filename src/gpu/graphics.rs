//! Graphics pipelines of a checked interface for dynamic rendering, their storage
//! buffers bound with push descriptors (the compute side is pipeline.rs).
use super::access::{buffer_uses, Use};
use super::interface::Interface;
use super::pipeline::{
    all_defines, as_refs, bound_uses, checked_stages, destroy_layouts, keep, layouts, push_buffers,
    release, shader_module,
};
use super::pipelines::{Built, PipelineKey};
use super::track::BufferUse;
use super::Context;
use crate::error::Result;
use ash::vk;
use std::collections::BTreeMap;
use std::marker::PhantomData;

/// A graphics pipeline for dynamic rendering with storage buffers read by its shaders.
pub struct GraphicsDesc<'a> {
    pub name: &'a str,
    pub vertex: &'a str,
    pub fragment: &'a str,
    pub defines: &'a [(&'a str, String)],
    /// None: no colour attachment (passes that only write storage buffers).
    pub color_format: Option<vk::Format>,
    pub depth_format: Option<vk::Format>,
    /// Alpha blending (src alpha, one minus src alpha): drawn back to front, so depth is
    /// tested but not written.
    pub blend: bool,
    pub topology: vk::PrimitiveTopology,
}

/// A graphics pipeline of interface `I` (both stages checked against it).
pub struct GraphicsPipeline<I: Interface> {
    pub pipeline: vk::Pipeline,
    pub layout: vk::PipelineLayout,
    pub set_layout: vk::DescriptorSetLayout,
    pub name: String,
    /// What each stage does with each binding (from the SPIR-V), for the barrier tracker.
    uses: Vec<(vk::PipelineStageFlags2, BTreeMap<u32, Use>)>,
    interface: PhantomData<I>,
}

/// The graphics pipeline of `d`'s states (dynamic rendering, dynamic viewport and
/// scissor) over the two shader modules.
fn fixed_function(
    ctx: &Context,
    d: &GraphicsDesc,
    (vsm, fsm): (vk::ShaderModule, vk::ShaderModule),
    layout: vk::PipelineLayout,
) -> std::result::Result<Vec<vk::Pipeline>, (Vec<vk::Pipeline>, vk::Result)> {
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
        .depth_write_enable(d.depth_format.is_some() && !d.blend)
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
    let blend =
        vk::PipelineColorBlendStateCreateInfo::default().attachments(if d.color_format.is_some() {
            &attachment[..]
        } else {
            &[]
        });
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
    unsafe {
        ctx.device
            .create_graphics_pipelines(ctx.pipeline_cache, &[info], None)
    }
}

impl<I: Interface> GraphicsPipeline<I> {
    pub fn new(ctx: &Context, d: &GraphicsDesc) -> Result<Self> {
        let defines = all_defines::<I>(d.defines);
        let raw = |f: Option<vk::Format>| f.map_or(-1, |f| f.as_raw() as i64);
        let fixed = vec![
            raw(d.color_format),
            raw(d.depth_format),
            d.blend as i64,
            d.topology.as_raw() as i64,
        ];
        let shaders = [d.vertex, d.fragment];
        let key = PipelineKey::new(std::any::type_name::<I>(), &shaders, &defines, fixed);
        let b = match ctx.pipelines.acquire(&key) {
            Some(b) => b,
            None => Self::build(ctx, d, &defines, key)?,
        };
        Ok(Self {
            pipeline: b.pipeline,
            layout: b.layout,
            set_layout: b.set_layout,
            name: d.name.to_string(),
            uses: b.uses,
            interface: PhantomData,
        })
    }

    /// A new pipeline of `d`, kept under `key`.
    fn build(
        ctx: &Context,
        d: &GraphicsDesc,
        defines: &[(String, String)],
        key: PipelineKey,
    ) -> Result<Built> {
        let shaders = [d.vertex, d.fragment];
        let spv = checked_stages::<I>(ctx, d.name, &shaders, &as_refs(defines))?;
        let stages_flags = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
        let push_size = std::mem::size_of::<I::Push>() as u32;
        let (set_layout, layout) = layouts(ctx, I::BINDINGS, push_size, stages_flags, d.name)?;
        let modules = shader_module(ctx, &spv[0], d.vertex).and_then(|v| {
            shader_module(ctx, &spv[1], d.fragment)
                .inspect_err(|_| unsafe { ctx.device.destroy_shader_module(v, None) })
                .map(|f| (v, f))
        });
        let (vsm, fsm) = match modules {
            Ok(m) => m,
            Err(e) => {
                destroy_layouts(ctx, layout, set_layout);
                return Err(e);
            }
        };
        let r = fixed_function(ctx, d, (vsm, fsm), layout);
        unsafe {
            ctx.device.destroy_shader_module(vsm, None);
            ctx.device.destroy_shader_module(fsm, None);
        }
        let uses = vec![
            (vk::PipelineStageFlags2::VERTEX_SHADER, buffer_uses(&spv[0])),
            (
                vk::PipelineStageFlags2::FRAGMENT_SHADER,
                buffer_uses(&spv[1]),
            ),
        ];
        keep(ctx, key, d.name, r, (layout, set_layout), uses)
    }

    /// Declare that the next rendering scope draws this pipeline with `bufs` (call before
    /// it begins): the tracker places the barriers the draws need now.
    pub fn prepare(&self, ctx: &Context, cmd: vk::CommandBuffer, bufs: &I::Bufs<'_>) {
        ctx.prepare_draws(cmd, &self.draw_uses(bufs));
    }

    fn draw_uses(&self, bufs: &I::Bufs<'_>) -> Vec<BufferUse> {
        let buffers = I::buffers(bufs);
        self.uses
            .iter()
            .flat_map(|(stage, map)| bound_uses(&buffers, map, *stage))
            .collect()
    }

    /// Bind the pipeline, its buffers and push constants (inside a rendering scope: uses
    /// not declared by `prepare` are counted as hazards where no barrier can be placed).
    pub fn bind(&self, ctx: &Context, cmd: vk::CommandBuffer, bufs: &I::Bufs<'_>, push: &I::Push) {
        ctx.track(cmd, &self.draw_uses(bufs), false);
        unsafe {
            ctx.device
                .cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
            push_buffers(
                ctx,
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.layout,
                &I::buffers(bufs),
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

    /// Give up this holder's share: the last holder destroys the pipeline and layouts.
    pub fn destroy(&mut self, ctx: &Context) {
        release(ctx, self.pipeline, self.layout, self.set_layout);
        self.pipeline = vk::Pipeline::null();
        self.layout = vk::PipelineLayout::null();
        self.set_layout = vk::DescriptorSetLayout::null();
    }
}

impl<I: Interface> super::Destroy for GraphicsPipeline<I> {
    fn destroy(&mut self, ctx: &Context) {
        GraphicsPipeline::destroy(self, ctx)
    }
}

//! Headless render target: colour + depth images, a readback buffer per frame slot, PNG out.
use super::memory::{subresource, Buffer, Image, MemoryLocation};
use super::{Context, Guard};
use crate::error::{Error, Result};
use ash::vk;
use std::path::Path;

pub const COLOR_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

pub struct ColorTarget {
    pub color: Image,
    pub depth: Image,
    readbacks: Vec<Buffer>,
}

fn image_barrier(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    image: vk::Image,
    aspect: vk::ImageAspectFlags,
    (src_stage, src_access, old): (vk::PipelineStageFlags2, vk::AccessFlags2, vk::ImageLayout),
    (dst_stage, dst_access, new): (vk::PipelineStageFlags2, vk::AccessFlags2, vk::ImageLayout),
) {
    let b = [vk::ImageMemoryBarrier2::default()
        .src_stage_mask(src_stage)
        .src_access_mask(src_access)
        .dst_stage_mask(dst_stage)
        .dst_access_mask(dst_access)
        .old_layout(old)
        .new_layout(new)
        .image(image)
        .subresource_range(subresource(aspect))];
    let dep = vk::DependencyInfo::default().image_memory_barriers(&b);
    unsafe { ctx.device.cmd_pipeline_barrier2(cmd, &dep) };
}

impl ColorTarget {
    pub fn new(ctx: &Context, width: u32, height: u32, slots: usize) -> Result<Self> {
        let color = Guard::new(
            ctx,
            ctx.create_image(
                "color target",
                width,
                height,
                COLOR_FORMAT,
                vk::ImageUsageFlags::COLOR_ATTACHMENT
                    | vk::ImageUsageFlags::TRANSFER_SRC
                    | vk::ImageUsageFlags::TRANSFER_DST
                    | vk::ImageUsageFlags::STORAGE,
            )?,
        );
        let depth = Guard::new(
            ctx,
            ctx.create_image(
                "depth target",
                width,
                height,
                DEPTH_FORMAT,
                vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
                    | vk::ImageUsageFlags::TRANSFER_SRC
                    | vk::ImageUsageFlags::TRANSFER_DST,
            )?,
        );
        let mut readbacks = Guard::new(ctx, Vec::new());
        for _ in 0..slots {
            readbacks.push(ctx.create_buffer(
                "frame readback",
                width as u64 * height as u64 * 4,
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )?);
        }
        Ok(Self {
            color: color.take(),
            depth: depth.take(),
            readbacks: readbacks.take(),
        })
    }

    pub fn width(&self) -> u32 {
        self.color.width
    }

    pub fn height(&self) -> u32 {
        self.color.height
    }

    /// Begin dynamic rendering, clearing colour to `clear` and depth to 1.
    pub fn begin_rendering(&self, ctx: &Context, cmd: vk::CommandBuffer, clear: [f32; 4]) {
        self.begin_with(ctx, cmd, Some(clear));
    }

    /// Begin dynamic rendering over the colour and depth `load_layers` just copied in.
    pub fn begin_rendering_loaded(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        self.begin_with(ctx, cmd, None);
    }

    fn begin_with(&self, ctx: &Context, cmd: vk::CommandBuffer, clear: Option<[f32; 4]>) {
        use vk::{AccessFlags2 as A, ImageLayout as L, PipelineStageFlags2 as S};
        // Cleared: the previous frame's copy-out read the image; wait for it before
        // overwriting. Loaded: the copies in wrote both images.
        let (color_src, depth_src, load) = match clear {
            Some(_) => (
                (
                    S::ALL_COMMANDS,
                    A::MEMORY_READ | A::MEMORY_WRITE,
                    L::UNDEFINED,
                ),
                (
                    S::LATE_FRAGMENT_TESTS | S::COPY,
                    A::DEPTH_STENCIL_ATTACHMENT_WRITE,
                    L::UNDEFINED,
                ),
                vk::AttachmentLoadOp::CLEAR,
            ),
            None => (
                (S::COPY, A::TRANSFER_WRITE, L::TRANSFER_DST_OPTIMAL),
                (S::COPY, A::TRANSFER_WRITE, L::TRANSFER_DST_OPTIMAL),
                vk::AttachmentLoadOp::LOAD,
            ),
        };
        image_barrier(
            ctx,
            cmd,
            self.color.raw,
            vk::ImageAspectFlags::COLOR,
            color_src,
            (
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_WRITE | A::COLOR_ATTACHMENT_READ,
                L::COLOR_ATTACHMENT_OPTIMAL,
            ),
        );
        image_barrier(
            ctx,
            cmd,
            self.depth.raw,
            vk::ImageAspectFlags::DEPTH,
            depth_src,
            (
                S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS,
                A::DEPTH_STENCIL_ATTACHMENT_WRITE | A::DEPTH_STENCIL_ATTACHMENT_READ,
                L::DEPTH_ATTACHMENT_OPTIMAL,
            ),
        );
        let clear = clear.unwrap_or([0.0; 4]);
        let color = [vk::RenderingAttachmentInfo::default()
            .image_view(self.color.view)
            .image_layout(L::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(load)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue {
                color: vk::ClearColorValue { float32: clear },
            })];
        let depth = vk::RenderingAttachmentInfo::default()
            .image_view(self.depth.view)
            .image_layout(L::DEPTH_ATTACHMENT_OPTIMAL)
            .load_op(load)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue {
                depth_stencil: vk::ClearDepthStencilValue {
                    depth: 1.0,
                    stencil: 0,
                },
            });
        let info = vk::RenderingInfo::default()
            .layer_count(1)
            .color_attachments(&color)
            .depth_attachment(&depth);
        begin(ctx, cmd, info, self.width(), self.height());
    }

    pub fn end_rendering(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        ctx.end_rendering(cmd);
    }

    /// The colour image into `dst` at byte `offset`, after rendering (the caller makes
    /// the copy visible).
    pub fn copy_color(&self, ctx: &Context, cmd: vk::CommandBuffer, dst: &Buffer, offset: u64) {
        use vk::{AccessFlags2 as A, ImageLayout as L, PipelineStageFlags2 as S};
        image_barrier(
            ctx,
            cmd,
            self.color.raw,
            vk::ImageAspectFlags::COLOR,
            (
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_WRITE,
                L::COLOR_ATTACHMENT_OPTIMAL,
            ),
            (S::COPY, A::TRANSFER_READ, L::TRANSFER_SRC_OPTIMAL),
        );
        let region = self.region(vk::ImageAspectFlags::COLOR, offset);
        track_copy(ctx, cmd, dst, &region, true);
        unsafe {
            ctx.device.cmd_copy_image_to_buffer(
                cmd,
                self.color.raw,
                L::TRANSFER_SRC_OPTIMAL,
                dst.raw,
                &[region],
            )
        };
    }

    /// Copy the colour image into this slot's readback buffer (after rendering).
    pub fn copy_out(&self, ctx: &Context, cmd: vk::CommandBuffer, slot: usize) {
        use vk::{AccessFlags2 as A, PipelineStageFlags2 as S};
        self.copy_color(ctx, cmd, &self.readbacks[slot], 0);
        let b = [vk::MemoryBarrier2::default()
            .src_stage_mask(S::COPY)
            .src_access_mask(A::TRANSFER_WRITE)
            .dst_stage_mask(S::HOST)
            .dst_access_mask(A::HOST_READ)];
        let dep = vk::DependencyInfo::default().memory_barriers(&b);
        unsafe { ctx.device.cmd_pipeline_barrier2(cmd, &dep) };
    }

    /// The whole image's `aspect`, tightly packed at byte `offset` of a buffer.
    fn region(&self, aspect: vk::ImageAspectFlags, offset: u64) -> vk::BufferImageCopy {
        vk::BufferImageCopy {
            buffer_offset: offset,
            buffer_row_length: 0,
            buffer_image_height: 0,
            image_subresource: vk::ImageSubresourceLayers {
                aspect_mask: aspect,
                mip_level: 0,
                base_array_layer: 0,
                layer_count: 1,
            },
            image_offset: vk::Offset3D::default(),
            image_extent: vk::Extent3D {
                width: self.width(),
                height: self.height(),
                depth: 1,
            },
        }
    }

    /// Copy the colour (RGBA8) to `dst` at byte `color_at` and the depth (f32) at
    /// `depth_at`, tightly packed rows, after rendering; the caller makes the copy visible.
    pub fn copy_layers(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        dst: &super::Buffer,
        color_at: u64,
        depth_at: u64,
    ) {
        use vk::{AccessFlags2 as A, ImageLayout as L, PipelineStageFlags2 as S};
        self.copy_color(ctx, cmd, dst, color_at);
        image_barrier(
            ctx,
            cmd,
            self.depth.raw,
            vk::ImageAspectFlags::DEPTH,
            (
                S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS,
                A::DEPTH_STENCIL_ATTACHMENT_WRITE,
                L::DEPTH_ATTACHMENT_OPTIMAL,
            ),
            (S::COPY, A::TRANSFER_READ, L::TRANSFER_SRC_OPTIMAL),
        );
        let region = self.region(vk::ImageAspectFlags::DEPTH, depth_at);
        track_copy(ctx, cmd, dst, &region, true);
        unsafe {
            ctx.device.cmd_copy_image_to_buffer(
                cmd,
                self.depth.raw,
                L::TRANSFER_SRC_OPTIMAL,
                dst.raw,
                &[region],
            );
        }
    }

    /// The reverse of `copy_layers`: colour (RGBA8) and depth (f32, 0..1) from
    /// (buffer, byte offset), tightly packed rows, whose writes the caller made visible to
    /// copies; then `begin_rendering_loaded`. Waits for the images' previous uses.
    pub fn load_layers(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        color: (&super::Buffer, u64),
        depth: (&super::Buffer, u64),
    ) {
        use vk::{AccessFlags2 as A, ImageLayout as L, PipelineStageFlags2 as S};
        for (image, aspect, (src, at)) in [
            (&self.color, vk::ImageAspectFlags::COLOR, color),
            (&self.depth, vk::ImageAspectFlags::DEPTH, depth),
        ] {
            image_barrier(
                ctx,
                cmd,
                image.raw,
                aspect,
                (
                    S::ALL_COMMANDS,
                    A::MEMORY_READ | A::MEMORY_WRITE,
                    L::UNDEFINED,
                ),
                (S::COPY, A::TRANSFER_WRITE, L::TRANSFER_DST_OPTIMAL),
            );
            let region = self.region(aspect, at);
            track_copy(ctx, cmd, src, &region, false);
            unsafe {
                ctx.device.cmd_copy_buffer_to_image(
                    cmd,
                    src.raw,
                    image.raw,
                    L::TRANSFER_DST_OPTIMAL,
                    &[region],
                )
            };
        }
    }

    /// RGBA8 pixels of the frame last copied out of `slot` (valid after its fence).
    pub fn pixels(&self, slot: usize) -> &[u8] {
        self.readbacks[slot].mapped().expect("readback is mapped")
    }

    pub fn save_png(&self, slot: usize, path: &Path) -> Result<()> {
        save_rgba(path, self.width(), self.height(), self.pixels(slot))
    }

    pub fn destroy(&mut self, ctx: &Context) {
        ctx.destroy_image(&mut self.color);
        ctx.destroy_image(&mut self.depth);
        for b in &mut self.readbacks {
            ctx.destroy_buffer(b);
        }
    }
}

/// Begin dynamic rendering with no attachments over width x height (fragment passes that
/// only write storage buffers), with the viewport and scissor set.
pub fn begin_empty_rendering(ctx: &Context, cmd: vk::CommandBuffer, width: u32, height: u32) {
    begin(
        ctx,
        cmd,
        vk::RenderingInfo::default().layer_count(1),
        width,
        height,
    );
}

/// Begin rendering over the whole width x height area and set viewport and scissor to it.
fn begin(ctx: &Context, cmd: vk::CommandBuffer, info: vk::RenderingInfo, width: u32, height: u32) {
    let area = vk::Rect2D {
        offset: vk::Offset2D { x: 0, y: 0 },
        extent: vk::Extent2D { width, height },
    };
    let viewport = vk::Viewport {
        x: 0.0,
        y: 0.0,
        width: width as f32,
        height: height as f32,
        min_depth: 0.0,
        max_depth: 1.0,
    };
    unsafe {
        ctx.device.cmd_begin_rendering(cmd, &info.render_area(area));
        ctx.device.cmd_set_viewport(cmd, 0, &[viewport]);
        ctx.device.cmd_set_scissor(cmd, 0, &[area]);
    }
}

/// Write RGBA8 pixels as a PNG.
pub fn save_rgba(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<()> {
    let img =
        image::RgbaImage::from_raw(width, height, rgba.to_vec()).ok_or_else(|| Error::Image {
            path: path.display().to_string(),
            message: "pixel count does not match the size".into(),
        })?;
    img.save(path).map_err(|e| Error::Image {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}
crate::impl_destroy!(ColorTarget);

/// The buffer side of an image copy (4 bytes a texel, tightly packed) for the barrier
/// tracker: written by a copy out of the image, read by a copy into it.
fn track_copy(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    b: &super::Buffer,
    region: &vk::BufferImageCopy,
    write: bool,
) {
    let e = region.image_extent;
    let bytes = e.width as u64 * e.height as u64 * e.depth.max(1) as u64 * 4;
    let u = super::track::BufferUse::transfer(b.raw, write).bytes(region.buffer_offset, bytes);
    ctx.track(cmd, &[u], true);
}

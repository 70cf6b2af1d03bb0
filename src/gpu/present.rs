//! A window's swapchain. Each window frame copies the run's picture (the RGBA8 readback
//! that `run` writes as PNG, so the window shows exactly those bytes) into the acquired
//! image, lets an overlay draw over it in a dynamic-rendering scope, and presents it.
//! Resizing recreates the swapchain; a minimised window (zero extent) presents nothing.
use super::Context;
use crate::error::{Error, Result, VkContext};
use ash::vk;
use gpu_allocator::MemoryLocation;

/// How frames are handed to the display (`--present`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PresentMode {
    Fifo,
    Mailbox,
    Immediate,
}

impl PresentMode {
    fn vk(self) -> vk::PresentModeKHR {
        match self {
            Self::Fifo => vk::PresentModeKHR::FIFO,
            Self::Mailbox => vk::PresentModeKHR::MAILBOX,
            Self::Immediate => vk::PresentModeKHR::IMMEDIATE,
        }
    }
}

/// Records the overlay inside the presenter's rendering scope of the swapchain image.
pub type OverlayDraw<'a> = &'a mut dyn FnMut(vk::CommandBuffer, vk::Extent2D) -> Result<()>;

struct Slot {
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    /// Signalled by the acquire; waited on by this slot's submit.
    acquired: vk::Semaphore,
    staging: Option<super::Buffer>,
    busy: bool,
}

pub struct Presenter {
    surface_fn: ash::khr::surface::Instance,
    swapchain_fn: ash::khr::swapchain::Device,
    surface: vk::SurfaceKHR,
    swapchain: vk::SwapchainKHR,
    images: Vec<vk::Image>,
    views: Vec<vk::ImageView>,
    /// Per swapchain image: signalled by the submit that drew it, waited on by present.
    done: Vec<vk::Semaphore>,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    mode: vk::PresentModeKHR,
    pool: vk::CommandPool,
    slots: Vec<Slot>,
    next: usize,
    /// The swapchain must be rebuilt before the next frame (resized, out of date).
    stale: bool,
}

const SLOTS: usize = 2;

impl Presenter {
    /// A surface and swapchain for `window`, `size` its inner size in pixels.
    pub fn new(
        ctx: &Context,
        display: raw_window_handle::RawDisplayHandle,
        window: raw_window_handle::RawWindowHandle,
        mode: PresentMode,
        size: (u32, u32),
    ) -> Result<Self> {
        let surface_fn = ash::khr::surface::Instance::new(&ctx.entry, &ctx.instance);
        let surface =
            unsafe { ash_window::create_surface(&ctx.entry, &ctx.instance, display, window, None) }
                .ctx("create window surface")?;
        let mut me = Self {
            swapchain_fn: ash::khr::swapchain::Device::new(&ctx.instance, &ctx.device),
            surface_fn,
            surface,
            swapchain: vk::SwapchainKHR::null(),
            images: Vec::new(),
            views: Vec::new(),
            done: Vec::new(),
            format: vk::Format::UNDEFINED,
            extent: vk::Extent2D::default(),
            mode: mode.vk(),
            pool: vk::CommandPool::null(),
            slots: Vec::new(),
            next: 0,
            stale: true,
        };
        match me.init(ctx, mode, size) {
            Ok(()) => Ok(me),
            Err(e) => {
                me.destroy(ctx);
                Err(e)
            }
        }
    }

    fn init(&mut self, ctx: &Context, mode: PresentMode, size: (u32, u32)) -> Result<()> {
        let (pd, s) = (ctx.physical, self.surface);
        let supported = unsafe {
            self.surface_fn
                .get_physical_device_surface_support(pd, ctx.queue_family, s)
        }
        .ctx("surface support")?;
        if !supported {
            return Err(Error::Unsupported(format!(
                "{} cannot present to this window from its queue",
                ctx.info.name
            )));
        }
        let modes = unsafe {
            self.surface_fn
                .get_physical_device_surface_present_modes(pd, s)
        }
        .ctx("present modes")?;
        if !modes.contains(&self.mode) {
            return Err(Error::Unsupported(format!(
                "--present {mode:?}: {} offers only {modes:?} for this window",
                ctx.info.name
            )));
        }
        let formats = unsafe { self.surface_fn.get_physical_device_surface_formats(pd, s) }
            .ctx("surface formats")?;
        // UNORM: the picture's bytes are already display-encoded (they are the PNG's).
        self.format = [vk::Format::R8G8B8A8_UNORM, vk::Format::B8G8R8A8_UNORM]
            .into_iter()
            .find(|f| formats.iter().any(|sf| sf.format == *f))
            .ok_or_else(|| {
                Error::Unsupported(format!(
                    "no 8-bit UNORM RGBA/BGRA surface format in {formats:?}"
                ))
            })?;
        let info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(ctx.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        self.pool = unsafe { ctx.device.create_command_pool(&info, None) }.ctx("present pool")?;
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(SLOTS as u32);
        let cmds = unsafe { ctx.device.allocate_command_buffers(&alloc) }.ctx("present cmds")?;
        for cmd in cmds {
            let fence = unsafe {
                ctx.device
                    .create_fence(&vk::FenceCreateInfo::default(), None)
            }
            .ctx("present fence")?;
            let acquired = semaphore(ctx);
            self.slots.push(Slot {
                cmd,
                fence,
                acquired: vk::Semaphore::null(),
                staging: None,
                busy: false,
            });
            self.slots.last_mut().unwrap().acquired = acquired?;
            ctx.set_name(cmd, "present");
        }
        self.resize(ctx, size)
    }

    /// The pool the overlay's texture uploads use.
    pub fn command_pool(&self) -> vk::CommandPool {
        self.pool
    }

    /// Rebuild the swapchain for a window of `size` (after a resize or when out of date).
    pub fn resize(&mut self, ctx: &Context, size: (u32, u32)) -> Result<()> {
        ctx.wait_idle()?;
        let caps = unsafe {
            self.surface_fn
                .get_physical_device_surface_capabilities(ctx.physical, self.surface)
        }
        .ctx("surface capabilities")?;
        let extent = match caps.current_extent.width {
            u32::MAX => vk::Extent2D {
                width: size
                    .0
                    .clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: size
                    .1
                    .clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            },
            _ => caps.current_extent,
        };
        self.drop_swapchain(ctx, false);
        self.extent = extent;
        if extent.width == 0 || extent.height == 0 {
            // Minimised: nothing to present until the window has an area again.
            self.stale = true;
            return Ok(());
        }
        let count = match caps.max_image_count {
            0 => caps.min_image_count + 1,
            m => (caps.min_image_count + 1).min(m),
        };
        let old = self.swapchain;
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(self.surface)
            .min_image_count(count)
            .image_format(self.format)
            .image_color_space(vk::ColorSpaceKHR::SRGB_NONLINEAR)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(vk::ImageUsageFlags::TRANSFER_DST | vk::ImageUsageFlags::COLOR_ATTACHMENT)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(vk::CompositeAlphaFlagsKHR::OPAQUE)
            .present_mode(self.mode)
            .clipped(true)
            .old_swapchain(old);
        let made = unsafe { self.swapchain_fn.create_swapchain(&info, None) };
        if old != vk::SwapchainKHR::null() {
            unsafe { self.swapchain_fn.destroy_swapchain(old, None) };
            self.swapchain = vk::SwapchainKHR::null();
        }
        self.swapchain = made.ctx("create swapchain")?;
        self.images = unsafe { self.swapchain_fn.get_swapchain_images(self.swapchain) }
            .ctx("swapchain images")?;
        for (i, &image) in self.images.iter().enumerate() {
            ctx.set_name(image, &format!("swapchain image {i}"));
            let view = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(self.format)
                .subresource_range(super::memory::subresource(vk::ImageAspectFlags::COLOR));
            self.views
                .push(unsafe { ctx.device.create_image_view(&view, None) }.ctx("swapchain view")?);
            self.done.push(semaphore(ctx)?);
        }
        self.stale = false;
        Ok(())
    }

    /// Whether the swapchain must be rebuilt (call `resize`) before frames show.
    pub fn stale(&self) -> bool {
        self.stale
    }

    /// Show `picture` (RGBA8, width, height; the top-left corner of the window, the rest
    /// cleared) with `overlay` over it. False when nothing was shown (minimised or out of
    /// date: call `resize`).
    pub fn present(
        &mut self,
        ctx: &Context,
        picture: Option<(&[u8], u32, u32)>,
        overlay: OverlayDraw,
    ) -> Result<bool> {
        if self.stale {
            return Ok(false);
        }
        let k = self.next;
        if self.slots[k].busy {
            ctx.wait(self.slots[k].fence)?;
            unsafe { ctx.device.reset_fences(&[self.slots[k].fence]) }.ctx("reset fence")?;
            self.slots[k].busy = false;
        }
        let acquired = unsafe {
            self.swapchain_fn.acquire_next_image(
                self.swapchain,
                u64::MAX,
                self.slots[k].acquired,
                vk::Fence::null(),
            )
        };
        let index = match acquired {
            Ok((i, _)) => i,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => {
                self.stale = true;
                return Ok(false);
            }
            Err(e) => return Err(e).ctx("acquire swapchain image"),
        };
        let copy = match picture {
            Some(p) => Some((self.stage(ctx, k, p)?, p.1)),
            None => None,
        };
        self.record(ctx, k, index as usize, copy, overlay)?;
        let cmd = self.slots[k].cmd;
        let waits = [vk::SemaphoreSubmitInfo::default()
            .semaphore(self.slots[k].acquired)
            .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)];
        let signals = [vk::SemaphoreSubmitInfo::default()
            .semaphore(self.done[index as usize])
            .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)];
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        let submit = vk::SubmitInfo2::default()
            .wait_semaphore_infos(&waits)
            .command_buffer_infos(&cmds)
            .signal_semaphore_infos(&signals);
        unsafe {
            ctx.device
                .queue_submit2(ctx.queue, &[submit], self.slots[k].fence)
        }
        .ctx("submit present")?;
        self.slots[k].busy = true;
        self.next = (k + 1) % SLOTS;
        let (sems, chains, indices) = ([self.done[index as usize]], [self.swapchain], [index]);
        let info = vk::PresentInfoKHR::default()
            .wait_semaphores(&sems)
            .swapchains(&chains)
            .image_indices(&indices);
        match unsafe { self.swapchain_fn.queue_present(ctx.queue, &info) } {
            Ok(false) => Ok(true),
            Ok(true) | Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => {
                self.stale = true;
                Ok(true)
            }
            Err(e) => Err(e).ctx("present"),
        }
    }

    /// The picture in slot `k`'s staging buffer, as the swapchain's byte order; the copy
    /// region (the part of the picture inside the window).
    fn stage(
        &mut self,
        ctx: &Context,
        k: usize,
        (rgba, w, h): (&[u8], u32, u32),
    ) -> Result<vk::Extent2D> {
        let bytes = w as u64 * h as u64 * 4;
        let slot = &mut self.slots[k];
        if slot.staging.as_ref().is_none_or(|b| b.size != bytes) {
            if let Some(mut b) = slot.staging.take() {
                ctx.destroy_buffer(&mut b);
            }
            slot.staging = Some(ctx.create_buffer(
                "window picture",
                bytes,
                vk::BufferUsageFlags::TRANSFER_SRC,
                MemoryLocation::CpuToGpu,
            )?);
        }
        let dst = slot
            .staging
            .as_mut()
            .and_then(|b| b.mapped_mut())
            .ok_or_else(|| Error::Memory("the window's picture buffer is not mapped".into()))?;
        let dst = &mut dst[..bytes as usize];
        match self.format {
            vk::Format::B8G8R8A8_UNORM => {
                for (d, s) in dst.chunks_exact_mut(4).zip(rgba.chunks_exact(4)) {
                    d.copy_from_slice(&[s[2], s[1], s[0], s[3]]);
                }
            }
            _ => dst.copy_from_slice(&rgba[..bytes as usize]),
        }
        Ok(vk::Extent2D {
            width: w.min(self.extent.width),
            height: h.min(self.extent.height),
        })
    }

    fn record(
        &self,
        ctx: &Context,
        k: usize,
        index: usize,
        copy: Option<(vk::Extent2D, u32)>,
        overlay: OverlayDraw,
    ) -> Result<()> {
        let d = &ctx.device;
        let cmd = self.slots[k].cmd;
        let image = self.images[index];
        unsafe {
            d.reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty())
                .ctx("reset present")?;
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            d.begin_command_buffer(cmd, &begin).ctx("begin present")?;
            use vk::{AccessFlags2 as A, ImageLayout as L, PipelineStageFlags2 as S};
            let transfer = (S::ALL_TRANSFER, A::TRANSFER_WRITE);
            let attachment = (
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_READ | A::COLOR_ATTACHMENT_WRITE,
            );
            // The acquire's wait covers every stage, so the first barrier starts there.
            layout(
                d,
                cmd,
                image,
                (S::ALL_COMMANDS, A::NONE),
                transfer,
                L::UNDEFINED,
                L::TRANSFER_DST_OPTIMAL,
            );
            let range = [super::memory::subresource(vk::ImageAspectFlags::COLOR)];
            let clear = vk::ClearColorValue {
                float32: [0.02, 0.02, 0.04, 1.0],
            };
            d.cmd_clear_color_image(cmd, image, L::TRANSFER_DST_OPTIMAL, &clear, &range);
            if let (Some((region, row)), Some(buf)) = (copy, self.slots[k].staging.as_ref()) {
                layout(
                    d,
                    cmd,
                    image,
                    transfer,
                    transfer,
                    L::TRANSFER_DST_OPTIMAL,
                    L::TRANSFER_DST_OPTIMAL,
                );
                // Rows of the picture's own width; only the part inside the window.
                let copy = vk::BufferImageCopy::default()
                    .buffer_row_length(row)
                    .image_subresource(vk::ImageSubresourceLayers {
                        aspect_mask: vk::ImageAspectFlags::COLOR,
                        mip_level: 0,
                        base_array_layer: 0,
                        layer_count: 1,
                    })
                    .image_extent(vk::Extent3D {
                        width: region.width,
                        height: region.height,
                        depth: 1,
                    });
                d.cmd_copy_buffer_to_image(cmd, buf.raw, image, L::TRANSFER_DST_OPTIMAL, &[copy]);
            }
            layout(
                d,
                cmd,
                image,
                transfer,
                attachment,
                L::TRANSFER_DST_OPTIMAL,
                L::COLOR_ATTACHMENT_OPTIMAL,
            );
            let color = [vk::RenderingAttachmentInfo::default()
                .image_view(self.views[index])
                .image_layout(L::COLOR_ATTACHMENT_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::LOAD)
                .store_op(vk::AttachmentStoreOp::STORE)];
            let info = vk::RenderingInfo::default()
                .render_area(vk::Rect2D {
                    offset: vk::Offset2D::default(),
                    extent: self.extent,
                })
                .layer_count(1)
                .color_attachments(&color);
            d.cmd_begin_rendering(cmd, &info);
            let drawn = overlay(cmd, self.extent);
            d.cmd_end_rendering(cmd);
            layout(
                d,
                cmd,
                image,
                attachment,
                (S::NONE, A::NONE),
                L::COLOR_ATTACHMENT_OPTIMAL,
                L::PRESENT_SRC_KHR,
            );
            d.end_command_buffer(cmd).ctx("end present")?;
            drawn
        }
    }

    fn drop_swapchain(&mut self, ctx: &Context, all: bool) {
        unsafe {
            for v in self.views.drain(..) {
                ctx.device.destroy_image_view(v, None);
            }
            for s in self.done.drain(..) {
                ctx.device.destroy_semaphore(s, None);
            }
            self.images.clear();
            if all && self.swapchain != vk::SwapchainKHR::null() {
                self.swapchain_fn.destroy_swapchain(self.swapchain, None);
                self.swapchain = vk::SwapchainKHR::null();
            }
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        let _ = ctx.wait_idle();
        self.drop_swapchain(ctx, true);
        unsafe {
            for mut s in self.slots.drain(..) {
                ctx.device.destroy_fence(s.fence, None);
                ctx.device.destroy_semaphore(s.acquired, None);
                if let Some(b) = &mut s.staging {
                    ctx.destroy_buffer(b);
                }
            }
            if self.pool != vk::CommandPool::null() {
                ctx.device.destroy_command_pool(self.pool, None);
            }
            self.surface_fn.destroy_surface(self.surface, None);
        }
    }
}

fn semaphore(ctx: &Context) -> Result<vk::Semaphore> {
    unsafe {
        ctx.device
            .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
    }
    .ctx("create semaphore")
}

/// A layout transition of a swapchain image, with its (stage, access) before and after.
#[allow(clippy::too_many_arguments)]
unsafe fn layout(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    image: vk::Image,
    src: (vk::PipelineStageFlags2, vk::AccessFlags2),
    dst: (vk::PipelineStageFlags2, vk::AccessFlags2),
    old: vk::ImageLayout,
    new: vk::ImageLayout,
) {
    let b = [vk::ImageMemoryBarrier2::default()
        .src_stage_mask(src.0)
        .src_access_mask(src.1)
        .dst_stage_mask(dst.0)
        .dst_access_mask(dst.1)
        .old_layout(old)
        .new_layout(new)
        .image(image)
        .subresource_range(super::memory::subresource(vk::ImageAspectFlags::COLOR))];
    d.cmd_pipeline_barrier2(
        cmd,
        &vk::DependencyInfo::default().image_memory_barriers(&b),
    );
}

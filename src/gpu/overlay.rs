//! The viewer's overlay renderer: egui's shapes drawn with egui-ash-renderer into the
//! swapchain image, inside the presenter's rendering scope, after the scene's picture. It
//! records Vulkan commands, so it lives in the GPU core with the presenter.
use crate::error::{Error, Result};
use crate::Context;
use ash::vk;
use egui_ash_renderer::{DynamicRendering, Options, Renderer};

pub struct Overlay {
    /// Dropped in `destroy`, before the device (the crate frees its objects on Drop).
    renderer: Option<Renderer>,
    primitives: Vec<egui::ClippedPrimitive>,
    pixels_per_point: f32,
    /// Textures egui let go of, freed once no frame in flight can use them.
    free: Vec<egui::TextureId>,
}

fn err(e: impl std::fmt::Display) -> Error {
    Error::Unsupported(format!("overlay renderer: {e}"))
}

impl Overlay {
    pub fn new(ctx: &Context, format: vk::Format) -> Result<Self> {
        let renderer = Renderer::with_default_allocator(
            &ctx.instance,
            ctx.physical,
            ctx.device.clone(),
            DynamicRendering {
                color_attachment_format: format,
                depth_attachment_format: None,
            },
            Options {
                in_flight_frames: 2,
                // The swapchain is UNORM: the crate writes sRGB-encoded colours.
                srgb_framebuffer: false,
                ..Default::default()
            },
        )
        .map_err(err)?;
        Ok(Self {
            renderer: Some(renderer),
            primitives: Vec::new(),
            pixels_per_point: 1.0,
            free: Vec::new(),
        })
    }

    /// Take egui's output for the next present: texture uploads now, shapes tessellated.
    pub fn prepare(
        &mut self,
        ctx: &Context,
        pool: vk::CommandPool,
        egui_ctx: &egui::Context,
        out: egui::FullOutput,
    ) -> Result<()> {
        let r = self.renderer.as_mut().ok_or_else(|| err("destroyed"))?;
        if !self.free.is_empty() {
            // Rare (egui frees a texture when its font atlas grows): wait, then free.
            ctx.wait_idle()?;
            r.free_textures(&self.free).map_err(err)?;
            self.free.clear();
        }
        r.set_textures(ctx.queue, pool, &out.textures_delta.set)
            .map_err(err)?;
        self.free.extend(out.textures_delta.free);
        self.pixels_per_point = out.pixels_per_point;
        self.primitives = egui_ctx.tessellate(out.shapes, out.pixels_per_point);
        Ok(())
    }

    /// Record the prepared shapes (inside a rendering scope of the swapchain image).
    pub fn draw(&mut self, cmd: vk::CommandBuffer, extent: vk::Extent2D) -> Result<()> {
        let r = self.renderer.as_mut().ok_or_else(|| err("destroyed"))?;
        r.cmd_draw(cmd, extent, self.pixels_per_point, &self.primitives)
            .map_err(err)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        let _ = ctx.wait_idle();
        if let Some(mut r) = self.renderer.take() {
            let _ = r.free_textures(&self.free);
        }
    }
}

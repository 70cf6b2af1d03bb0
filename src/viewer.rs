//! How `run` shows particles: ray-marched metaballs with per-pixel lists, or the
//! sphere-impostor particle view, behind one `View` trait. Both write one PNG per saved
//! frame.
use crate::config::Switches;
use crate::error::Result;
use crate::gpu::{sync, Buffer, ColorTarget, Context, Guard, Profiler};
use crate::render::metaball::{FrameStats, MetaballBuffers, MetaballRenderer, MetaballSettings};
use crate::render::{points::PointsPush, Camera, PointsView};
use ash::vk;
use serde::{Deserialize, Serialize};

/// A picture of `n` particles per frame.
pub trait View {
    /// Record the frame's picture of the particles at `pos` (colours in `attr`), whose
    /// writes the caller made visible to compute, vertex shaders and copies.
    #[allow(clippy::too_many_arguments)]
    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        pos: &Buffer,
        attr: &Buffer,
        n: u32,
        slot: usize,
        save: bool,
    ) -> Result<()>;
    /// After the slot's fence: check the frame; its picture when `save` (it was recorded
    /// with `save`).
    fn retire(
        &mut self,
        ctx: &Context,
        slot: usize,
        n: u32,
        save: bool,
    ) -> Result<Option<Picture<'_>>>;
    fn stats(&self) -> RenderSummary;
    fn destroy(&mut self, ctx: &Context);
}

impl crate::gpu::Destroy for Box<dyn View> {
    fn destroy(&mut self, ctx: &Context) {
        View::destroy(self.as_mut(), ctx)
    }
}

/// A frame's RGBA8 pixels.
pub struct Picture<'a> {
    pub rgba: &'a [u8],
    pub width: u32,
    pub height: u32,
}

/// The `stats.render` block of summary.json.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct RenderSummary {
    pub renderer: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub settings: Option<MetaballSettings>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub last_frame: Option<FrameStats>,
    pub max_fragments: u64,
    pub max_list_bytes: u64,
    pub longest_list: u32,
    pub overflow_redos: u32,
    /// Frames with rays cut short by llvmpipe's loop budget (wrong pixels).
    pub frames_past_loop_budget: u32,
}

pub struct PointsViewer {
    view: PointsView,
    target: ColorTarget,
    push: PointsPush,
}

impl PointsViewer {
    pub fn new(
        ctx: &Context,
        sw: &Switches,
        cam: &Camera,
        radius: f32,
        slots: usize,
    ) -> Result<Self> {
        let view = Guard::new(ctx, PointsView::new(ctx)?);
        let target = ColorTarget::new(ctx, sw.frame.width(), sw.frame.height(), slots)?;
        Ok(Self {
            view: view.take(),
            target,
            push: PointsPush::from_camera(cam, radius),
        })
    }
}

impl View for PointsViewer {
    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        pos: &Buffer,
        attr: &Buffer,
        n: u32,
        slot: usize,
        save: bool,
    ) -> Result<()> {
        prof.begin(ctx, cmd, PointsView::NAME);
        self.target
            .begin_rendering(ctx, cmd, [0.02, 0.02, 0.04, 1.0]);
        self.view.draw(ctx, cmd, pos, attr, n, &self.push);
        self.target.end_rendering(ctx, cmd);
        prof.end(ctx, cmd);
        if save {
            prof.begin(ctx, cmd, "readback");
            self.target.copy_out(ctx, cmd, slot);
            prof.end(ctx, cmd);
        }
        Ok(())
    }

    fn retire(
        &mut self,
        _: &Context,
        slot: usize,
        _: u32,
        save: bool,
    ) -> Result<Option<Picture<'_>>> {
        Ok(save.then(|| Picture {
            rgba: self.target.pixels(slot),
            width: self.target.width(),
            height: self.target.height(),
        }))
    }

    fn stats(&self) -> RenderSummary {
        RenderSummary {
            renderer: "points".into(),
            ..Default::default()
        }
    }

    fn destroy(&mut self, ctx: &Context) {
        self.view.destroy(ctx);
        self.target.destroy(ctx);
    }
}

pub struct MetaballViewer {
    renderer: MetaballRenderer,
    buffers: MetaballBuffers,
    /// Per-slot copies of the particle positions, so a frame can be redone.
    centers: Vec<Buffer>,
    cam: Camera,
    totals: RenderSummary,
}

impl MetaballViewer {
    /// `tank`: the container to draw around the fluid (min, max), if any.
    pub fn new(
        ctx: &Context,
        sw: &Switches,
        cam: Camera,
        n: u32,
        slots: usize,
        tank: Option<[[f32; 3]; 2]>,
    ) -> Result<Self> {
        let mut settings = MetaballSettings::from_switches(sw)?;
        settings.tank = tank;
        let renderer = Guard::new(ctx, MetaballRenderer::new(ctx, settings)?);
        let buffers = Guard::new(ctx, renderer.buffers(ctx, n as u64, slots, false)?);
        let mut centers = Guard::new(ctx, Vec::new());
        for _ in 0..slots {
            centers.push(ctx.storage_buffer("metaball centers", n as u64 * 16)?);
        }
        let totals = RenderSummary {
            renderer: "metaballs".into(),
            settings: Some(renderer.settings.clone()),
            ..Default::default()
        };
        Ok(Self {
            renderer: renderer.take(),
            buffers: buffers.take(),
            centers: centers.take(),
            cam,
            totals,
        })
    }
}

impl View for MetaballViewer {
    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        pos: &Buffer,
        _: &Buffer,
        n: u32,
        slot: usize,
        _: bool,
    ) -> Result<()> {
        ctx.copy(cmd, pos, 0, &self.centers[slot], 0, n as u64 * 16);
        // This slot's centers -> the renderer's bounds pass and billboards.
        ctx.barrier(
            cmd,
            sync::TRANSFER_WRITE,
            sync::COMPUTE_READ | sync::GRAPHICS_READ,
        );
        prof.begin(ctx, cmd, "render");
        let r = self.renderer.record(
            ctx,
            cmd,
            prof,
            &self.buffers,
            &self.centers[slot],
            n,
            &self.cam,
            slot,
        );
        prof.end(ctx, cmd);
        r
    }

    fn retire(
        &mut self,
        ctx: &Context,
        slot: usize,
        n: u32,
        save: bool,
    ) -> Result<Option<Picture<'_>>> {
        let mut st = self.renderer.frame_stats(&self.buffers, slot);
        if st.overflow > 0 {
            // Buffers of frames still in flight are about to be replaced.
            ctx.wait_idle()?;
            let list = self.renderer.settings.list;
            self.buffers.grow(ctx, list, st.fragments)?;
            let (again, redos) = self.renderer.render_sync(
                ctx,
                &mut self.buffers,
                &self.centers[slot],
                n,
                &self.cam,
                slot,
            )?;
            st = again;
            self.totals.overflow_redos += 1 + redos;
        }
        let t = &mut self.totals;
        t.max_fragments = t.max_fragments.max(st.fragments);
        t.max_list_bytes = t.max_list_bytes.max(st.list_bytes);
        t.longest_list = t.longest_list.max(st.longest);
        if st.budget_pixels > 0 {
            t.frames_past_loop_budget += 1;
            eprintln!(
                "warning: {} pixels' rays were cut short by llvmpipe's loop budget \
                 (a coarser --radius, fewer particles or lists help)",
                st.budget_pixels
            );
        }
        t.last_frame = Some(st);
        let s = &self.renderer.settings;
        Ok(save.then(|| Picture {
            rgba: self.buffers.pixels(slot),
            width: s.width,
            height: s.height,
        }))
    }

    fn stats(&self) -> RenderSummary {
        self.totals.clone()
    }

    fn destroy(&mut self, ctx: &Context) {
        self.buffers.destroy(ctx);
        for c in &mut self.centers {
            ctx.destroy_buffer(c);
        }
        self.renderer.destroy(ctx);
    }
}

//! How `run` shows particles: ray-marched metaballs with per-pixel lists, or the
//! sphere-impostor particle view, behind one `FluidView` trait; either draws a character's
//! skinned mesh with them, depth-tested, and an overlay (particle systems): its opaque
//! draws with the mesh, its blended ones over the finished picture, depth-tested against
//! the fluid and the mesh. Both write one PNG per saved frame.
use crate::config::Switches;
use crate::error::Result;
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{Buffer, ColorTarget, Context, Guard, Labels, Profiler, Scopes};
use crate::render::mesh::{MeshDraw, MeshView};
use crate::render::metaball::{FluidRenderer, FrameStats, MetaballBuffers, MetaballSettings};
use crate::render::surface::SurfaceFluid;
use crate::render::ShowMesh;
use crate::render::{points::PointsPush, Camera, PointsView};
use serde::{Deserialize, Serialize};

const OVERLAY_SCOPE: crate::gpu::ScopeName = crate::gpu::ScopeName::new("overlay");
const READBACK_SCOPE: crate::gpu::ScopeName = crate::gpu::ScopeName::new("readback");

/// Draws shown with a view's particles (particle systems), inside its rendering scopes:
/// the opaque ones write depth; the blended ones only test it, drawn after everything
/// opaque (the fluid included).
pub trait Overlay {
    /// Declare the draws of the next rendering scope (before it begins): the opaque ones,
    /// or the blended ones.
    fn prepare(&self, ctx: &Context, cmd: vk::CommandBuffer, opaque: bool);
    fn draw_opaque(&self, ctx: &Context, cmd: vk::CommandBuffer);
    fn draw_blended(&self, ctx: &Context, cmd: vk::CommandBuffer);
    fn has_blended(&self) -> bool;
}

/// What a frame shows besides the particles.
#[derive(Clone, Copy, Default)]
pub struct Layers<'a> {
    /// The character's mesh (a view made with a mesh view needs one each frame).
    pub mesh: Option<&'a MeshDraw<'a>>,
    pub overlay: Option<&'a dyn Overlay>,
}

/// A picture of `n` particles per frame.
pub trait FluidView {
    /// Record the frame's picture of the particles at `pos` (colours in `attr`) and its
    /// layers, whose writes the caller made visible to compute, vertex shaders and copies.
    #[allow(clippy::too_many_arguments)]
    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        pos: &Buffer,
        attr: &Buffer,
        n: u32,
        layers: Layers,
        slot: usize,
        save: bool,
    ) -> Result<()>;
    /// After the slot's fence: check the frame; its picture when `save` (it was recorded
    /// with `save`). A frame redone here (a metaball list overflowed) draws `overlay` as
    /// it is now.
    fn retire(
        &mut self,
        ctx: &Context,
        slot: usize,
        n: u32,
        save: bool,
        overlay: Option<&dyn Overlay>,
    ) -> Result<Option<Picture<'_>>>;
    fn stats(&self) -> RenderSummary;
    /// Draw from `cam` from the next recorded frame on (the viewer's camera).
    fn set_camera(&mut self, cam: &Camera);
    fn destroy(&mut self, ctx: &Context);
}

impl crate::gpu::Destroy for Box<dyn FluidView> {
    fn destroy(&mut self, ctx: &Context) {
        FluidView::destroy(self.as_mut(), ctx)
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
    /// Bytes of the renderer's buffers at the end of the run (by ownership).
    #[serde(default)]
    pub renderer_bytes: u64,
    pub longest_list: u32,
    pub overflow_redos: u32,
    /// Frames with rays cut short by llvmpipe's loop budget (wrong pixels).
    pub frames_past_loop_budget: u32,
}

pub struct PointsViewer {
    view: PointsView,
    mesh: Option<MeshView>,
    target: ColorTarget,
    push: PointsPush,
}

/// The mesh view for `show`, if the mesh is drawn.
fn mesh_view(ctx: &Context, cam: &Camera, show: ShowMesh) -> Result<Option<MeshView>> {
    match show {
        ShowMesh::Off => Ok(None),
        s => MeshView::new(ctx, cam, s).map(Some),
    }
}

impl PointsViewer {
    pub fn new(
        ctx: &Context,
        sw: &Switches,
        cam: &Camera,
        radius: f32,
        slots: usize,
        show: ShowMesh,
    ) -> Result<Self> {
        let size = (sw.frame.width(), sw.frame.height());
        // Colour, depth and a readback per slot; images, bound by no storage range.
        check_frame(ctx, size, (8 + 4 * slots as u64, 0), sw.common.quiet)?;
        let view = Guard::new(ctx, PointsView::new(ctx)?);
        let mesh = Guard::new(ctx, mesh_view(ctx, cam, show)?);
        let target = ColorTarget::new(ctx, size.0, size.1, slots)?;
        Ok(Self {
            view: view.take(),
            mesh: mesh.take(),
            target,
            push: PointsPush::from_camera(cam, radius),
        })
    }
}

impl FluidView for PointsViewer {
    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        pos: &Buffer,
        attr: &Buffer,
        n: u32,
        layers: Layers,
        slot: usize,
        save: bool,
    ) -> Result<()> {
        {
            let _scope = prof.open(ctx, cmd, crate::render::points::POINTS.scope());
            if let (Some(v), Some(m)) = (&self.mesh, layers.mesh) {
                v.prepare(ctx, cmd, m);
            }
            if n > 0 {
                self.view.prepare(ctx, cmd, pos, attr);
            }
            if let Some(o) = layers.overlay {
                o.prepare(ctx, cmd, true);
                o.prepare(ctx, cmd, false);
            }
            self.target
                .begin_rendering(ctx, cmd, [0.02, 0.02, 0.04, 1.0]);
            if let (Some(v), Some(m)) = (&self.mesh, layers.mesh) {
                v.draw(ctx, cmd, m);
            }
            if n > 0 {
                self.view.draw(ctx, cmd, pos, attr, n, &self.push);
            }
            if let Some(o) = layers.overlay {
                o.draw_opaque(ctx, cmd);
                o.draw_blended(ctx, cmd);
            }
            self.target.end_rendering(ctx, cmd);
        }
        if save {
            {
                let _scope = prof.open(ctx, cmd, READBACK_SCOPE);
                self.target.copy_out(ctx, cmd, slot);
            }
        }
        Ok(())
    }

    fn retire(
        &mut self,
        _: &Context,
        slot: usize,
        _: u32,
        save: bool,
        _: Option<&dyn Overlay>,
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

    fn set_camera(&mut self, cam: &Camera) {
        self.push = PointsPush::from_camera(cam, self.push.right[3]);
        if let Some(m) = &mut self.mesh {
            m.set_camera(cam);
        }
    }

    fn destroy(&mut self, ctx: &Context) {
        self.view.destroy(ctx);
        if let Some(m) = &mut self.mesh {
            m.destroy(ctx);
        }
        self.target.destroy(ctx);
    }
}

pub struct MetaballViewer {
    renderer: FluidRenderer,
    buffers: MetaballBuffers,
    /// The mesh view, if the mesh is shown.
    mesh: Option<MeshView>,
    /// The colour + depth target of the opaque layer (the mesh and the overlay's opaque
    /// draws), copied into the renderer's opaque layer each frame; the overlay's blended
    /// draws go over the finished picture in it.
    target: Option<ColorTarget>,
    /// Per-slot copies of the particle positions, so a frame can be redone.
    centers: Vec<Buffer>,
    cam: Camera,
    totals: RenderSummary,
}

impl MetaballViewer {
    /// `tank`: the container to draw around the fluid (min, max), if any; `fluid`: the
    /// particles' (for the other surfaces); `overlay`: frames come with an overlay.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        ctx: &Context,
        sw: &Switches,
        cam: Camera,
        n: u32,
        slots: usize,
        (tank, fluid): (Option<[[f32; 3]; 2]>, SurfaceFluid),
        show: ShowMesh,
        overlay: bool,
    ) -> Result<Self> {
        let mut settings = crate::settings::run_metaball_settings(sw, n)?;
        settings.tank = tank;
        settings.fluid = Some(fluid);
        settings.opaque = show != ShowMesh::Off || overlay;
        let bytes = crate::render::metaball::buffers::pixel_bytes(&settings, slots);
        check_frame(
            ctx,
            (settings.width, settings.height),
            bytes,
            sw.common.quiet,
        )?;
        let mesh = Guard::new(ctx, mesh_view(ctx, &cam, show)?);
        let target = match settings.opaque {
            true => Some(ColorTarget::new(ctx, settings.width, settings.height, 0)?),
            false => None,
        };
        let target = Guard::new(ctx, target);
        let renderer = Guard::new(ctx, FluidRenderer::new(ctx, settings)?);
        let buffers = Guard::new(ctx, renderer.buffers(ctx, n as u64, slots, false)?);
        let mut centers = Guard::new(ctx, Vec::new());
        for _ in 0..slots {
            centers.push(ctx.storage_buffer("metaball centers", n as u64 * 16)?);
        }
        let totals = RenderSummary {
            renderer: renderer.settings.surface.as_str(),
            settings: Some(renderer.settings.clone()),
            ..Default::default()
        };
        Ok(Self {
            renderer: renderer.take(),
            buffers: buffers.take(),
            mesh: mesh.take(),
            target: target.take(),
            centers: centers.take(),
            cam,
            totals,
        })
    }
}

impl MetaballViewer {
    /// After the picture: the overlay's blended draws over it (depth-tested against the
    /// fluid and the opaque layer), then this slot's readbacks.
    fn record_finish(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        overlay: Option<&dyn Overlay>,
        slot: usize,
    ) -> Result<()> {
        let b = &self.buffers;
        if let Some(o) = overlay.filter(|o| o.has_blended()) {
            let target = self.target.as_ref().ok_or_else(|| {
                crate::Error::Param("a metaball view made without overlays was given one".into())
            })?;
            {
                let _scope = scopes.open(ctx, cmd, OVERLAY_SCOPE);
                target.load_layers(ctx, cmd, (&b.pixels, 0), (&b.scene_depth, 0));
                o.prepare(ctx, cmd, false);
                target.begin_rendering_loaded(ctx, cmd);
                o.draw_blended(ctx, cmd);
                target.end_rendering(ctx, cmd);
                target.copy_color(ctx, cmd, &b.pixels, 0);
            }
        }
        self.renderer.record_readback(ctx, cmd, b, slot);
        Ok(())
    }
}

impl FluidView for MetaballViewer {
    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        pos: &Buffer,
        _: &Buffer,
        n: u32,
        layers: Layers,
        slot: usize,
        _: bool,
    ) -> Result<()> {
        if let Some(target) = &self.target {
            {
                let _scope = prof.open(ctx, cmd, crate::render::mesh::MESH.scope());
                let mesh = match &self.mesh {
                    Some(view) => Some((
                        view,
                        layers.mesh.ok_or_else(|| {
                            crate::Error::Param(
                                "a metaball view made to draw a mesh was given none".into(),
                            )
                        })?,
                    )),
                    None => None,
                };
                if let Some((view, m)) = mesh {
                    view.prepare(ctx, cmd, m);
                }
                if let Some(o) = layers.overlay {
                    o.prepare(ctx, cmd, true);
                }
                target.begin_rendering(ctx, cmd, [0.0; 4]);
                if let Some((view, m)) = mesh {
                    view.draw(ctx, cmd, m);
                }
                if let Some(o) = layers.overlay {
                    o.draw_opaque(ctx, cmd);
                }
                target.end_rendering(ctx, cmd);
                let px = self.renderer.settings.pixels();
                target.copy_layers(ctx, cmd, &self.buffers.opaque, 0, px * 4);
            }
        }
        ctx.copy(cmd, pos, 0, &self.centers[slot], 0, n as u64 * 16);
        {
            let mut prof = prof.open(ctx, cmd, crate::render::SCOPE.scope());
            self.renderer.record_picture(
                ctx,
                cmd,
                &mut *prof,
                &self.buffers,
                &self.centers[slot],
                n,
                &self.cam,
            )?;
        }
        self.record_finish(ctx, cmd, prof, layers.overlay, slot)
    }

    fn retire(
        &mut self,
        ctx: &Context,
        slot: usize,
        n: u32,
        save: bool,
        overlay: Option<&dyn Overlay>,
    ) -> Result<Option<Picture<'_>>> {
        let mut st = self.renderer.frame_stats(&self.buffers, slot);
        if st.overflow > 0 {
            // Buffers of frames still in flight are about to be replaced.
            ctx.wait_idle()?;
            self.renderer.grow(ctx, &mut self.buffers, &st)?;
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
            if overlay.is_some_and(|o| o.has_blended()) {
                // render_sync redid the picture alone: the overlay over it again.
                ctx.one_shot(|cmd| self.record_finish(ctx, cmd, &mut Labels, overlay, slot))??;
            }
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
        RenderSummary {
            renderer_bytes: self.buffers.bytes(),
            ..self.totals.clone()
        }
    }

    fn set_camera(&mut self, cam: &Camera) {
        self.cam = *cam;
        if let Some(m) = &mut self.mesh {
            m.set_camera(cam);
        }
    }

    fn destroy(&mut self, ctx: &Context) {
        if let Some(v) = &mut self.mesh {
            v.destroy(ctx);
        }
        if let Some(t) = &mut self.target {
            t.destroy(ctx);
        }
        self.buffers.destroy(ctx);
        for c in &mut self.centers {
            ctx.destroy_buffer(c);
        }
        self.renderer.destroy(ctx);
    }
}

/// Frames of at least this many pixels on a CPU device are announced at start.
const LARGE_FRAME_PIXELS: f64 = 4.0 * 1024.0 * 1024.0;

/// Refuse a `w` x `h` frame the device cannot hold, before anything is made for it: a side
/// over the device's image limit, the largest pixel-sized buffer (`largest` bytes a pixel)
/// over what one storage binding addresses, or all of them (`total` bytes a pixel) over
/// half the device's memory. The error names the largest frame of the same shape that
/// fits. A frame that fits but is large on a CPU device is announced unless `quiet`: its
/// frames take long, and the progress is per frame.
pub fn check_frame(
    ctx: &Context,
    (w, h): (u32, u32),
    (total, largest): (u64, u64),
    quiet: bool,
) -> Result<()> {
    const MIB: f64 = (1u64 << 20) as f64;
    let px = w as f64 * h as f64;
    let max_side = ctx.limits.max_image_dimension2_d;
    let range = ctx.max_storage_range() as f64;
    let memory = ctx.info.device_local_bytes as f64 / 2.0;
    let mut limits = vec![(
        max_side as f64 / w.max(h) as f64,
        format!("its sides may be at most {max_side} pixels here"),
    )];
    limits.push((
        (range / (largest as f64 * px)).sqrt(),
        format!(
            "one of its buffers would take {:.0} MiB, more than one storage binding addresses here ({:.0} MiB)",
            largest as f64 * px / MIB,
            range / MIB
        ),
    ));
    if memory > 0.0 {
        limits.push((
            (memory / (total as f64 * px)).sqrt(),
            format!(
                "its buffers would take {:.0} MiB, more than half the device's memory ({:.0} MiB)",
                total as f64 * px / MIB,
                2.0 * memory / MIB
            ),
        ));
    }
    let (scale, why) = limits
        .into_iter()
        .fold((1.0f64, None), |(s, why), (l, text)| match l < s {
            true => (l, Some(text)),
            false => (s, why),
        });
    if let Some(why) = why {
        let fit = |side: u32| ((side as f64 * scale).floor() as u32).max(1);
        return Err(crate::error::Error::Memory(format!(
            "a {w} x {h} frame is too large: {why}; the largest frame of its shape that fits is --width {} --height {}",
            fit(w),
            fit(h)
        )));
    }
    if !quiet && px >= LARGE_FRAME_PIXELS && ctx.info.kind == "cpu" {
        eprintln!(
            "a {w} x {h} frame ({:.1} Mpx, {:.0} MiB of frame buffers) on a CPU device: each frame takes long; progress is per frame",
            px / 1e6,
            total as f64 * px / MIB
        );
    }
    Ok(())
}

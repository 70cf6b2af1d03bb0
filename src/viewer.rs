//! How `run` shows SPH particles: ray-marched metaballs with per-pixel lists, or the
//! sphere-impostor particle view. Both write one PNG per saved frame.
use crate::config::Switches;
use crate::error::Result;
use crate::gpu::target::save_rgba;
use crate::gpu::{Buffer, ColorTarget, Context, Profiler};
use crate::render::metaball::{FrameStats, MetaballBuffers, MetaballRenderer, MetaballSettings};
use crate::render::{points::PointsPush, Camera, PointsView};
use ash::vk;
use serde_json::{json, Value};
use std::cell::RefCell;
use std::path::Path;

// One viewer per run: the size difference between the variants does not matter.
#[allow(clippy::large_enum_variant)]
pub enum Viewer {
    Points {
        view: PointsView,
        target: ColorTarget,
        push: PointsPush,
    },
    Metaballs {
        renderer: Box<MetaballRenderer>,
        buffers: RefCell<MetaballBuffers>,
        /// Per-slot copies of the particle positions, so a frame can be redone.
        centers: Vec<Buffer>,
        cam: Camera,
        stats: RefCell<RenderTotals>,
    },
}

#[derive(Default)]
pub struct RenderTotals {
    pub last: FrameStats,
    pub max_fragments: u64,
    pub max_list_bytes: u64,
    pub longest: u32,
    pub redos: u32,
    /// Frames with rays cut short by llvmpipe's loop budget (wrong pixels).
    pub budget_frames: u32,
}

impl Viewer {
    pub fn metaballs(
        ctx: &Context,
        sw: &Switches,
        cam: Camera,
        n: u32,
        slots: usize,
    ) -> Result<Self> {
        let settings = MetaballSettings::from_switches(sw)?;
        let renderer = MetaballRenderer::new(ctx, settings)?;
        let buffers = renderer.buffers(ctx, n as u64, slots, false)?;
        let mut centers = Vec::new();
        for _ in 0..slots {
            centers.push(ctx.storage_buffer("metaball centers", n as u64 * 16)?);
        }
        Ok(Viewer::Metaballs {
            renderer: Box::new(renderer),
            buffers: RefCell::new(buffers),
            centers,
            cam,
            stats: RefCell::new(RenderTotals::default()),
        })
    }

    pub fn points(
        ctx: &Context,
        sw: &Switches,
        cam: &Camera,
        radius: f32,
        slots: usize,
    ) -> Result<Self> {
        Ok(Viewer::Points {
            view: PointsView::new(ctx)?,
            target: ColorTarget::new(ctx, sw.width, sw.height, slots)?,
            push: PointsPush::from_camera(cam, radius),
        })
    }

    /// Record the frame's picture of `n` particles at `pos` (colours in `attr`).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        pos: &Buffer,
        attr: &Buffer,
        n: u32,
        slot: usize,
        save: bool,
    ) -> Result<()> {
        match self {
            Viewer::Points { view, target, push } => {
                prof.begin(ctx, cmd, PointsView::NAME);
                target.begin_rendering(ctx, cmd, [0.02, 0.02, 0.04, 1.0]);
                view.draw(ctx, cmd, pos, attr, n, push);
                target.end_rendering(ctx, cmd);
                prof.end(ctx, cmd);
                if save {
                    prof.begin(ctx, cmd, "readback");
                    target.copy_out(ctx, cmd, slot);
                    prof.end(ctx, cmd);
                }
                Ok(())
            }
            Viewer::Metaballs {
                renderer,
                buffers,
                centers,
                cam,
                ..
            } => {
                let region = vk::BufferCopy {
                    src_offset: 0,
                    dst_offset: 0,
                    size: n as u64 * 16,
                };
                ctx.barrier(cmd);
                unsafe {
                    ctx.device
                        .cmd_copy_buffer(cmd, pos.raw, centers[slot].raw, &[region])
                };
                ctx.barrier(cmd);
                prof.begin(ctx, cmd, "render");
                renderer.record(
                    ctx,
                    cmd,
                    prof,
                    &buffers.borrow(),
                    &centers[slot],
                    n,
                    cam,
                    slot,
                )?;
                prof.end(ctx, cmd);
                Ok(())
            }
        }
    }

    /// After the slot's fence: check the lists (grow and redo an overflowed frame) and
    /// save the PNG when asked.
    pub fn retire(&self, ctx: &Context, slot: usize, n: u32, png: Option<&Path>) -> Result<()> {
        match self {
            Viewer::Points { target, .. } => {
                if let Some(p) = png {
                    target.save_png(slot, p)?;
                }
                Ok(())
            }
            Viewer::Metaballs {
                renderer,
                buffers,
                centers,
                cam,
                stats,
            } => {
                let mut st = renderer.frame_stats(&buffers.borrow(), slot);
                if st.overflow > 0 {
                    // Buffers of frames still in flight are about to be replaced.
                    unsafe { ctx.device.device_wait_idle() }.map_err(|e| crate::Error::Vulkan {
                        context: "wait idle before growing the lists".into(),
                        result: e,
                    })?;
                    let mut b = buffers.borrow_mut();
                    renderer.grow(ctx, &mut b, st.fragments)?;
                    let (again, redos) =
                        renderer.render_sync(ctx, &mut b, &centers[slot], n, cam, slot)?;
                    st = again;
                    stats.borrow_mut().redos += 1 + redos;
                }
                let mut t = stats.borrow_mut();
                t.max_fragments = t.max_fragments.max(st.fragments);
                t.max_list_bytes = t.max_list_bytes.max(st.list_bytes);
                t.longest = t.longest.max(st.longest);
                if st.budget_pixels > 0 {
                    t.budget_frames += 1;
                    eprintln!(
                        "warning: {} pixels' rays were cut short by llvmpipe's loop budget \
                         (a coarser --radius, fewer particles or lists help)",
                        st.budget_pixels
                    );
                }
                t.last = st;
                if let Some(p) = png {
                    let s = &renderer.settings;
                    save_rgba(p, s.width, s.height, buffers.borrow().pixels(slot))?;
                }
                Ok(())
            }
        }
    }

    pub fn stats(&self) -> Value {
        match self {
            Viewer::Points { .. } => json!({ "renderer": "points" }),
            Viewer::Metaballs {
                renderer, stats, ..
            } => {
                let t = stats.borrow();
                json!({
                    "renderer": "metaballs",
                    "settings": renderer.settings,
                    "last_frame": t.last,
                    "max_fragments": t.max_fragments,
                    "max_list_bytes": t.max_list_bytes,
                    "longest_list": t.longest,
                    "overflow_redos": t.redos,
                    "frames_past_loop_budget": t.budget_frames,
                })
            }
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        match self {
            Viewer::Points { view, target, .. } => {
                view.destroy(ctx);
                target.destroy(ctx);
            }
            Viewer::Metaballs {
                renderer,
                buffers,
                centers,
                ..
            } => {
                buffers.get_mut().destroy(ctx);
                for c in centers {
                    ctx.destroy_buffer(c);
                }
                renderer.destroy(ctx);
            }
        }
    }
}

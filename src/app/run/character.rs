//! `run` of a character alone: skinned each frame and drawn.
use super::*;

/// The scene's character, skinned by --skinning and shown by --show-mesh (default shaded).
fn scene_character(
    ctx: &Context,
    scene: &crate::scene::Scene,
    sw: &Switches,
) -> Result<Option<SceneCharacter>> {
    let method = sw.character.skinning.unwrap_or(Skinning::Lbs);
    // (Scenes with fluid, and so any control target, play through SceneTargets.)
    let show = sw.character.show_mesh.unwrap_or(ShowMesh::Shaded);
    scene
        .character
        .as_ref()
        .map(|d| SceneCharacter::new(ctx, d, method, show))
        .transpose()
}

/// A character alone: skinned each frame at 30 frames per second of scene time.
struct CharacterWork {
    character: SceneCharacter,
    view: PointsViewer,
    frames: Frames,
}

impl FrameWork for CharacterWork {
    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        frame: u64,
        slot: usize,
    ) -> Result<()> {
        let t = frame as f64 / ANIMATION_FPS as f64;
        self.character.record(ctx, cmd, prof, t)?;
        let save = self.frames.save(frame);
        let m = self.character.draw();
        // Without fluid the mesh is always shown (run_character refuses --show-mesh off).
        let Some(pos) = m.as_ref().map(|m| m.pos) else {
            return Err(Error::Param(
                "a character scene with its mesh hidden".into(),
            ));
        };
        let layers = crate::run::view::Layers {
            mesh: m.as_ref(),
            overlay: None,
        };
        self.view
            .record(ctx, cmd, prof, pos, pos, 0, layers, slot, save)
    }

    fn retire(&mut self, ctx: &Context, frame: u64, slot: usize) -> Result<()> {
        let save = self.frames.save(frame);
        let pic = self.view.retire(ctx, slot, 0, save, None)?;
        self.frames.store(frame, pic)
    }
}

pub(super) fn run_character(opts: &RunOptions, scene: crate::scene::Scene) -> Result<RunResult> {
    use crate::config::Group;
    let sw = &crate::settings::with_look(&scene.look, &opts.switches);
    sw.reject_unused(
        &format!("scene {} (a character with no fluid)", scene.name),
        &[Group::Character, Group::Camera],
    )?;
    if sw.character.show_mesh == Some(ShowMesh::Off) {
        return Err(Error::Param(format!(
            "scene {} has no fluid: --show-mesh off leaves nothing to draw",
            scene.name
        )));
    }
    let frame_count = opts.frames.unwrap_or(scene.frames);
    let ctx = open(sw)?;
    let aspect = sw.frame.width() as f32 / sw.frame.height() as f32;
    let character = scene_character(&ctx, &scene, sw)?
        .ok_or_else(|| Error::Param(format!("scene {}: no fluid and no character", scene.name)))?;
    let character = Guard::new(&ctx, character);
    let cam = match &scene.camera {
        Some(c) => Camera::look_at(c.eye.into(), c.target.into(), c.fov, aspect),
        None => {
            let st = character.stats(None)?;
            let h = st.height.max(1e-3);
            let base = character.anim.placement.w_axis.truncate();
            let c = base + glam::Vec3::Y * 0.5 * h;
            Camera::look_at(
                c + glam::Vec3::new(0.6, 0.3, 1.6) * h * 1.3,
                c,
                40.0,
                aspect,
            )
        }
    };
    let cam = camera_with_switches(cam, sw);
    let view = PointsViewer::new(&ctx, sw, &cam, 1.0, SLOTS, character.show)?;
    let mut work = CharacterWork {
        character: character.take(),
        view,
        frames: Frames::new(&opts.out, opts.save_every, frame_count).sampled(&sw.frame),
    };
    let memory = ctx.memory_bytes();
    let timings = play_run(&ctx, frame_count, &mut work, &opts.scene, &sw.common);
    let stats = work.character.stats(None);
    let render = work.view.stats();
    work.character.destroy(&ctx);
    work.view.destroy(&ctx);
    let timings = timings?;
    let stats = RunStats::Character(Box::new(CharacterRunStats {
        character: stats?,
        render,
    }));
    finish_fluidless(
        &ctx,
        opts,
        sw,
        (&scene.name, frame_count, 0),
        (&timings, memory),
        stats,
        work.frames,
    )
}

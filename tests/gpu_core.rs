//! The Vulkan core on lavapipe with validation: device, compute and graphics round trips,
//! profiler, shader errors.
mod common;
use ash::vk;
use bytemuck::{Pod, Zeroable};
use fluidform::gpu::{
    shader, ColorTarget, ComputeDesc, ComputePipeline, Context, FrameLoop, FrameWork, Profiler,
};
use fluidform::render::points::{PointsPush, PointsView};
use fluidform::Error;

#[test]
fn device_opens_with_required_features() {
    let ctx = common::ctx();
    assert!(ctx.info.missing.is_empty(), "{:?}", ctx.info.missing);
    assert!(ctx.info.timestamp_period_ns > 0.0);
    assert!(ctx.info.timestamp_valid_bits > 0);
    assert!(ctx.info.api.starts_with("1.3") || ctx.info.api.starts_with("1.4"));
    let all = fluidform::gpu::list_devices().unwrap();
    assert!(all.iter().any(|d| d.name == ctx.info.name));
    common::finish(&ctx);
}

#[test]
fn validation_layer_reports_misuse() {
    // Proves the messenger is live: a zero-sized buffer is invalid usage.
    let ctx = common::ctx();
    let info = vk::BufferCreateInfo::default()
        .size(0)
        .usage(vk::BufferUsageFlags::STORAGE_BUFFER);
    if let Ok(b) = unsafe { ctx.device.create_buffer(&info, None) } {
        unsafe { ctx.device.destroy_buffer(b, None) };
    }
    assert!(
        ctx.validation_counts().0 >= 1,
        "validation did not report a zero-sized buffer"
    );
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct SaxpyPush {
    a: f32,
    n: u32,
}

fluidform::gpu_interface! {
    /// glsl/test/saxpy.comp
    SaxpyIo / SaxpyBufs: "SAXPY", push SaxpyPush { x = 0, y = 1, u = 2 }
}

#[test]
fn compute_round_trip_matches_cpu_exactly() {
    let ctx = common::ctx();
    // Local size 32 so 3M elements need more than 65535 groups: exercises the y split.
    let mut p = ComputePipeline::<SaxpyIo>::new(
        &ctx,
        &ComputeDesc::plain("saxpy", "test/saxpy.comp", &[], 32),
    )
    .unwrap();
    for n in [1usize, 1000, 3_000_001] {
        let x: Vec<f32> = (0..n).map(|i| (i % 1024) as f32).collect();
        let y: Vec<f32> = (0..n).map(|i| (i % 77) as f32 - 30.0).collect();
        let u = common::random_u32(n, n as u64);
        let mut bx = ctx.storage_buffer("x", (n * 4) as u64).unwrap();
        let mut by = ctx.storage_buffer("y", (n * 4) as u64).unwrap();
        let mut bu = ctx.storage_buffer("u", (n * 4) as u64).unwrap();
        ctx.upload(&mut bx, 0, &x).unwrap();
        ctx.upload(&mut by, 0, &y).unwrap();
        ctx.upload(&mut bu, 0, &u).unwrap();
        let push = SaxpyPush {
            a: 2.0,
            n: n as u32,
        };
        let bufs = SaxpyBufs {
            x: &bx,
            y: &by,
            u: &bu,
        };
        ctx.one_shot(|cmd| p.dispatch(&ctx, cmd, &bufs, &push, n as u64))
            .unwrap();
        let gy: Vec<f32> = ctx.read_all(&by).unwrap();
        let gu: Vec<u32> = ctx.read_all(&bu).unwrap();
        for i in 0..n {
            assert_eq!(gy[i], 2.0 * x[i] + y[i], "y[{i}] (n = {n})");
            assert_eq!(
                gu[i],
                u[i].wrapping_mul(2654435761).wrapping_add(i as u32),
                "u[{i}] (n = {n})"
            );
        }
        for b in [&mut bx, &mut by, &mut bu] {
            ctx.destroy_buffer(b);
        }
    }
    p.destroy(&ctx);
    common::finish(&ctx);
}

#[test]
fn orbits_step_matches_cpu_reference() {
    use fluidform::orbits::*;
    let ctx = common::ctx();
    let n = 5000;
    let state = initial_state(n, 7);
    let pass = OrbitsPass::new(&ctx).unwrap();
    let mut gpu = Orbits::new(&ctx, &state).unwrap();
    let dt = 1.0 / 120.0;
    ctx.one_shot(|cmd| {
        for _ in 0..10 {
            pass.step(&ctx, cmd, &gpu, dt);
            ctx.compute_barrier(cmd);
        }
    })
    .unwrap();
    let (mut pos, mut vel) = (state.pos.clone(), state.vel.clone());
    let push = OrbitsPush {
        dt,
        strength: STRENGTH,
        eps: EPS,
        n: n as u32,
    };
    for _ in 0..10 {
        step_cpu(&mut pos, &mut vel, &push);
    }
    let gpos: Vec<[f32; 4]> = ctx.read_all(&gpu.pos).unwrap();
    for (i, (g, c)) in gpos.iter().zip(&pos).enumerate() {
        for k in 0..3 {
            assert!(
                (g[k] - c[k]).abs() < 1e-4,
                "particle {i} axis {k}: {g:?} vs {c:?}"
            );
            assert!(g[k].abs() <= 1.0, "particle {i} left the box");
        }
    }
    gpu.destroy(&ctx);
    let mut pass = pass;
    pass.destroy(&ctx);
    common::finish(&ctx);
}

type Disc = ([f32; 2], f32, [f32; 3]);

/// The colour the points view gives the pixel centred at clip `(cx, cy)`: a disc's shaded
/// colour, or the blue clear colour; None within 1.5 pixels of a disc's rim.
fn expected_pixel(discs: &[Disc], (cx, cy): (f32, f32), side: u32) -> Option<[u8; 4]> {
    let mut expected = [0u8, 0, 255, 255];
    for (c, r, rgb) in discs {
        // Distance in the disc's own uv (quad spans [-r, r] in both clip axes).
        let (u, v) = ((cx - c[0]) / r, (cy - c[1]) / r);
        let d2 = u * u + v * v;
        let px_r = 1.5 * 2.0 / (side as f32 * r); // 1.5 pixels in uv units
        if (d2.sqrt() - 1.0).abs() < px_r {
            return None;
        } else if d2 < 1.0 {
            let s = 0.35 + 0.65 * (1.0 - d2).sqrt();
            expected = [
                (rgb[0] * s * 255.0).round() as u8,
                (rgb[1] * s * 255.0).round() as u8,
                (rgb[2] * s * 255.0).round() as u8,
                255,
            ];
        }
    }
    Some(expected)
}

#[test]
fn graphics_round_trip_matches_expected_pixels() {
    let ctx = common::ctx();
    let (w, h) = (128u32, 96u32);
    // Two discs in clip space (identity view-projection): red at (-0.5, -0.5) radius 0.25,
    // green at (0.5, 0.25) radius 0.125. Vulkan clip y points down the image.
    let discs = [
        ([-0.5f32, -0.5], 0.25f32, [1.0f32, 0.0, 0.0]),
        ([0.5, 0.25], 0.125, [0.0, 1.0, 0.0]),
    ];
    let pos: Vec<[f32; 4]> = discs
        .iter()
        .map(|(c, r, _)| [c[0], c[1], 0.5, *r])
        .collect();
    let col: Vec<[f32; 4]> = discs
        .iter()
        .map(|(_, _, c)| [c[0], c[1], c[2], 1.0])
        .collect();
    let mut bpos = ctx.storage_buffer("pos", 32).unwrap();
    let mut bcol = ctx.storage_buffer("col", 32).unwrap();
    ctx.upload(&mut bpos, 0, &pos).unwrap();
    ctx.upload(&mut bcol, 0, &col).unwrap();
    let mut view = PointsView::new(&ctx).unwrap();
    let mut target = ColorTarget::new(&ctx, w, h, 1).unwrap();
    let push = PointsPush {
        view_proj: glam::Mat4::IDENTITY.to_cols_array_2d(),
        right: [1.0, 0.0, 0.0, 1.0],
        up: [0.0, 1.0, 0.0, 0.0],
    };
    let clear = [0.0, 0.0, 1.0, 1.0];
    ctx.one_shot(|cmd| {
        view.prepare(&ctx, cmd, &bpos, &bcol);
        target.begin_rendering(&ctx, cmd, clear);
        view.draw(&ctx, cmd, &bpos, &bcol, 2, &push);
        target.end_rendering(&ctx, cmd);
        target.copy_out(&ctx, cmd, 0);
    })
    .unwrap();
    let px = target.pixels(0).to_vec();
    let (mut inside, mut outside) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let p = &px[((y * w + x) * 4) as usize..][..4];
            // Pixel centre in clip space.
            let cx = (x as f32 + 0.5) / w as f32 * 2.0 - 1.0;
            let cy = (y as f32 + 0.5) / h as f32 * 2.0 - 1.0;
            let Some(expected) = expected_pixel(&discs, (cx, cy), w.min(h)) else {
                continue;
            };
            if expected[2] == 255 {
                outside += 1
            } else {
                inside += 1
            }
            for k in 0..4 {
                assert!(
                    (p[k] as i32 - expected[k] as i32).abs() <= 2,
                    "pixel ({x}, {y}): got {p:?}, expected {expected:?}"
                );
            }
        }
    }
    assert!(
        inside > 100 && outside > 1000,
        "inside {inside}, outside {outside}"
    );
    // Orientation: clip y = -0.5 is the upper half of the image.
    let red_row = (0.25 * h as f32) as u32;
    let i = ((red_row * w + w / 4) * 4) as usize;
    assert!(
        px[i] > 200 && px[i + 2] == 0,
        "red disc not at top-left: {:?}",
        &px[i..i + 4]
    );
    view.destroy(&ctx);
    target.destroy(&ctx);
    ctx.destroy_buffer(&mut bpos);
    ctx.destroy_buffer(&mut bcol);
    common::finish(&ctx);
}

#[test]
fn profiler_scopes_present_and_nested_inside_frame() {
    let ctx = common::ctx();
    let mut p = ComputePipeline::<SaxpyIo>::new(
        &ctx,
        &ComputeDesc::plain("saxpy", "test/saxpy.comp", &[], 64),
    )
    .unwrap();
    let n = 1 << 20;
    let mut bufs: Vec<_> = ["x", "y", "u"]
        .iter()
        .map(|name| ctx.storage_buffer(name, n * 4).unwrap())
        .collect();
    for b in &mut bufs {
        ctx.upload(b, 0, &vec![1u32; n as usize]).unwrap();
    }
    let mut frames = FrameLoop::new(&ctx, 2).unwrap();
    let push = SaxpyPush {
        a: 0.5,
        n: n as u32,
    };
    struct Work<'a> {
        p: &'a ComputePipeline<SaxpyIo>,
        bufs: SaxpyBufs<'a>,
        push: SaxpyPush,
        n: u64,
        done: Vec<u64>,
    }
    impl FrameWork for Work<'_> {
        fn record(
            &mut self,
            ctx: &Context,
            cmd: ash::vk::CommandBuffer,
            prof: &mut Profiler,
            _: u64,
            _: usize,
        ) -> fluidform::Result<()> {
            use fluidform::gpu::{Open, ScopeName};
            const SCOPES: [ScopeName; 2] = [ScopeName::new("first"), ScopeName::new("second")];
            for name in SCOPES {
                let _scope = prof.open(ctx, cmd, name);
                self.p.dispatch(ctx, cmd, &self.bufs, &self.push, self.n);
                ctx.compute_barrier(cmd);
            }
            Ok(())
        }
        fn retire(&mut self, _: &Context, frame: u64, _: usize) -> fluidform::Result<()> {
            self.done.push(frame);
            Ok(())
        }
    }
    let mut work = Work {
        p: &p,
        bufs: SaxpyBufs {
            x: &bufs[0],
            y: &bufs[1],
            u: &bufs[2],
        },
        push,
        n,
        done: Vec::new(),
    };
    frames.run(&ctx, 7, &mut work).unwrap();
    assert_eq!(
        work.done,
        (0..7).collect::<Vec<_>>(),
        "every frame retired once, in order"
    );
    let t = &frames.profiler.results;
    assert_eq!(t.len(), 7);
    for ft in t {
        let names: Vec<&str> = ft.passes.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["first", "second"]);
        let sum: f64 = ft.passes.iter().map(|(_, ms)| ms).sum();
        for (name, ms) in &ft.passes {
            assert!(*ms >= 0.0 && ms.is_finite(), "{name}: {ms}");
        }
        assert!(ft.frame_ms > 0.0, "frame {}: {}", ft.frame, ft.frame_ms);
        assert!(
            sum <= ft.frame_ms * 1.0001 + 1e-6,
            "passes {sum} ms > frame {} ms",
            ft.frame_ms
        );
    }
    frames.destroy(&ctx);
    for b in &mut bufs {
        ctx.destroy_buffer(b);
    }
    p.destroy(&ctx);
    common::finish(&ctx);
}

#[test]
fn shader_error_names_file_and_line() {
    let c = shader::ShaderCompiler::new().unwrap();
    let src = "#version 450\n#include \"common/index.glsl\"\nlayout(local_size_x = 1) in;\nvoid main() {\n  undefined_thing = 1;\n}\n";
    let e = c
        .compile_source("test/broken.comp", src, shaderc::ShaderKind::Compute, &[])
        .unwrap_err();
    match &e {
        Error::Shader {
            file,
            line,
            message,
        } => {
            assert_eq!(file, "glsl/test/broken.comp");
            assert_eq!(*line, 5);
            assert!(message.contains("undefined_thing"), "{message}");
        }
        other => panic!("expected a shader error, got {other}"),
    }
    assert!(e.to_string().starts_with("glsl/test/broken.comp:5:"), "{e}");
    // A missing include is named too.
    let e = c
        .compile_source(
            "test/broken.comp",
            "#version 450\n#include \"common/nope.glsl\"\nvoid main(){}\n",
            shaderc::ShaderKind::Compute,
            &[],
        )
        .unwrap_err();
    assert!(e.to_string().contains("nope.glsl"), "{e}");
}

#[test]
fn every_glsl_file_compiles_with_every_define_set_the_code_uses() {
    let c = shader::ShaderCompiler::new().unwrap();
    let variants = fluidform::gpu::pass::compiled_files();
    let mut count = 0;
    for f in shader::glsl_files() {
        if f.ends_with(".glsl") {
            continue; // include-only
        }
        let mine: Vec<_> = variants.iter().filter(|(file, _)| *file == f).collect();
        // Test shaders declare literal bindings; every other one must be registered.
        if mine.is_empty() {
            assert!(
                f.starts_with("test/"),
                "glsl/{f} is in no pass declaration (compute_pass!, graphics_pass!)"
            );
            c.compile(f, &[]).unwrap_or_else(|e| panic!("{e}"));
        }
        for (_, defines) in mine {
            let d: Vec<(&str, String)> = defines
                .iter()
                .map(|(k, v)| (k.as_str(), v.clone()))
                .collect();
            c.compile(f, &d)
                .unwrap_or_else(|e| panic!("glsl/{f} with {defines:?}: {e}"));
            count += 1;
        }
    }
    assert!(count >= 100, "only {count} shader variants compiled");
}

#[test]
fn a_variant_switch_with_an_unknown_value_fails_to_compile() {
    // Every multi-valued GLSL switch ends in #error: an unlisted value must not compile
    // into a default variant.
    let c = shader::ShaderCompiler::new().unwrap();
    let variants = fluidform::gpu::pass::compiled_files();
    let cases = [
        ("render/metaball/march.comp", "DENSITY"),
        ("render/metaball/march.comp", "LIST"),
        ("render/metaball/march.comp", "MATERIAL"),
        ("render/metaball/march.comp", "MARCH"),
        ("render/metaball/billboard.frag", "PASS"),
        ("render/surface/shade.comp", "MATERIAL"),
        ("render/surface/mesh.frag", "PASS"),
        ("primitives/nb_query.comp", "NB_STRATEGY"),
        ("primitives/nb_keys.comp", "NB_STRATEGY"),
        ("control/rays.frag", "PASS"),
        ("psys/draw.vert", "MODE"),
        ("psys/draw.frag", "MODE"),
        ("character/skin.comp", "SKIN_METHOD"),
        ("control/force.comp", "ADAPTIVE"),
        ("sph/dfsph.comp", "PASS"),
        ("sph/pcisph.comp", "PASS"),
        ("sph/pbf.comp", "PASS"),
    ];
    for (file, switch) in cases {
        let (_, defines) = variants
            .iter()
            .find(|(f, d)| *f == file && d.iter().any(|(k, _)| k == switch))
            .unwrap_or_else(|| panic!("no registered variant of {file} sets {switch}"));
        let d: Vec<(&str, String)> = defines
            .iter()
            .map(|(k, v)| match k == switch {
                true => (k.as_str(), "99".to_string()),
                false => (k.as_str(), v.clone()),
            })
            .collect();
        let e = c
            .compile(file, &d)
            .expect_err(&format!("{file} compiled with {switch}=99"));
        assert!(e.to_string().contains("#error"), "{file} {switch}: {e}");
    }
}

//! Rust mirrors of GPU structs (push constants, parameter blocks, stats) against the
//! offsets the GLSL compiler gives each member.
/// Rust mirrors of GPU structs against the offsets the GLSL compiler gave each member: every
/// `#[repr(C)]` struct in src (a test below counts them); one entry per struct.
#[test]
fn gpu_struct_mirrors_match_glsl_field_offsets() {
    use fluidform::gpu::interface::member_offsets;
    use std::mem::{offset_of, size_of};
    // The size of a field, from an accessor (no value of the struct needed).
    fn field_size<T, F>(_: fn(&T) -> &F) -> usize {
        size_of::<F>()
    }
    macro_rules! fields {
        ($t:ty; $($f:ident),* $(,)?) => {{
            let v = vec![$((stringify!($f), offset_of!($t, $f))),*];
            // Every field listed: the fields tile the struct with no gap or hidden tail.
            let mut end = 0;
            $(
                assert_eq!(offset_of!($t, $f), end, "{}: gap before {}", stringify!($t), stringify!($f));
                end += field_size(|t: &$t| &t.$f);
            )*
            assert_eq!(end, size_of::<$t>(), "{}: fields missing from the list", stringify!($t));
            (size_of::<$t>(), v, std::any::type_name::<$t>().rsplit("::").next().unwrap())
        }};
    }
    let c = fluidform::gpu::shader::ShaderCompiler::new().unwrap();
    let variants = fluidform::gpu::pass::compiled_files();
    let spv = |file: &str| {
        let (_, d) = variants.iter().find(|(f, _)| *f == file).unwrap();
        let d: Vec<(&str, String)> = d.iter().map(|(k, v)| (k.as_str(), v.clone())).collect();
        c.compile(file, &d).unwrap()
    };
    use fluidform::render::metaball::settings::RenderParams;
    use fluidform::render::metaball::GpuStats;
    use fluidform::sph::params::{GpuCollider, SphGpuParams};
    use fluidform::sph::store::LiveCount;
    // Every Rust field is listed (the list covers the whole struct: tested by count).
    type Fields = (usize, Vec<(&'static str, usize)>, &'static str);
    let cases: Vec<(&str, &str, Fields)> = vec![
        (
            "sph/integrate.comp",
            "SphParams",
            fields!(SphGpuParams;
            gravity, domain_min, domain_max, h, mass, rest_density, stiffness, viscosity,
            tension, tension_threshold, gamma, eos, clamp_negative, colliders, live, poly6,
            poly6_grad, spiky_grad, visc_lap, solver, min_iter, max_iter, density_target,
            divergence_target, proto_grad2, pbf_relaxation, scorr_k, scorr_n, scorr_inv_w,
            xsph, vorticity, list_max, kernel, kernel_k, min_neighbors, div_min_iter,
            dt_prev, cfl, dt_max, cfl_speed, wall_offset, pad1, pad2),
        ),
        (
            "sph/dfsph.comp",
            "SolveState",
            fields!(fluidform::sph::pressure::SolveState;
            gx, gy, gz, iter, done, arrived, pad0, pad1, density_iters, divergence_iters,
            density_err, divergence_err),
        ),
        (
            "sph/integrate.comp",
            "Collider",
            fields!(GpuCollider; a, b, vel),
        ),
        (
            "render/metaball/march.comp",
            "RenderParams",
            fields!(RenderParams;
            view_proj, inv_view_proj, view, proj, eye, sun, absorb, f0, base, tank_min, tank_max,
            width, height,
            n, refine, depth, max_steps, list_capacity, offscreen_end, sky_w, sky_h, debug, opaque,
            tile, tiles_x, rank_bits, pair_capacity, occupancy, pad0, pad1, pad2),
        ),
        (
            "render/metaball/march.comp",
            "RenderStats",
            fields!(GpuStats;
            abuffer_nodes, longest, overflow, offscreen_samples, sbuffer_fragments,
            budget_pixels, triangles, rays, steps, evals, candidates, pairs, pad),
        ),
        (
            "control/force.comp",
            "ControlParams",
            fields!(fluidform::control::force::ControlGpuParams;
            grid, dims, pressure, radius, spiky_grad, velocity, adaptive, low, high, up, down,
            inv_frame, group, live, attraction, reach, reach_cells, damping),
        ),
        (
            "emission/emit.comp",
            "EmitParams",
            fields!(fluidform::emission::emit::EmitGpuParams;
            n, sources, budget, seed, limit, dt, dtau, k, tau_lo, tau_hi, frame_dt, jitter),
        ),
        (
            "emission/uv_compact.comp",
            "Push",
            fields!(fluidform::emission::uv::UvPush; atlas, size),
        ),
        (
            "control/rays_emit.comp",
            "Push",
            fields!(fluidform::control::rays::RaysGpuPush;
            lo, dims, capacity, triangles, pixels, pad),
        ),
        (
            "character/skin.comp",
            "Joint",
            fields!(fluidform::character::pose::GpuJoint; m, real, dual, s),
        ),
        (
            "common/live_args.comp",
            "LiveCount",
            fields!(LiveCount;
            n, capacity, local_size, pad, groups, pad2),
        ),
        (
            "primitives/bounds.comp",
            "Push",
            fields!(fluidform::primitives::bounds::BoundsPush; n, pairs),
        ),
        (
            "primitives/gather.comp",
            "Push",
            fields!(fluidform::primitives::counting::GatherPush; n, count),
        ),
        (
            "primitives/count.comp",
            "Push",
            fields!(fluidform::primitives::counting::CountPush; n, cells),
        ),
        (
            "primitives/scan_chunk_reduce.comp",
            "Push",
            fields!(fluidform::primitives::scan::ScanPush; n, base, flags),
        ),
        (
            "primitives/oddeven.comp",
            "Push",
            fields!(fluidform::primitives::sort::SortPush; n, p, k, mode),
        ),
        (
            "sph/step_error.comp",
            "Push",
            fields!(fluidform::sph::errors::StepErrorPush; n, mode, step, rest_density),
        ),
        (
            "sph/cfl.comp",
            "Push",
            fields!(fluidform::sph::cfl::CflPush; n, parts, cfl, dt_max, speed, dt_prev),
        ),
        (
            "sph/constant_force.comp",
            "Push",
            fields!(fluidform::sph::hooks::ConstantForcePush; accel, n),
        ),
        (
            "sph/health.comp",
            "Health",
            fields!(fluidform::sph::health::GpuHealth; nonfinite, max_speed2, max_density, pad),
        ),
        (
            "primitives/nb_query.comp",
            "Push",
            fields!(fluidform::primitives::neighbors::NeighborPush;
            origin_cell, dims, radius, n, max_neighbors, pad),
        ),
        (
            "orbits/orbits.comp",
            "Push",
            fields!(fluidform::orbits::OrbitsPush; dt, strength, eps, n),
        ),
        (
            "render/surface/cells.comp",
            "Push",
            fields!(fluidform::render::surface::SurfacePush; origin, dims, fluid, look),
        ),
        (
            "render/points.vert",
            "Push",
            fields!(fluidform::render::points::PointsPush; view_proj, right, up),
        ),
        (
            "render/mesh.vert",
            "Push",
            fields!(fluidform::render::mesh::MeshPush; view_proj, eye, color),
        ),
        (
            "character/skin.comp",
            "Push",
            fields!(fluidform::character::skin::SkinPush; n, morphs),
        ),
        (
            "psys/draw.vert",
            "Push",
            fields!(fluidform::psys::gpu::DrawPush;
            view_proj, right, up, screen, offset, identity, pad),
        ),
        (
            "psys/emit.comp",
            "Push",
            fields!(fluidform::psys::gpu::StepPush;
            view_proj, source, births, seed, cur, head, dt, capacity, mode, cells, near, far,
            capsules, triangles),
        ),
        (
            "psys/emit.comp",
            "Counters",
            fields!(fluidform::psys::gpu::Counters;
            dead_count, alive, verts, update_args, draw_args, births, refused, died_life,
            died_view, died_distance, died_collision, overwritten, changed, spawned,
            spawn_refused, events_dropped, pad),
        ),
        (
            "psys/emit.comp",
            "SystemParams",
            fields!(fluidform::psys::gpu::SystemParams;
            emitter, extent, normal, offset_mean, offset_var, vel_mean, vel_var, color_mean,
            color_var, scalar_mean, scalar_var, gravity, wind, death, counts, counts2,
            size_keys, color_keys, opacity_keys, forces, colliders, boids, grid_dims),
        ),
    ];
    let checked: Vec<&str> = cases.iter().map(|c| c.2 .2).collect();
    for (file, glsl, (size, rust, _)) in cases {
        let got = member_offsets(&spv(file), glsl);
        let want: Vec<(String, u32)> = rust
            .iter()
            .map(|(n, o)| (n.to_string(), *o as u32))
            .collect();
        assert_eq!(got.len(), want.len(), "{glsl}: GLSL members {got:?}");
        for ((gn, go), (rn, ro)) in got.iter().zip(&want) {
            assert_eq!((gn, go), (rn, ro), "{glsl} in glsl/{file}");
        }
        assert!(size > 0);
    }
    // Every `#[repr(C)]` struct in src is among them.
    let mut missing = Vec::new();
    let mut stack = vec![std::path::PathBuf::from("src")];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
                continue;
            }
            let text = std::fs::read_to_string(&p).unwrap_or_default();
            let mut lines = text.lines();
            while let Some(l) = lines.next() {
                if l.trim() != "#[repr(C)]" {
                    continue;
                }
                let decl = lines.by_ref().find(|l| l.contains("struct ")).unwrap_or("");
                let name = decl.split("struct ").nth(1).unwrap_or("");
                let name = name
                    .split(|c: char| !c.is_alphanumeric() && c != '_')
                    .next();
                let name = name.unwrap_or("").to_string();
                if !checked.contains(&name.as_str()) {
                    missing.push(format!("{name} ({})", p.display()));
                }
            }
        }
    }
    assert!(
        missing.is_empty(),
        "repr(C) structs with no offset check: {missing:?}"
    );
}

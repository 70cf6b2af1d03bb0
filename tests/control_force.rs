//! The driving force (eq. 7) on the GPU against an f64 CPU reference: control densities
//! and the acceleration it adds, for every adaptive mode and a controlled group, and with
//! the deficit attraction and damping of the fidelity preset.
mod common;
use fluidform::character::Mesh;
use fluidform::character::Skinning;
use fluidform::control::force::{ControlForce, ControlSettings, Pose, ALL_GROUPS};
use fluidform::control::Adaptive;
use fluidform::gpu::Labels;
use fluidform::kinds::Neighbors;
use fluidform::scene::schema::{Ball, Block, Domain, Scene};
use fluidform::sph::hooks::SphHook;
use fluidform::sph::{FluidParams, SphSolver};
use glam::{Mat4, Vec3};

fn scene() -> Scene {
    Scene {
        name: "control test".into(),
        domain: Domain {
            min: [0.0; 3],
            max: [0.5, 0.5, 0.5],
        },
        fluid: FluidParams::default(),
        blocks: vec![Block {
            min: [0.05, 0.0, 0.05],
            max: [0.3, 0.15, 0.3],
            group: 0,
            color: [0.2, 0.5, 1.0],
            velocity: [0.0; 3],
        }],
        balls: vec![Ball {
            center: [0.3, 0.3, 0.3],
            radius: 0.06,
            group: 1,
            color: [1.0, 0.5, 0.1],
            velocity: [0.0; 3],
        }],
        colliders: vec![],
        camera: None,
        frames: 1,
        look: Default::default(),
        character: None,
        control: None,
        targets: vec![],
        timeline: vec![],
        emission: None,
        system: vec![],
        pool: None,
    }
}

/// Control particles on a lattice in a box over the pool, bound rigidly to one joint.
fn control_mesh(spacing: f32) -> Mesh {
    let mut m = Mesh {
        influence_sets: 1,
        ..Default::default()
    };
    for k in 0..6 {
        for j in 0..8 {
            for i in 0..6 {
                m.positions.push(
                    Vec3::new(0.1, 0.08, 0.1) + Vec3::new(i as f32, j as f32, k as f32) * spacing,
                );
            }
        }
    }
    let n = m.positions.len();
    m.normals = vec![Vec3::ZERO; n];
    m.joints = vec![[0; 8]; n];
    m.weights = vec![[1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]; n];
    m
}

fn poly6(r2: f64, h: f64) -> f64 {
    if r2 >= h * h {
        return 0.0;
    }
    315.0 / (64.0 * std::f64::consts::PI * h.powi(9)) * (h * h - r2).powi(3)
}

/// The adaptive control pressure's factor at control density ratio `fr` (thesis eq. 7).
fn adaptive_factor(settings: &ControlSettings, fr: f64) -> f64 {
    match settings.adaptive {
        Adaptive::Off => 1.0,
        Adaptive::On if fr < settings.low as f64 => settings.up as f64,
        Adaptive::On if fr > settings.high as f64 => settings.down as f64,
        Adaptive::On => 1.0,
        Adaptive::Smooth => {
            settings.up as f64
                * ((settings.high as f64 - fr) / (settings.high - settings.low) as f64)
                    .clamp(0.0, 1.0)
        }
    }
}

type Field = std::collections::HashMap<glam::I64Vec3, (glam::DVec3, f64)>;

/// The reference attraction and damping field at the control grid's cells (and the
/// grid's cells per side), from control particles at `positions` with densities `rho_ref`.
fn reference_field(
    positions: &[glam::Vec3],
    rho_ref: &[f64],
    settings: &ControlSettings,
    rho0: f64,
) -> (Field, i64) {
    // The attraction and damping field at the control grid's cell centres (cell h_c from
    // the domain's corner), each cell's control particles taken together at their
    // deficit-weighted centre. The control particles all move alike (compare's
    // `velocity`), so the character's velocity is theirs wherever the mask is 1.
    let (reach, hc) = (settings.reach as f64, settings.radius as f64);
    let dims = ((0.5 / hc).ceil()) as i64;
    let key = |p: glam::DVec3| {
        (p / hc)
            .floor()
            .as_i64vec3()
            .clamp(glam::I64Vec3::ZERO, glam::I64Vec3::splat(dims - 1))
    };
    let mut cells: std::collections::HashMap<glam::I64Vec3, (glam::DVec3, f64, glam::DVec3, f64)> =
        Default::default();
    for (c, &rho_j) in positions.iter().zip(rho_ref) {
        let e = cells.entry(key(c.as_dvec3())).or_default();
        let d = (1.0 - rho_j / rho0).max(0.0);
        e.0 += d * c.as_dvec3();
        e.1 += d;
        e.2 += c.as_dvec3();
        e.3 += 1.0;
    }
    let k = (reach / hc).ceil() as i64;
    let mut field = std::collections::HashMap::new();
    for z in 0..dims {
        for y in 0..dims {
            for x in 0..dims {
                let c0 = glam::I64Vec3::new(x, y, z);
                let xc = (c0.as_dvec3() + 0.5) * hc;
                let (mut pull, mut wall, mut wdef) = (glam::DVec3::ZERO, 0.0, 0.0);
                for (cell, (dc, dsum, csum, n)) in &cells {
                    if (*cell - c0).abs().max_element() > k {
                        continue;
                    }
                    if *dsum > 0.0 {
                        let d = *dc / *dsum - xc;
                        let r = d.length();
                        if r < reach {
                            let w = (1.0 - r / reach).powi(2) * dsum;
                            if r > 1e-6 {
                                pull += w / r * d;
                            }
                            wdef += w;
                        }
                    }
                    let r = (*csum / *n - xc).length();
                    if r < reach {
                        wall += (1.0 - r / reach).powi(2) * n;
                    }
                }
                let a = if wdef > 0.0 {
                    settings.attraction as f64 * pull / f64::max(wdef, 1.0)
                } else {
                    glam::DVec3::ZERO
                };
                field.insert(c0, (a, if wall > 0.0 { 1.0 } else { 0.0 }));
            }
        }
    }
    (field, dims)
}

/// Largest relative error of the control acceleration, and of the control densities, with
/// the control set moving at `velocity` (its pose a frame ahead shifted by velocity x dt).
/// Long because it is one GPU run and its f64 restatement side by side (the field and the
/// adaptive factor are apart).
fn compare(settings: ControlSettings, velocity: Vec3) -> (f64, f64) {
    let ctx = common::ctx();
    let sc = scene();
    let mut solver = SphSolver::new(&ctx, Neighbors::Grid, None).unwrap();
    let parts = sc.particles(1);
    let mesh = control_mesh(0.03);
    let mut control = ControlForce::new(
        &ctx,
        &solver,
        &mesh,
        1,
        settings.clone(),
        (sc.domain.min, sc.domain.max),
        (None, Skinning::Lbs, None),
    )
    .unwrap();
    let mut st = solver.state(&ctx, &sc, &parts).unwrap();
    let joints =
        fluidform::character::pose::gpu_joints(&[Mat4::IDENTITY], Skinning::Lbs, &|_| "j".into())
            .unwrap();
    let frame_dt = 1.0 / 30.0;
    let ahead = (velocity != Vec3::ZERO).then(|| {
        let m = Mat4::from_translation(velocity * frame_dt);
        let j = fluidform::character::pose::gpu_joints(&[m], Skinning::Lbs, &|_| "j".into());
        (j.unwrap(), Vec::new())
    });
    let mut accs = Vec::new();
    for with in [false, true] {
        if with {
            control.set_pose(Pose {
                joints: joints.clone(),
                weights: Vec::new(),
                frame_dt,
                next: ahead.clone(),
            });
        }
        ctx.one_shot(|cmd| {
            solver.record_params(&ctx, cmd, &st);
            solver.record_arrange(&ctx, cmd, &mut Labels, &mut st)?;
            solver.record_density(&ctx, cmd, &mut Labels, &st);
            solver.record_forces(&ctx, cmd, &mut Labels, &st);
            if with {
                control.record(&ctx, cmd, &mut Labels, &st)?;
            }
            Ok::<_, fluidform::Error>(())
        })
        .unwrap()
        .unwrap();
        accs.push(st.read(&ctx).unwrap());
    }
    let crho = control.densities(&ctx).unwrap();
    let (d0, d1) = (&accs[0], &accs[1]);
    // Each run sorts the particles anew, and the counting sort's order within a cell
    // follows its atomics: the run without control is matched to the run with it by
    // position (unchanged: no step integrates), not by slot.
    let key = |p: &[f32; 4]| [p[0].to_bits(), p[1].to_bits(), p[2].to_bits()];
    let slot0: std::collections::HashMap<_, usize> = d0
        .pos
        .iter()
        .enumerate()
        .map(|(i, p)| (key(p), i))
        .collect();
    let f = &sc.fluid;
    let (h, hc, m) = (f.h as f64, settings.radius as f64, f.mass as f64);
    let group = |a: &[f32; 4]| a[3].to_bits();
    let controlled = |a: &[f32; 4]| settings.group == ALL_GROUPS || group(a) == settings.group;
    let fluid: Vec<glam::DVec3> = d1
        .pos
        .iter()
        .map(|p| glam::DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
        .collect();
    // Control densities in f64 (the GPU holds them in control-grid order: compared as a
    // multiset).
    let rho_ref: Vec<f64> = mesh
        .positions
        .iter()
        .map(|c| {
            (0..fluid.len())
                .filter(|&i| controlled(&d1.attr[i]))
                .map(|i| m * poly6((fluid[i] - c.as_dvec3()).length_squared(), h))
                .sum()
        })
        .collect();
    let mut want = rho_ref.clone();
    let mut got: Vec<f64> = crho.iter().map(|&x| x as f64).collect();
    want.sort_by(f64::total_cmp);
    got.sort_by(f64::total_cmp);
    let rho0 = f.rest_density as f64;
    let err_rho = want
        .iter()
        .zip(&got)
        .map(|(w, g)| (w - g).abs() / rho0)
        .fold(0.0, f64::max);
    assert!(
        want.iter().any(|&r| r > 0.3 * rho0),
        "some control particles sit in fluid"
    );
    let (field, dims) = reference_field(&mesh.positions, &rho_ref, &settings, rho0);
    let factor = |r: f64| adaptive_factor(&settings, r / rho0);
    let spiky = -45.0 / (std::f64::consts::PI * hc.powi(6));
    let vc = velocity.as_dvec3();
    let (mut err, mut scale, mut touched) = (0.0f64, 0.0f64, 0);
    let mut rows = Vec::new();
    for (i, &x) in fluid.iter().enumerate() {
        let (mut fsum, mut wsum) = (glam::DVec3::ZERO, 0.0);
        let v = glam::DVec3::from_array([0, 1, 2].map(|k| d1.vel[i][k] as f64));
        if controlled(&d1.attr[i]) {
            for (c, &rho_j) in mesh.positions.iter().zip(&rho_ref) {
                let d = x - c.as_dvec3();
                let r = d.length();
                if r < hc && r > 0.0 {
                    fsum +=
                        settings.pressure as f64 * rho_j * factor(rho_j) * spiky * (hc - r).powi(2)
                            / r
                            * d;
                    wsum += (hc - r).powi(3);
                }
            }
        }
        let mut want = fsum / d1.rho_p[i][0] as f64;
        // The velocity term: towards the kernel-weighted mean control velocity (all vc).
        if wsum > 0.0 {
            want += settings.velocity as f64 * (vc - v);
        }
        // Deficit attraction and damping: the node field, trilinear between cell centres.
        if controlled(&d1.attr[i]) {
            let u = x / hc - 0.5;
            let hi = glam::I64Vec3::splat(dims - 1);
            let b = u.floor().as_i64vec3().clamp(glam::I64Vec3::ZERO, hi);
            let t = (u - b.as_dvec3()).clamp(glam::DVec3::ZERO, glam::DVec3::ONE);
            for n in 0..8 {
                let o = glam::I64Vec3::new(n & 1, (n >> 1) & 1, n >> 2);
                let c = (b + o).min(hi);
                let of = o.as_dvec3();
                let wt = (glam::DVec3::ONE - t) * (glam::DVec3::ONE - of) + t * of;
                let (pull, mask) = field[&c];
                want += wt.x * wt.y * wt.z * (pull + settings.damping as f64 * mask * (vc - v));
            }
        }
        let a0 = d0.acc[slot0[&key(&d1.pos[i])]];
        let got = glam::DVec3::from_array([0, 1, 2].map(|k| (d1.acc[i][k] - a0[k]) as f64));
        rows.push((want, got));
        scale = scale.max(want.length());
        touched += (want.length() > 0.0) as usize;
    }
    for (w, g) in &rows {
        err = err.max((*w - *g).length() / scale);
    }
    assert!(touched > 50, "{touched} fluid particles feel the control");
    control.destroy(&ctx);
    let mut s = solver;
    st.destroy(&ctx);
    s.destroy(&ctx);
    common::finish(&ctx);
    (err, err_rho)
}

fn settings(adaptive: Adaptive, group: u32) -> ControlSettings {
    ControlSettings {
        pressure: 2.0,
        radius: 0.06,
        adaptive,
        low: 0.8,
        high: 1.2,
        up: 2.0,
        down: 0.5,
        velocity: 0.0,
        attraction: 0.0,
        reach: 0.18,
        damping: 0.0,
        motion: fluidform::control::ControlMotion::Frames,
        group,
        every: 1,
    }
}

#[test]
fn deficit_attraction_and_damping_match_the_f64_reference() {
    for (a, g) in [(Adaptive::Off, ALL_GROUPS), (Adaptive::Smooth, 0)] {
        let s = ControlSettings {
            attraction: 20.0,
            reach: 0.1,
            damping: 3.0,
            ..settings(a, g)
        };
        let (err, err_rho) = compare(s, Vec3::ZERO);
        assert!(
            err_rho < 1e-4,
            "{a:?} group {g}: control density error {err_rho}"
        );
        assert!(
            err < 1e-3,
            "{a:?} group {g}: acceleration error {err} of the largest"
        );
    }
}

#[test]
fn driving_force_matches_the_f64_reference() {
    for (a, g) in [
        (Adaptive::Off, ALL_GROUPS),
        (Adaptive::On, ALL_GROUPS),
        (Adaptive::Smooth, ALL_GROUPS),
        (Adaptive::Off, 0),
    ] {
        let (err, err_rho) = compare(settings(a, g), Vec3::ZERO);
        assert!(
            err_rho < 1e-4,
            "{a:?} group {g}: control density error {err_rho} of rho0"
        );
        assert!(
            err < 1e-3,
            "{a:?} group {g}: acceleration error {err} of the largest"
        );
    }
}

/// The velocity term (K = 10/s) and the damping with the control set moving: the
/// kernel-weighted mean control velocity and the field's character velocity against the
/// f64 reference (eq. 7 off: its pull would dwarf the errors looked for).
#[test]
fn velocity_term_and_damping_with_a_moving_control_set_match_the_f64_reference() {
    let s = ControlSettings {
        pressure: 0.0,
        velocity: 10.0,
        attraction: 20.0,
        reach: 0.1,
        damping: 3.0,
        motion: fluidform::control::ControlMotion::Skin,
        ..settings(Adaptive::On, ALL_GROUPS)
    };
    let (err, err_rho) = compare(s, Vec3::new(0.6, -0.3, 0.9));
    assert!(err_rho < 1e-4, "control density error {err_rho} of rho0");
    assert!(err < 1e-3, "acceleration error {err} of the largest");
}

/// `--control-every 2`: the step after a refresh gathers each particle's stored eq. 7 sum
/// and mean control velocity through the step's permutation and applies them with its own
/// density and velocity. Here the second step sees the first step's particles in a random
/// order (its permutation says so) with the same positions, densities and velocities, so
/// each particle must get exactly the acceleration the refresh gave it.
#[test]
fn stored_control_sums_follow_the_particles_through_the_sort() {
    use fluidform::sph::solver::{ACC, ATTR, POS, RHO_P, VEL};
    use rand::seq::SliceRandom;
    use rand::SeedableRng;
    let ctx = common::ctx();
    let sc = scene();
    let mut solver = SphSolver::new(&ctx, Neighbors::Grid, None).unwrap();
    let parts = sc.particles(1);
    let s = ControlSettings {
        velocity: 5.0,
        attraction: 20.0,
        reach: 0.1,
        damping: 3.0,
        every: 2,
        ..settings(Adaptive::Smooth, ALL_GROUPS)
    };
    let mesh = control_mesh(0.03);
    let domain = (sc.domain.min, sc.domain.max);
    let mut control = ControlForce::new(
        &ctx,
        &solver,
        &mesh,
        1,
        s,
        domain,
        (None, Skinning::Lbs, None),
    )
    .unwrap();
    let mut st = solver.state(&ctx, &sc, &parts).unwrap();
    let joints =
        fluidform::character::pose::gpu_joints(&[Mat4::IDENTITY], Skinning::Lbs, &|_| "j".into())
            .unwrap();
    control.set_pose(Pose {
        joints,
        weights: Vec::new(),
        frame_dt: 1.0 / 30.0,
        next: None,
    });
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    let n = st.n as usize;
    // Fluid velocities for the velocity term and the damping to act on.
    let vel: Vec<[f32; 4]> = (0..n)
        .map(|i| [(i % 7) as f32 * 0.1 - 0.3, 0.2, (i % 5) as f32 * -0.05, 0.0])
        .collect();
    st.particles.upload(&ctx, VEL, &vel).unwrap();
    let zero = vec![[0f32; 4]; n];
    // Step 1: a refresh (the pose's first step), onto zero accelerations.
    ctx.one_shot(|cmd| {
        solver.record_params(&ctx, cmd, &st);
        solver.record_arrange(&ctx, cmd, &mut Labels, &mut st)?;
        solver.record_density(&ctx, cmd, &mut Labels, &st);
        Ok::<_, fluidform::Error>(())
    })
    .unwrap()
    .unwrap();
    st.particles.upload(&ctx, ACC, &zero).unwrap();
    ctx.one_shot(|cmd| control.record(&ctx, cmd, &mut Labels, &st))
        .unwrap()
        .unwrap();
    let a = st.read(&ctx).unwrap();
    let moved = a
        .acc
        .iter()
        .filter(|v| v[0].abs() + v[1].abs() + v[2].abs() > 1e-3);
    assert!(moved.count() > n / 4, "the control barely acts");
    // The same particles in a random order, and that order as the step's permutation.
    let mut perm: Vec<u32> = (0..n as u32).collect();
    perm.shuffle(&mut rng);
    let by = |v: &[[f32; 4]]| perm.iter().map(|&p| v[p as usize]).collect::<Vec<_>>();
    st.particles.upload(&ctx, POS, &by(&a.pos)).unwrap();
    st.particles.upload(&ctx, VEL, &by(&a.vel)).unwrap();
    st.particles.upload(&ctx, ATTR, &by(&a.attr)).unwrap();
    let rho: Vec<[f32; 2]> = perm.iter().map(|&p| a.rho_p[p as usize]).collect();
    st.particles.upload(&ctx, RHO_P, &rho).unwrap();
    st.particles.upload(&ctx, ACC, &zero).unwrap();
    ctx.upload(&mut st.nb.perm, 0, &perm).unwrap();
    // Step 2: no new pose, one step after the refresh: the stored sums.
    ctx.one_shot(|cmd| control.record(&ctx, cmd, &mut Labels, &st))
        .unwrap()
        .unwrap();
    let b = st.read(&ctx).unwrap();
    let largest = a.acc.iter().fold(0f32, |m, v| {
        m.max(v[0].abs().max(v[1].abs()).max(v[2].abs()))
    });
    for (i, &p) in perm.iter().enumerate() {
        let (want, got) = (a.acc[p as usize], b.acc[i]);
        for k in 0..3 {
            assert!(
                (want[k] - got[k]).abs() <= 1e-5 * largest,
                "particle {i} (was {p}): {got:?} against the refresh's {want:?}"
            );
        }
    }
    control.destroy(&ctx);
    st.destroy(&ctx);
    solver.destroy(&ctx);
    common::finish(&ctx);
}

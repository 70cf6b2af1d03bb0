//! Control of one particle group, with every solver.

use super::*;

#[test]
fn group_only_control_leaves_the_other_group_alone() {
    group_only_control(&[]);
}

/// The control force and groups with each incompressible solver: 6 fixed steps of 1.8 ms
/// per frame and 8 iterations per solve. A solve stops on the mean error over every
/// particle and CFL steps follow the fastest one, so group 0's control would change group
/// 1's steps and iterations, and its settling splash with them; fixed, group 1 must match
/// the free run as a body (see group_only_control).
#[test]
fn control_and_groups_work_with_every_solver() {
    for solver in ["pcisph", "dfsph", "pbf"] {
        eprintln!("solver {solver}");
        group_only_control(&[
            "--solver",
            solver,
            "--fluid",
            "dt=0.0018",
            "--fluid",
            "substeps=6",
            "--fluid",
            "min_iterations=8",
            "--fluid",
            "max_iterations=8",
            "--fluid",
            "pbf_iterations=8",
            "--fluid",
            "dfsph.divergence_min_iterations=8",
            // The thesis's kernel at h = 0.0457 m, the reach the groups' gap is checked
            // against (the cubic's 2 spacings reach farther).
            "--kernel",
            "muller",
            // Fixed steps, not the solvers' own CFL-limited ones.
            "--fluid",
            "pcisph.cfl=0",
            "--fluid",
            "dfsph.cfl=0",
            "--fluid",
            "pbf.cfl=0",
        ]);
    }
}

/// Control on group 0 raises it into the target and leaves group 1 where an uncontrolled
/// run leaves it. `solver`: extra switches (the solver and its step).
fn group_only_control(solver: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let free = scene(d, "free", "", 9e-4, 12);
    let held = scene(d, "held", "[control]\ngroup = 0", 9e-4, 12);
    let frames = 20;
    // Both at the default spacing (a controlled scene would otherwise choose its own
    // from the character: scene::fit).
    let spacing = fluidform::sph::params::FluidParams::default().spacing();
    let spacing_switch = format!("spacing={spacing}");
    let mut ex = vec![
        "--export",
        "ply",
        "--export-every",
        "19",
        "--fluid",
        &spacing_switch,
    ];
    ex.extend_from_slice(solver);
    let a = play(&free, &d.join("free"), frames, &ex);
    let b = play(&held, &d.join("held"), frames, &ex);
    let again = play(&free, &d.join("again"), frames, &ex);
    // The steps and the iterations of each solve are the same (they are fixed here).
    let steps = |name: &str| step_lines(&d.join(name));
    assert_eq!(steps("free"), steps("held"), "steps or iterations differ");
    let read = |r: &fluidform::run::RunResult| -> Vec<(u32, [f32; 3])> {
        let p = r.exports.last().expect("an export").clone();
        read_ply(&p)
    };
    // Every comparison below is of bodies (extents, centroid, spread): particle order
    // does not matter.
    let (pa, pb) = (read(&a), read(&b));
    let g1 = |v: &[(u32, [f32; 3])]| {
        v.iter()
            .filter(|x| x.0 == 1)
            .map(|x| x.1)
            .collect::<Vec<_>>()
    };
    let pc = read(&again);
    let (fa, fb, fc) = (g1(&pa), g1(&pb), g1(&pc));
    assert_eq!(fa.len(), fb.len());
    // The premise: the free groups never meet, never within the kernel's reach h (else
    // control of one rightly moves the other).
    let gap = extent_x(&pa, 1).0 - extent_x(&pa, 0).1;
    let h = fluidform::sph::params::FluidParams::default().h;
    assert!(gap > h, "the free groups came within {gap} m of each other");
    // The groups never meet, so group 1 feels group 0's control only through what is
    // global: the steps and iterations (fixed here) and the order of float sums. Group 0's
    // new cells shift group 1's sorted slots across workgroups, which reorders the
    // atomics of the counting sort within a cell and so the sums; the splash amplifies
    // that to centimetres for a few particles (seen: 4 mm with DFSPH here, 18 cm with
    // PCISPH on CI). What control must not change is group 1 as a body: its centroid and
    // spread stay within a tenth of a spacing of the free run's.
    let tol = 0.1 * spacing as f64;
    let ((ca, sa), (cb, sb), (cc, sc)) = (body(&fa), body(&fb), body(&fc));
    let shift = |u: &[f64], v: &[f64]| (0..3).map(|k| (u[k] - v[k]).abs()).fold(0.0, f64::max);
    eprintln!(
        "group 1: centroid moved {:.2e} m under control ({:.2e} m between free runs), spread {sa:.4} vs {sb:.4} m",
        shift(&ca, &cb),
        shift(&ca, &cc)
    );
    assert!(
        shift(&ca, &cc) <= tol && (sa - sc).abs() <= tol,
        "two free runs differ as bodies"
    );
    assert!(
        shift(&ca, &cb) <= tol,
        "group 1's centroid moved by {} m under group 0's control",
        shift(&ca, &cb)
    );
    assert!(
        (sa - sb).abs() <= tol,
        "group 1's spread changed from {sa} to {sb} m under group 0's control"
    );
    // Group 0 did feel the control.
    let g0 = |v: &[(u32, [f32; 3])]| {
        v.iter()
            .filter(|x| x.0 == 0)
            .map(|x| x.1[1])
            .fold(0.0, f32::max)
    };
    assert!(
        g0(&pb) > g0(&pa) + 0.02,
        "controlled group rose: {} vs {}",
        g0(&pb),
        g0(&pa)
    );
}

/// The smallest and largest x of group `g`'s points.
fn extent_x(v: &[(u32, [f32; 3])], g: u32) -> (f32, f32) {
    let x = v.iter().filter(|x| x.0 == g).map(|x| x.1[0]);
    (
        x.clone().fold(f32::MAX, f32::min),
        x.fold(f32::MIN, f32::max),
    )
}

/// Centroid and RMS spread of a body of points.
fn body(v: &[[f32; 3]]) -> (Vec<f64>, f64) {
    let n = v.len() as f64;
    let c: Vec<f64> = (0..3)
        .map(|k| v.iter().map(|x| x[k] as f64).sum::<f64>() / n)
        .collect();
    let spread = (v
        .iter()
        .map(|x| (0..3).map(|k| (x[k] as f64 - c[k]).powi(2)).sum::<f64>())
        .sum::<f64>()
        / n)
        .sqrt();
    (c, spread)
}

/// Each step's time step and iteration counts from a run's steps.csv.
fn step_lines(run: &Path) -> Vec<String> {
    std::fs::read_to_string(run.join("steps.csv"))
        .unwrap()
        .lines()
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            format!("{} {} {}", c[3], c[4], c[7])
        })
        .collect()
}

//! The barrier tracker (gpu::track): known command sequences and the barriers it places,
//! and the uses it reads from SPIR-V.
mod common;
use ash::vk;
use fluidform::gpu::access::buffer_uses;
use fluidform::gpu::sync;
use fluidform::gpu::track::{BufferUse, Tracker};
use vk::Handle;

fn buf(i: u64) -> vk::Buffer {
    vk::Buffer::from_raw(i)
}
fn read(i: u64) -> BufferUse {
    BufferUse::compute(buf(i), true, false)
}
fn write(i: u64) -> BufferUse {
    BufferUse::compute(buf(i), false, true)
}

#[test]
fn write_then_read_gets_one_barrier_reads_and_other_buffers_none() {
    let mut t = Tracker::default();
    assert!(t.before(&[write(1)], true).is_none(), "a first write");
    let (from, to) = t.before(&[read(1)], true).expect("write -> read");
    assert!(from.stage.contains(vk::PipelineStageFlags2::COMPUTE_SHADER));
    assert!(from.access.contains(vk::AccessFlags2::SHADER_STORAGE_WRITE));
    assert!(to.access.contains(vk::AccessFlags2::SHADER_STORAGE_READ));
    assert!(t.before(&[read(1)], true).is_none(), "read -> read");
    assert!(t.before(&[write(2)], true).is_none(), "another buffer");
    assert!(t.before(&[read(3)], true).is_none(), "never written");
    // Write after read waits for the read (an execution dependency).
    let (from, to) = t.before(&[write(1)], true).expect("read -> write");
    assert!(from.stage.contains(vk::PipelineStageFlags2::COMPUTE_SHADER));
    assert!(to.stage.contains(vk::PipelineStageFlags2::COMPUTE_SHADER));
    // A barrier orders the reads before it, not a read recorded after it.
    t.before(&[read(7)], true);
    t.barrier(sync::COMPUTE_READ, sync::COMPUTE_READ);
    t.before(&[read(7)], true);
    assert!(
        t.before(&[write(7)], true).is_some(),
        "read after the barrier -> write"
    );
    // Write after write, through a transfer: the fill waits for the dispatch's write.
    let (from, to) = t
        .before(&[BufferUse::transfer(buf(1), true)], true)
        .expect("write -> write");
    assert!(from.access.contains(vk::AccessFlags2::SHADER_STORAGE_WRITE));
    assert!(to.access.contains(vk::AccessFlags2::TRANSFER_WRITE));
    assert_eq!(t.placed, 4);
}

#[test]
fn a_hand_barrier_that_covers_the_hazard_leaves_nothing_to_place() {
    let mut t = Tracker::default();
    t.before(&[write(1), write(2)], true);
    t.barrier(sync::COMPUTE_WRITE, sync::COMPUTE_READ);
    assert!(t.before(&[read(1), read(2)], true).is_none());
    // A barrier to the wrong stage does not cover an indirect read or a copy.
    t.before(&[write(3)], true);
    t.barrier(sync::COMPUTE_WRITE, sync::COMPUTE_READ);
    assert!(t.before(&[BufferUse::indirect(buf(3))], true).is_some());
    t.before(&[write(4)], true);
    t.barrier(sync::COMPUTE_WRITE, sync::COMPUTE_READ);
    // Chained: compute -> compute, then compute -> transfer makes the write visible to a copy.
    t.barrier(sync::COMPUTE_READ, sync::TRANSFER_READ);
    assert!(t
        .before(&[BufferUse::transfer(buf(4), false)], true)
        .is_none());
    // ALL_COMMANDS covers everything.
    t.before(&[write(5)], true);
    t.barrier(sync::ALL, sync::ALL);
    assert!(t.before(&[BufferUse::indirect(buf(5))], true).is_none());
    assert_eq!(t.placed, 1);
    // Inside a rendering scope a hazard is counted, not placed.
    t.before(&[write(6)], true);
    assert!(t.before(&[read(6)], false).is_some());
    assert_eq!((t.placed, t.unplaced), (1, 1));
}

/// Uses come from what a shader does, not from how it declares a block.
fn fragment(i: u64, r: bool, w: bool) -> BufferUse {
    let (a, b) = (
        vk::AccessFlags2::SHADER_STORAGE_READ,
        vk::AccessFlags2::SHADER_STORAGE_WRITE,
    );
    BufferUse::at(
        buf(i),
        vk::PipelineStageFlags2::FRAGMENT_SHADER,
        (r, a),
        (w, b),
    )
}

#[test]
fn declared_draws_get_their_barrier_before_the_scope_and_undeclared_ones_count() {
    let mut t = Tracker::default();
    // A dispatch writes 1; a draw reads 1 and writes 2 (its uses declared before the scope).
    t.before(&[write(1)], true);
    let draw = [fragment(1, true, false), fragment(2, false, true)];
    let (from, to) = t.declare(&draw).expect("compute write -> fragment read");
    assert!(from.access.contains(vk::AccessFlags2::SHADER_STORAGE_WRITE));
    assert!(to.stage.contains(vk::PipelineStageFlags2::FRAGMENT_SHADER));
    // Inside the scope the draw finds its uses declared: no hazard, nothing unplaced.
    assert!(t.before(&draw, false).is_none());
    t.end_scope();
    assert_eq!((t.placed, t.unplaced), (1, 0));
    // After the scope: a dispatch reading 2 waits for the fragment write.
    let (from, _) = t
        .before(&[read(2)], true)
        .expect("fragment write -> compute read");
    assert!(from
        .stage
        .contains(vk::PipelineStageFlags2::FRAGMENT_SHADER));
    // A draw that was not declared: its hazard is counted, no barrier placed.
    t.before(&[write(3)], true);
    assert!(t.before(&[fragment(3, true, false)], false).is_some());
    t.end_scope();
    assert_eq!((t.placed, t.unplaced), (2, 1));
    // Declarations end with their scope: the next scope's draw of 1 is checked again.
    t.before(&[write(1)], true);
    assert!(t.before(&[fragment(1, true, false)], false).is_some());
    assert_eq!(t.unplaced, 2);
}

#[test]
fn host_reads_wait_for_the_writes_they_read() {
    let mut t = Tracker::default();
    t.before(&[BufferUse::transfer(buf(1), true)], true);
    let (from, to) = t
        .host_read(&[BufferUse::host(buf(1))])
        .expect("copy -> host");
    assert!(from.access.contains(vk::AccessFlags2::TRANSFER_WRITE));
    assert!(to.access.contains(vk::AccessFlags2::HOST_READ));
    assert!(to.stage.contains(vk::PipelineStageFlags2::HOST));
    // Read again: already visible to the host.
    assert!(t.host_read(&[BufferUse::host(buf(1))]).is_none());
    // A buffer this command buffer never touched: its writes came earlier, so every
    // device write is made visible to the host.
    let (from, _) = t
        .host_read(&[BufferUse::host(buf(9))])
        .expect("unknown -> a barrier");
    assert!(from.access.contains(vk::AccessFlags2::SHADER_STORAGE_WRITE));
    assert!(from.access.contains(vk::AccessFlags2::TRANSFER_WRITE));
}

#[test]
fn buffer_uses_follow_loads_stores_and_atomics() {
    let c = fluidform::gpu::shader::ShaderCompiler::new().unwrap();
    let src = r#"#version 450
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer A { float a[]; };          // read only (declared rw)
layout(std430, binding = 1) buffer B { float b[]; };          // written
layout(std430, binding = 2) buffer C { uint c[]; };           // atomic: read and write
layout(std430, binding = 3) readonly buffer D { float d[]; }; // unused
void main() {
    uint i = gl_GlobalInvocationID.x;
    b[i] = a[i] * 2.0;
    atomicAdd(c[0], 1u);
}
"#;
    let spv = c
        .compile_source("test/uses.comp", src, shaderc::ShaderKind::Compute, &[])
        .unwrap();
    let u = buffer_uses(&spv);
    let rw = |b: u32| u.get(&b).map(|u| (u.read, u.write));
    assert_eq!(rw(0), Some((true, false)));
    assert_eq!(rw(1), Some((false, true)));
    assert_eq!(rw(2), Some((true, true)));
    assert_eq!(rw(3), None);
}

/// One scene of each kind, with the validation layer's synchronization validation on: the
/// run is clean, and the tracker found no hazard in a draw it could not order (the barriers
/// before rendering scopes are still placed by hand).
#[test]
fn every_scene_kind_runs_clean_under_synchronization_validation() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [&[&str]; 10] = [
        &["--scene", "drop"],
        &["--scene", "drop", "--solver", "dfsph"],
        &["--scene", "character", "--control-every", "2"],
        &["--scene", "trail"],
        &["--scene", "fountain"],
        // Particle systems on a character (its mesh drawn, the body's capsules).
        &["--scene", "rain"],
        // Rays placement (its two draws) and the points view with the mesh.
        &[
            "--scene",
            "character",
            "--placement",
            "rays",
            "--render",
            "points",
            "--show-mesh",
            "shaded",
        ],
        &["--scene", "demo", "--list", "none"],
        &["--scene", "demo", "--list", "abuffer"],
        &["--scene", "demo", "--list", "sbuffer"],
    ];
    for (i, case) in cases.iter().enumerate() {
        let out = dir.path().join(i.to_string());
        let mut args = vec!["run", "--validation", "--quiet", "--frames", "2"];
        args.extend_from_slice(case);
        args.extend([
            "--width",
            "48",
            "--height",
            "48",
            "--out",
            out.to_str().unwrap(),
        ]);
        let o = common::fluidform(&args);
        assert!(o.status.success(), "{case:?}: {}", common::text(&o));
        let s = common::summary(&out);
        assert_eq!(s["validation"]["errors"], 0, "{case:?}");
        assert_eq!(s["barriers"]["unplaced"], 0, "{case:?}: {}", s["barriers"]);
        // The compute and transfer barriers are the tracker's (none remain by hand there).
        assert!(s["barriers"]["placed"].as_u64().unwrap() > 0, "{case:?}");
    }
}

//! Characters on ../shared/assets: loading, mesh checks, clip sampling, the CPU skinning
//! reference against hand-computed values, built-in shapes, and bad input.
mod common;
#[path = "character_files/compressed.rs"]
mod compressed;
#[path = "character_files/solid.rs"]
mod solid;
use common::asset;
use fluidform::character::anim::{clip_time, slerp};
use fluidform::character::Skinning;
use fluidform::character::{self, Channel, Character, Clip, Interp, Property};
use glam::{Mat4, Quat, Vec3, Vec4};

fn load(name: &str) -> Character {
    character::load(&asset(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn err_of(r: fluidform::Result<Character>) -> String {
    match r {
        Ok(_) => panic!("loaded, but an error was expected"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn cesium_man_is_a_closed_walking_character() {
    let ch = load("CesiumMan.glb");
    assert!(ch.skinned);
    assert_eq!(ch.skeleton.joints.len(), 19);
    assert_eq!(ch.clips.len(), 1);
    assert!(
        (ch.clips[0].duration - 2.0).abs() < 0.05,
        "{}",
        ch.clips[0].duration
    );
    assert_eq!(ch.clips[0].channels.len(), 57);
    assert_eq!(ch.mesh.triangles(), 4672);
    assert_eq!(ch.raw_vertices, 3273);
    assert_eq!(ch.check.welded_vertices, 2338);
    assert!(ch.check.closed(), "{:?}", ch.check);
    assert!(ch.check.signed_volume > 0.0);
    let (lo, hi) = ch.rest_bounds().unwrap();
    let height = hi.y - lo.y;
    assert!(
        (1.4..1.6).contains(&height),
        "height {height} (Y up after the root transform)"
    );
    assert!(!ch.normals_computed && !ch.mesh.uvs.is_empty());
    // Weights renormalised, heaviest first.
    for w in &ch.mesh.weights {
        assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-5);
        assert!(w.windows(2).all(|p| p[0] >= p[1]));
    }
}

#[test]
fn rigged_simple_is_a_closed_two_joint_cylinder() {
    let ch = load("RiggedSimple.glb");
    assert_eq!(ch.skeleton.joints.len(), 2);
    assert!(ch.check.closed(), "{:?}", ch.check);
    assert_eq!(ch.check.welded_vertices, 96);
    assert_eq!(ch.clips.len(), 1);
}

/// glTF tutorial, skinning chapter: jointMatrix(j) = globalTransform(joint j) *
/// inverseBindMatrix(j); v' = sum_j w_j jointMatrix(j) v. At t = 1 s the second joint
/// (under a node translated by (0, 1, 0)) is rotated 90 degrees about Z; both inverse bind
/// matrices translate by (-0.5, -1, 0).
#[test]
fn simple_skin_matches_the_tutorial_formula_by_hand() {
    let ch = load("SimpleSkin.gltf");
    assert!(!ch.check.closed());
    assert_eq!(ch.check.boundary_edges, 10);
    assert_eq!(ch.check.nonmanifold_edges, 0);
    let anim = character::Animator {
        clip: Some(ch.clip_index("0").unwrap()),
        looping: false,
        placement: Mat4::IDENTITY,
    };
    let mats = anim.joint_matrices(&ch, 1.0);
    let (pos, _) = ch.skinned_at(&mats, Skinning::Lbs).unwrap();
    // (vertex, expected): worked out on paper from the formula above.
    let expect = [
        (0, Vec3::new(-0.5, 0.0, 0.0)),
        (2, Vec3::new(-0.25, 0.5, 0.0)),
        (4, Vec3::new(-0.25, 0.75, 0.0)),
        (8, Vec3::new(-1.0, 0.5, 0.0)),
        (9, Vec3::new(-1.0, 1.5, 0.0)),
    ];
    for (v, e) in expect {
        assert!(
            (pos[v] - e).length() < 1e-5,
            "vertex {v}: {} vs {e}",
            pos[v]
        );
    }
    // Dual quaternions agree where one joint carries a vertex.
    let (dq, _) = ch.skinned_at(&mats, Skinning::Dqs).unwrap();
    for v in [0, 1, 8, 9] {
        assert!(
            (dq[v] - pos[v]).length() < 1e-5,
            "vertex {v}: {} vs {}",
            dq[v],
            pos[v]
        );
    }
    // A blended vertex: DQS keeps it at the joint's distance where LBS shrinks it.
    assert!((dq[4] - pos[4]).length() > 1e-3);
}

#[test]
fn obj_meshes_are_closed_with_the_known_volumes() {
    for (name, volume) in [("giraffe.obj", 0.267), ("spot.obj", 0.718)] {
        let ch = load(name);
        assert!(ch.check.closed(), "{name}: {:?}", ch.check);
        let v = ch.check.signed_volume;
        assert!(
            (v - volume).abs() <= 0.01 * volume,
            "{name}: volume {v} vs {volume}"
        );
        assert!(!ch.skinned && ch.normals_computed);
        ch.require_closed("the test").unwrap();
    }
}

/// Computed normals face outward: on a closed mesh of positive volume (so its faces point
/// out), every vertex normal agrees with the faces around it.
#[test]
fn computed_normals_face_outward() {
    for name in ["giraffe.obj", "spot.obj"] {
        let ch = load(name);
        let m = &ch.mesh;
        let (mut agree, mut total) = (0, 0);
        for t in m.indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
            let face = (b - a).cross(c - a);
            if face.length() < 1e-12 {
                continue;
            }
            let avg = (0..3).map(|k| m.normals[t[k] as usize]).sum::<Vec3>();
            total += 1;
            agree += (avg.dot(face) > 0.0) as usize;
        }
        assert!(
            agree as f64 >= 0.99 * total as f64,
            "{name}: {agree}/{total} agree"
        );
        assert!(m.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
    }
}

#[test]
fn an_inward_facing_closed_mesh_is_flipped_and_reported() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("inward.obj");
    // A unit cube with every face wound inward.
    let mut s = String::new();
    for z in [0, 1] {
        for y in [0, 1] {
            for x in [0, 1] {
                s += &format!("v {x} {y} {z}\n");
            }
        }
    }
    let faces = [
        [1, 3, 4, 2],
        [5, 6, 8, 7],
        [1, 2, 6, 5],
        [3, 7, 8, 4],
        [1, 5, 7, 3],
        [2, 4, 8, 6],
    ];
    for f in faces {
        // Reversed from the outward order.
        s += &format!("f {} {} {} {}\n", f[3], f[2], f[1], f[0]);
    }
    std::fs::write(&p, s).unwrap();
    let ch = character::load(p.to_str().unwrap()).unwrap();
    assert!(ch.check.closed());
    assert!(ch.flipped);
    assert!(
        (ch.check.signed_volume - 1.0).abs() < 1e-9,
        "{}",
        ch.check.signed_volume
    );
    assert!(
        ch.warnings.iter().any(|w| w.contains("inward")),
        "{:?}",
        ch.warnings
    );
    let v = fluidform::character::check::signed_volume(&ch.mesh.positions, &ch.mesh.indices);
    assert!(
        (v - 1.0).abs() < 1e-9,
        "the stored triangles face out after the flip: {v}"
    );
}

fn chan(property: Property, interp: Interp, times: &[f32], values: &[Vec4]) -> Channel {
    Channel {
        node: 0,
        property,
        interp,
        times: times.to_vec(),
        values: values.to_vec(),
    }
}

#[test]
fn samplers_match_hand_computed_values() {
    let x = |v: f32| Vec4::new(v, 0.0, 0.0, 0.0);
    let step = chan(
        Property::Translation,
        Interp::Step,
        &[0.0, 1.0, 2.0],
        &[x(1.0), x(5.0), x(9.0)],
    );
    assert_eq!(step.sample(0.5).x, 1.0);
    assert_eq!(step.sample(1.0).x, 5.0);
    assert_eq!(step.sample(1.99).x, 5.0);
    assert_eq!(step.sample(7.0).x, 9.0);
    assert_eq!(step.sample(-1.0).x, 1.0);
    let lin = chan(
        Property::Translation,
        Interp::Linear,
        &[0.0, 2.0],
        &[x(1.0), x(5.0)],
    );
    assert!((lin.sample(0.5).x - 2.0).abs() < 1e-6);
    // CUBICSPLINE over [0, 2] (dt = 2) at s = 0.5: h00 = 0.5, h10 = 0.125, h01 = 0.5,
    // h11 = -0.125, so p = 0.5 v0 + 0.25 b0 + 0.5 v1 - 0.25 a1 = 0.5 + 0.5 + 1.5 + 0.5.
    let cubic = chan(
        Property::Translation,
        Interp::CubicSpline,
        &[0.0, 2.0],
        &[x(0.0), x(1.0), x(2.0), x(-2.0), x(3.0), x(0.0)],
    );
    assert!(
        (cubic.sample(1.0).x - 3.0).abs() < 1e-6,
        "{}",
        cubic.sample(1.0).x
    );
    assert_eq!(cubic.sample(0.0).x, 1.0);
    assert_eq!(cubic.sample(2.0).x, 3.0);
}

#[test]
fn slerp_takes_the_short_path_and_clips_wrap() {
    let a = Vec4::from(Quat::IDENTITY);
    // 90 degrees about Y, stored with the opposite sign (the long way round if taken as is).
    let b = -Vec4::from(Quat::from_rotation_y(90f32.to_radians()));
    let rot = chan(Property::Rotation, Interp::Linear, &[0.0, 1.0], &[a, b]);
    let mid = Quat::from_vec4(rot.sample(0.5));
    let angle = mid.angle_between(Quat::from_rotation_y(45f32.to_radians()));
    assert!(
        angle < 1e-3,
        "half-way is 45 degrees about Y, off by {angle} rad"
    );
    let direct = Quat::from_vec4(slerp(a, b, 0.5));
    assert!(direct.angle_between(mid) < 1e-5);
    // Looping wraps, clamped holds the ends.
    assert!((clip_time(2.5, 2.0, true) - 0.5).abs() < 1e-6);
    assert!((clip_time(-0.5, 2.0, true) - 1.5).abs() < 1e-6);
    assert_eq!(clip_time(2.5, 2.0, false), 2.0);
    let ch = load("CesiumMan.glb");
    let clip: &Clip = &ch.clips[0];
    let d = clip.duration;
    let (p, q) = (
        clip.locals(&ch.skeleton, 0.3, true),
        clip.locals(&ch.skeleton, 0.3 + d, true),
    );
    for (u, v) in p.iter().zip(&q) {
        assert!((u.t - v.t).length() < 1e-5 && u.r.angle_between(v.r) < 1e-4);
    }
}

#[test]
fn built_in_shapes_are_closed_at_every_sampled_time() {
    let walker = character::load("builtin:walker").unwrap();
    assert!(walker.skeleton.joints.len() >= 10);
    assert_eq!(walker.clips.len(), 1);
    assert!(
        walker.check.closed() && walker.check.components == 1,
        "{:?}",
        walker.check
    );
    let rest = walker.check.signed_volume;
    let anim = character::Animator {
        clip: Some(0),
        looping: true,
        placement: Mat4::IDENTITY,
    };
    for k in 0..=10 {
        let t = k as f32 * 0.1;
        for method in [Skinning::Lbs, Skinning::Dqs] {
            let (p, _) = walker
                .skinned_at(&anim.joint_matrices(&walker, t), method)
                .unwrap();
            let c = character::check::check(&p, &walker.mesh.indices);
            assert!(c.closed(), "t = {t}: {:?}", c);
            let v = c.signed_volume;
            assert!(
                v > 0.8 * rest && v < 1.2 * rest,
                "t = {t} {method:?}: volume {v} vs rest {rest}"
            );
        }
    }
    let g = character::load("builtin:giraffe").unwrap();
    assert!(g.check.closed() && g.check.signed_volume > 0.0 && g.check.components == 1);
    let spacing = fluidform::sph::FluidParams::default().spacing();
    let thick = 2.0 * fluidform::character::procedural::giraffe_neck_radius() / spacing;
    assert!((2.0..=3.0).contains(&thick), "neck {thick} spacings thick");
    // The neck really is that thin: a slice across its middle spans about that width.
    let (a, b) = (Vec3::new(0.15, 0.52, 0.0), Vec3::new(0.30, 0.95, 0.0));
    let (mid, axis) = (0.5 * (a + b), (b - a).normalize());
    let near: Vec<f32> = g
        .mesh
        .positions
        .iter()
        .filter(|p| (**p - mid).dot(axis).abs() < 0.01)
        .map(|p| {
            let d = *p - mid;
            (d - axis * d.dot(axis)).length()
        })
        .collect();
    assert!(!near.is_empty());
    let r = near.iter().sum::<f32>() / near.len() as f32;
    assert!(
        (2.0 * r / spacing - thick).abs() < 0.3,
        "surface radius {r}"
    );
}

#[test]
fn external_buffers_and_data_uris_load_alike() {
    let text = std::fs::read_to_string(asset("SimpleSkin.gltf")).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let dir = tempfile::tempdir().unwrap();
    use base64_free::decode;
    for (i, b) in json["buffers"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .enumerate()
    {
        let uri = b["uri"].as_str().unwrap().to_string();
        let bytes = decode(uri.split(',').nth(1).unwrap());
        let name = format!("buffer {i}.bin");
        std::fs::write(dir.path().join(&name), bytes).unwrap();
        b["uri"] = serde_json::Value::String(format!("buffer%20{i}.bin"));
    }
    let p = dir.path().join("external.gltf");
    std::fs::write(&p, serde_json::to_string(&json).unwrap()).unwrap();
    let ext = character::load(p.to_str().unwrap()).unwrap();
    let emb = load("SimpleSkin.gltf");
    assert_eq!(ext.mesh.positions, emb.mesh.positions);
    assert_eq!(ext.mesh.weights, emb.mesh.weights);
    // A missing external buffer names the file.
    std::fs::remove_file(dir.path().join("buffer 1.bin")).unwrap();
    let e = err_of(character::load(p.to_str().unwrap()));
    assert!(
        e.contains("external.gltf") && e.contains("buffer%201.bin") && e.contains("missing"),
        "{e}"
    );
    assert_eq!(e.lines().count(), 1);
}

/// Minimal base64 decoding for the test (the standard alphabet, with padding).
mod base64_free {
    pub fn decode(s: &str) -> Vec<u8> {
        let val = |c: u8| match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            _ => 63,
        };
        let bytes: Vec<u8> = s.bytes().filter(|&c| c != b'=').collect();
        let mut out = Vec::new();
        for chunk in bytes.chunks(4) {
            let mut acc = 0u32;
            for (k, &c) in chunk.iter().enumerate() {
                acc |= (val(c) as u32) << (18 - 6 * k);
            }
            for k in 0..chunk.len() - 1 {
                out.push((acc >> (16 - 8 * k)) as u8);
            }
        }
        out
    }
}

/// A one-triangle glTF with its buffer as a data URI, for malformed variants.
fn triangle_gltf(mode: u32, extra_accessor: Option<serde_json::Value>) -> serde_json::Value {
    let mut buf = Vec::new();
    for v in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in v {
            buf.extend(c.to_le_bytes());
        }
    }
    // Sparse replacement: index 1 (u16) -> (2, 0, 0).
    buf.extend(1u16.to_le_bytes());
    buf.extend([0u8; 2]);
    for c in [2f32, 0.0, 0.0] {
        buf.extend(c.to_le_bytes());
    }
    let b64 = common::gltf::encode(&buf);
    let mut acc = serde_json::json!({
        "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
        "min": [0, 0, 0], "max": [2, 1, 0]
    });
    if let Some(extra) = extra_accessor {
        acc.as_object_mut()
            .unwrap()
            .extend(extra.as_object().unwrap().clone());
    }
    serde_json::json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}], "scene": 0,
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": mode}]}],
        "buffers": [{"byteLength": buf.len(), "uri": format!("data:application/octet-stream;base64,{b64}")}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 2},
            {"buffer": 0, "byteOffset": 40, "byteLength": 12}
        ],
        "accessors": [acc]
    })
}

fn write_json(dir: &std::path::Path, name: &str, v: &serde_json::Value) -> String {
    common::gltf::write(dir, name, v)
}

#[test]
fn sparse_accessors_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let sparse = serde_json::json!({"sparse": {
        "count": 1,
        "indices": {"bufferView": 1, "componentType": 5123},
        "values": {"bufferView": 2}
    }});
    let p = write_json(dir.path(), "sparse.gltf", &triangle_gltf(4, Some(sparse)));
    let ch = character::load(&p).unwrap();
    assert_eq!(ch.mesh.positions[1], Vec3::new(2.0, 0.0, 0.0));
    assert_eq!(ch.mesh.positions[2], Vec3::new(0.0, 1.0, 0.0));
    assert!(ch.normals_computed);
}

#[test]
fn bad_files_are_one_line_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let one_line = |e: &str, needles: &[&str]| {
        assert_eq!(e.lines().count(), 1, "{e}");
        for n in needles {
            assert!(e.contains(n), "'{e}' lacks '{n}'");
        }
    };
    // Missing.
    let e = err_of(character::load(d.join("nope.glb").to_str().unwrap()));
    one_line(&e, &["nope.glb", "No such file"]);
    // Truncated glb.
    let bytes = std::fs::read(asset("CesiumMan.glb")).unwrap();
    let p = d.join("cut.glb");
    std::fs::write(&p, &bytes[..1000]).unwrap();
    one_line(
        &err_of(character::load(p.to_str().unwrap())),
        &["cut.glb", "glTF"],
    );
    // Malformed JSON.
    let p = d.join("bad.gltf");
    std::fs::write(&p, "{\"asset\": {\"version\": ").unwrap();
    one_line(
        &err_of(character::load(p.to_str().unwrap())),
        &["bad.gltf", "glTF"],
    );
    // Lines, not triangles.
    let p = write_json(d, "lines.gltf", &triangle_gltf(1, None));
    one_line(
        &err_of(character::load(&p)),
        &["lines.gltf", "Lines", "triangle"],
    );
    // Accessors the spec does not allow: 2D positions, and normals short of the positions.
    let mut g = triangle_gltf(4, None);
    g["accessors"][0]["type"] = "VEC2".into();
    let p = write_json(d, "vec2.gltf", &g);
    one_line(
        &err_of(character::load(&p)),
        &["vec2.gltf", "Vec2", "does not allow"],
    );
    let mut g = triangle_gltf(4, None);
    g["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 1.into();
    g["accessors"].as_array_mut().unwrap().push(
        serde_json::json!({"bufferView": 0, "componentType": 5126, "count": 2, "type": "VEC3"}),
    );
    let p = write_json(d, "short.gltf", &g);
    one_line(
        &err_of(character::load(&p)),
        &["short.gltf", "2 entries for 3 vertices"],
    );
    // Malformed OBJ: a face past the vertices, and a number that is not one.
    let p = d.join("bad.obj");
    std::fs::write(&p, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap();
    one_line(&err_of(character::load(p.to_str().unwrap())), &["bad.obj"]);
    let p = d.join("text.obj");
    std::fs::write(&p, "v 0 zero 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    one_line(&err_of(character::load(p.to_str().unwrap())), &["text.obj"]);
    // Unknown format.
    one_line(
        &err_of(character::load("model.fbx")),
        &["model.fbx", ".glb"],
    );
    // An unknown animation lists the valid ones; a static mesh has no skin.
    let ch = load("CesiumMan.glb");
    let e = ch.clip_index("run").unwrap_err().to_string();
    one_line(&e, &["CesiumMan.glb", "'run'", "0 'animation0'"]);
    let e = load("giraffe.obj")
        .require_skin("animation")
        .unwrap_err()
        .to_string();
    one_line(&e, &["giraffe.obj", "no skin"]);
    // An open mesh is accepted, with its counts; a sheet has no inside and is refused
    // (and the GPU's ray placement still asks for a closed one).
    let sheet = load("SimpleSkin.gltf");
    assert!(
        sheet
            .warnings
            .iter()
            .any(|w| w.contains("open (10 boundary")),
        "{:?}",
        sheet.warnings
    );
    let rest = sheet.rest_positions().unwrap();
    let e = sheet.require_solid(&rest).unwrap_err().to_string();
    one_line(&e, &["SimpleSkin.gltf", "nowhere above 1/2", "10 boundary"]);
    let e = sheet.require_closed("--placement rays").unwrap_err();
    one_line(&e.to_string(), &["SimpleSkin.gltf", "not closed"]);
    let e = fluidform::control::placement::place(
        &sheet,
        &rest,
        fluidform::control::Placement::Random,
        0.05,
        1,
    );
    one_line(&e.unwrap_err().to_string(), &["no inside"]);
}

#[test]
fn more_joints_than_supported_are_refused_with_the_count() {
    let dir = tempfile::tempdir().unwrap();
    let n = fluidform::character::MAX_JOINTS + 1;
    let mut g = triangle_gltf(4, None);
    let mut nodes = vec![serde_json::json!({"mesh": 0, "skin": 0})];
    for _ in 0..n {
        nodes.push(serde_json::json!({}));
    }
    g["nodes"] = serde_json::Value::Array(nodes);
    g["skins"] = serde_json::json!([{"joints": (1..=n).collect::<Vec<_>>()}]);
    let p = write_json(dir.path(), "many.gltf", &g);
    let e = err_of(character::load(&p));
    assert!(
        e.contains("many.gltf") && e.contains(&n.to_string()) && e.contains("1024"),
        "{e}"
    );
    const { assert!(fluidform::character::MAX_JOINTS >= 256) };
}

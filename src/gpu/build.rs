//! Debian's libshaderc_combined.a does not contain glslang or SPIRV-Tools, so link
//! their static libraries (from glslang-dev and spirv-tools) after it.
use std::env;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

const STATIC_LIBS: &[&str] = &[
    "glslang",
    "MachineIndependent",
    "GenericCodeGen",
    "OSDependent",
    "OGLCompiler",
    "SPIRV",
    "HLSL",
    "glslang-default-resource-limits",
    "SPIRV-Tools-opt",
    "SPIRV-Tools",
];

fn main() {
    embed_glsl();
    println!("cargo:rerun-if-env-changed=SHADERC_LIB_DIR");
    println!("cargo:rerun-if-changed=build.rs");
    if env::var("CARGO_FEATURE_BUILD_FROM_SOURCE").is_ok() {
        return; // shaderc-sys builds and links everything itself
    }
    let dir = env::var("SHADERC_LIB_DIR").unwrap_or_else(|_| "/usr/lib/x86_64-linux-gnu".into());
    println!("cargo:rustc-link-search=native={dir}");
    for lib in STATIC_LIBS {
        println!("cargo:rustc-link-lib=static:-bundle={lib}");
    }
    println!("cargo:rustc-link-lib=dylib=stdc++");
}

/// Embed every file under glsl/ so the binary runs from anywhere (a GPU machine gets
/// only the binary); shaders are still compiled at run time, with the run's defines.
#[allow(dead_code)]
// The one GLSL header generated from Rust: the particle systems' codes, plain constants
// with no crate dependency, kept beside the systems that own them.
#[path = "../sim/psys/codes.rs"]
mod psys_codes;

fn embed_glsl() {
    let root = PathBuf::from(env::var("CARGO_MANIFEST_DIR").unwrap()).join("../../glsl");
    println!("cargo:rerun-if-changed={}", root.display());
    let mut files = Vec::new();
    walk(&root, &mut files);
    files.sort();
    let mut out = String::from("pub static GLSL_SOURCES: &[(&str, &str)] = &[\n");
    for f in &files {
        println!("cargo:rerun-if-changed={}", f.display());
        let rel = f
            .strip_prefix(&root)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        writeln!(
            out,
            "    ({rel:?}, include_str!({:?})),",
            f.display().to_string()
        )
        .unwrap();
    }
    // Headers generated from Rust (one source for codes shared with the shaders).
    let out_dir = PathBuf::from(env::var("OUT_DIR").unwrap());
    println!("cargo:rerun-if-changed=../sim/psys/codes.rs");
    let header = out_dir.join("psys_codes.glsl");
    std::fs::write(&header, psys_codes::glsl_header()).unwrap();
    writeln!(
        out,
        "    (\"generated/psys_codes.glsl\", include_str!({:?})),",
        header.display().to_string()
    )
    .unwrap();
    out.push_str("];\n");
    std::fs::write(
        PathBuf::from(env::var("OUT_DIR").unwrap()).join("glsl_sources.rs"),
        out,
    )
    .unwrap();
}

fn walk(dir: &Path, files: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            println!("cargo:rerun-if-changed={}", p.display());
            walk(&p, files);
        } else {
            files.push(p);
        }
    }
}

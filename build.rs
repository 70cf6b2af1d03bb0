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
    embed_commit();
    embed_font();
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
/// FLUIDFORM_COMMIT: the commit the binary is built from (experiments record it, so
/// results name the code that measured them, not the checkout they were run in).
fn embed_commit() {
    let git = |args: &[&str]| {
        std::process::Command::new("git")
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    let commit = match git(&["rev-parse", "--short", "HEAD"]) {
        Some(c) => match git(&["status", "--porcelain", "--untracked-files=no"]) {
            Some(s) if !s.is_empty() => format!("{c} with uncommitted changes"),
            _ => c,
        },
        None => "unknown (not built in a git checkout)".into(),
    };
    println!("cargo:rustc-env=FLUIDFORM_COMMIT={commit}");
    for p in [".git/HEAD", ".git/index"] {
        if Path::new(p).exists() {
            println!("cargo:rerun-if-changed={p}");
        }
    }
}

#[allow(dead_code)]
#[path = "src/psys/codes.rs"]
mod psys_codes;

fn embed_glsl() {
    let root = PathBuf::from(env::var("CARGO_MANIFEST_DIR").unwrap()).join("glsl");
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
    println!("cargo:rerun-if-changed=src/psys/codes.rs");
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

/// Embed DejaVu Sans (fonts-dejavu-core, from scripts/setup.sh) for the benchmark plots: a
/// GPU machine gets only the binary, and has no fonts. Absent here: an empty file, and the
/// plots read the font at run time.
fn embed_font() {
    let src = Path::new("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf");
    if src.exists() {
        println!("cargo:rerun-if-changed={}", src.display());
    }
    let out = PathBuf::from(env::var("OUT_DIR").expect("OUT_DIR")).join("font.ttf");
    let bytes = std::fs::read(src).unwrap_or_default();
    std::fs::write(&out, bytes).expect("write the embedded font");
}

//! The application's build facts: the commit it is built from and the plot font.
use std::env;
use std::path::{Path, PathBuf};

fn main() {
    embed_commit();
    embed_rustc();
    embed_font();
    println!("cargo:rerun-if-changed=build.rs");
}

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

/// FLUIDFORM_RUSTC: the compiler's version, part of every page's provenance.
fn embed_rustc() {
    let rustc = env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let v = std::process::Command::new(rustc)
        .arg("--version")
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=FLUIDFORM_RUSTC={v}");
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

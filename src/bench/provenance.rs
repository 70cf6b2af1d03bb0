//! Provenance of every number (fluidform-setup's `provenance`), with this binary's build
//! named: the commit and compiler the top crate's build script embeds.
pub use fluidform_setup::provenance::*;

/// Name this binary's build for every provenance written from now on.
pub fn init() {
    set_build(env!("FLUIDFORM_COMMIT"), env!("FLUIDFORM_RUSTC"));
}

/// Provenance now, of a measurement with `frames` timed and `warmup` warm-up frames.
pub fn measured(frames: u64, warmup: u64) -> Provenance {
    init();
    Provenance::now(Some(frames), Some(warmup))
}

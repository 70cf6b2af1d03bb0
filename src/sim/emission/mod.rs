//! Motion-trail emission (seed 002): SPH particles shed from a moving character's surface,
//! picked through a UV-space position buffer (RenderToUV).
mod kinds;
pub use kinds::EmitterKind;
pub mod emit;
pub mod emitter;
pub mod layout;
pub mod uv;

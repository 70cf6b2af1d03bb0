//! GPU particle systems (seed 003): emitters (point, box, sphere, disc) with every
//! attribute as mean + rand x variance and curves over life; Euler and Verlet steps that
//! keep state on the GPU, or the stateless closed form evaluated in the vertex shader;
//! forces, collisions, death; alive and dead lists compacted on the GPU with indirect
//! dispatch and draw; points, streaks and sprites sorted back to front.
mod kinds;
pub use kinds::{Integrator, SpriteMode};
pub mod character;
pub mod codes;
pub mod cpu;
pub mod frame;
pub mod gpu;
pub mod spec;
pub mod sprite;
pub mod system;

pub use gpu::{Counters, Passes};
pub use spec::SystemSpec;
pub use system::{FrameInfo, ParticleSystem};

/// SplitMix64: a well-mixed 64-bit hash (seeds of frames and textures).
pub fn hash64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

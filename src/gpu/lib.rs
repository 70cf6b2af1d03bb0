//! fluidform's GPU layer: the Vulkan core (context, devices, memory, shaders, pipelines,
//! timestamps, frames in flight, the headless render target and the window's swapchain and
//! overlay), the GPU primitives every algorithm shares (scan, sorts, bounds, the counting
//! grid and neighbour searches), the library's error type and the closed sets of choices
//! (`kinds`). Knows no fluid, character or command line; the only crate that calls ash.
pub mod access;
pub mod cache;
pub mod clock;
pub mod context;
pub mod device;
pub mod error;
pub mod frames;
pub mod graphics;
pub mod guard;
pub mod instance;
pub mod interface;
pub mod kinds;
pub mod memory;
pub mod overlay;
pub mod pass;
pub mod pipeline;
pub mod pipelines;
pub mod present;
pub mod primitives;
pub mod profiler;
pub mod shader;
pub mod sync;
pub mod target;
pub mod track;

pub use context::{Context, ContextOptions};
pub use device::{list_devices, DeviceInfo};
pub use frames::{FrameLoop, FrameWork, RecordOnly};
pub use graphics::{GraphicsDesc, GraphicsPipeline};
pub use guard::{Destroy, Guard};
pub use interface::{BindingDecl, BufferRange, Interface};
pub use memory::{Buffer, Image, MemoryLocation};
pub use pass::{ComputeDecl, GraphicsDecl, GraphicsStates, PassKey};
pub use pipeline::{ComputeDesc, ComputePipeline};
pub use profiler::{
    FrameTiming, Labels, Open, Profiler, Scope, ScopeDepth, ScopeKey, ScopeName, Scopes, FRAME,
};
pub use target::ColorTarget;
pub use track::Recorded;

pub use ash::vk;
pub use error::{Error, Result};
pub use inventory;

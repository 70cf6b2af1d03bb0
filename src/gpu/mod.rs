//! Vulkan core. Knows no algorithm: context, devices, memory, shaders, pipelines,
//! timestamps, frames in flight and the headless render target.
pub mod access;
pub mod context;
pub mod device;
pub mod frames;
pub mod guard;
pub mod instance;
pub mod interface;
pub mod memory;
pub mod overlay;
pub mod pipeline;
pub mod present;
pub mod profiler;
pub mod shader;
pub mod sync;
pub mod target;
pub mod track;

pub use context::{Context, ContextOptions};
pub use device::{list_devices, DeviceInfo};
pub use frames::{FrameLoop, FrameWork, RecordOnly};
pub use guard::{Destroy, Guard};
pub use interface::{BindingDecl, Interface, View};
pub use memory::{Buffer, Image, MemoryLocation};
pub use pipeline::{ComputeDesc, ComputePipeline, GraphicsDesc, GraphicsPipeline};
pub use profiler::{FrameTiming, Labels, Profiler, Scopes};
pub use target::ColorTarget;

//! The library's error type: every failure a user can cause or meet is one of these.
use ash::vk;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("{context}: {result}")]
    Vulkan { context: String, result: vk::Result },
    #[error("cannot load the Vulkan loader (libvulkan.so.1): {0}; run scripts/setup.sh")]
    Loader(String),
    #[error("no Vulkan device found{0}")]
    NoDevice(String),
    #[error("device '{device}' lacks {feature}, which fluidform needs")]
    MissingFeature { device: String, feature: String },
    #[error("{file}:{line}: {message}")]
    Shader {
        file: String,
        line: u32,
        message: String,
    },
    /// A pass's Rust interface disagrees with its shader (bindings or push constants).
    #[error("{0}")]
    Interface(String),
    #[error("GPU memory: {0}")]
    Memory(String),
    /// The simulation went unstable (NaN, infinity, or beyond what the step resolves).
    #[error("the simulation went unstable: {0}")]
    Unstable(String),
    #[error("invalid parameter: {0}")]
    Param(String),
    /// An internal invariant failed: a bug in fluidform, not the user's input.
    #[error("internal error (a bug, please report it): {0}")]
    Bug(String),
    #[error("{0}")]
    Unsupported(String),
    #[error("{path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    /// A character or mesh file that cannot be used as asked.
    #[error("{path}: {message}")]
    Model { path: String, message: String },
    #[error("image {path}: {message}")]
    Image { path: String, message: String },
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Attach context to a raw `vk::Result`.
pub trait VkContext<T> {
    fn ctx(self, context: &str) -> Result<T>;
}

impl<T> VkContext<T> for std::result::Result<T, vk::Result> {
    fn ctx(self, context: &str) -> Result<T> {
        self.map_err(|result| match result {
            vk::Result::ERROR_OUT_OF_DEVICE_MEMORY | vk::Result::ERROR_OUT_OF_HOST_MEMORY => {
                Error::Memory(format!("{context}: {result}"))
            }
            _ => Error::Vulkan {
                context: context.to_string(),
                result,
            },
        })
    }
}

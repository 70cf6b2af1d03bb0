//! A pass as one typed declaration: its name (debug labels, object names, its timestamp
//! scope), its shader file(s), its interface, the defines it always sets and a key type
//! whose values enumerate themselves, each with the defines it compiles with. A pass
//! builds its pipelines from its declaration, and every declaration registers itself, so
//! the shader test compiles exactly what the passes build: every declaration, every key
//! value (`registered()`). Declared with `compute_pass!` / `graphics_pass!` beside the pass.
use crate::error::Result;
use crate::graphics::{GraphicsDesc, GraphicsPipeline};
use crate::interface::Interface;
use crate::pipeline::{ComputeDesc, ComputePipeline};
use crate::Context;
use ash::vk;
use std::marker::PhantomData;

/// Owned defines: (name, value).
pub type Defines = Vec<(String, String)>;

/// What selects a pass's shader variant: a value type whose values enumerate themselves.
pub trait PassKey: Sized + 'static {
    /// Every value a pass can be built with.
    fn all() -> Vec<Self>;
    /// The defines this value compiles with (beyond the interface's and the declaration's).
    fn defines(&self) -> Defines;
    /// The values the shader test compiles: every value, unless the key's dimensions are
    /// independent enough that a covering subset reaches every line (said where overridden).
    fn compiled() -> Vec<Self> {
        Self::all()
    }
}

/// The key of a pass with one variant.
impl PassKey for () {
    fn all() -> Vec<Self> {
        vec![()]
    }
    fn defines(&self) -> Defines {
        Vec::new()
    }
}

/// `d` followed by a declaration's fixed defines.
fn with_fixed(mut d: Defines, fixed: &[(&str, &str)]) -> Defines {
    d.extend(fixed.iter().map(|(k, v)| (k.to_string(), v.to_string())));
    d
}

/// A compute pass of interface `I` and key `K`.
pub struct ComputeDecl<I, K = ()> {
    pub name: &'static str,
    pub shader: &'static str,
    /// Defines the pass always sets (one shader declared as two passes, say).
    pub fixed: &'static [(&'static str, &'static str)],
    marker: PhantomData<fn() -> (I, K)>,
}

impl<I: Interface, K: PassKey> ComputeDecl<I, K> {
    pub const fn new(
        name: &'static str,
        shader: &'static str,
        fixed: &'static [(&'static str, &'static str)],
    ) -> Self {
        Self {
            name,
            shader,
            fixed,
            marker: PhantomData,
        }
    }

    /// Its timestamp scope (and debug label), opened inside the caller's.
    pub const fn scope(&self) -> crate::ScopeName {
        crate::ScopeName::new(self.name)
    }

    /// The defines of `key`: the declaration's and the key's (the interface adds its own).
    pub fn defines(&self, key: &K) -> Defines {
        with_fixed(key.defines(), self.fixed)
    }

    /// The pipeline of `key` with workgroup size `local_size` and specialization
    /// constants 1.. = `spec`.
    pub fn pipeline(
        &self,
        ctx: &Context,
        key: &K,
        local_size: u32,
        spec: &[u32],
    ) -> Result<ComputePipeline<I>> {
        let d = self.defines(key);
        let refs = crate::pipeline::as_refs(&d);
        ComputePipeline::new(
            ctx,
            &ComputeDesc {
                name: self.name,
                shader: self.shader,
                defines: &refs,
                local_size,
                spec,
            },
        )
    }
}

/// A graphics pass's fixed-function states (the rest of `GraphicsDesc`).
#[derive(Clone, Copy)]
pub struct GraphicsStates {
    pub color_format: Option<vk::Format>,
    pub depth_format: Option<vk::Format>,
    pub blend: bool,
    pub topology: vk::PrimitiveTopology,
}

/// A graphics pass of interface `I` and key `K`: a vertex and a fragment shader.
pub struct GraphicsDecl<I, K = ()> {
    pub name: &'static str,
    pub vertex: &'static str,
    pub fragment: &'static str,
    pub fixed: &'static [(&'static str, &'static str)],
    marker: PhantomData<fn() -> (I, K)>,
}

impl<I: Interface, K: PassKey> GraphicsDecl<I, K> {
    pub const fn new(
        name: &'static str,
        vertex: &'static str,
        fragment: &'static str,
        fixed: &'static [(&'static str, &'static str)],
    ) -> Self {
        Self {
            name,
            vertex,
            fragment,
            fixed,
            marker: PhantomData,
        }
    }

    pub const fn scope(&self) -> crate::ScopeName {
        crate::ScopeName::new(self.name)
    }

    pub fn defines(&self, key: &K) -> Defines {
        with_fixed(key.defines(), self.fixed)
    }

    pub fn pipeline(
        &self,
        ctx: &Context,
        key: &K,
        states: GraphicsStates,
    ) -> Result<GraphicsPipeline<I>> {
        let d = self.defines(key);
        let refs = crate::pipeline::as_refs(&d);
        GraphicsPipeline::new(
            ctx,
            &GraphicsDesc {
                name: self.name,
                vertex: self.vertex,
                fragment: self.fragment,
                defines: &refs,
                color_format: states.color_format,
                depth_format: states.depth_format,
                blend: states.blend,
                topology: states.topology,
            },
        )
    }
}

/// A declaration as the shader test sees it: every (file, complete define set) it builds.
pub struct Registered {
    pub name: &'static str,
    pub variants: fn() -> Vec<(&'static str, Defines)>,
}

/// The interface's defines, then `own`.
pub fn complete<I: Interface>(own: Defines) -> Defines {
    let mut d = I::defines();
    d.extend(own);
    d
}

impl<I: Interface, K: PassKey> ComputeDecl<I, K> {
    /// Every (file, complete define set) of `K::compiled()`.
    pub fn variants(&self) -> Vec<(&'static str, Defines)> {
        let keys = K::compiled();
        keys.iter()
            .map(|k| (self.shader, complete::<I>(self.defines(k))))
            .collect()
    }
}

impl<I: Interface, K: PassKey> GraphicsDecl<I, K> {
    /// Both stages of every key of `K::compiled()`.
    pub fn variants(&self) -> Vec<(&'static str, Defines)> {
        let mut v = Vec::new();
        for k in K::compiled() {
            let d = complete::<I>(self.defines(&k));
            v.push((self.vertex, d.clone()));
            v.push((self.fragment, d));
        }
        v
    }
}

inventory::collect!(Registered);

/// Every declared pass of every crate linked in.
pub fn registered() -> impl Iterator<Item = &'static Registered> {
    inventory::iter::<Registered>.into_iter()
}

/// Declare a compute pass: `compute_pass!(pub NAME: Io, Key = "name", "dir/file.comp");`,
/// optionally followed by `, "DEFINE" = "value", ...` it always sets. It registers itself.
#[macro_export]
macro_rules! compute_pass {
    ($(#[$m:meta])* $vis:vis $id:ident: $io:ty, $key:ty = $name:literal, $shader:literal $(, $fk:literal = $fv:literal)* $(,)?) => {
        $(#[$m])*
        $vis const $id: $crate::pass::ComputeDecl<$io, $key> =
            $crate::pass::ComputeDecl::new($name, $shader, &[$(($fk, $fv)),*]);
        $crate::inventory::submit! {
            $crate::pass::Registered { name: $name, variants: || $id.variants() }
        }
    };
}

/// Declare a graphics pass: `graphics_pass!(pub NAME: Io, Key = "name", "a.vert", "a.frag");`.
#[macro_export]
macro_rules! graphics_pass {
    ($(#[$m:meta])* $vis:vis $id:ident: $io:ty, $key:ty = $name:literal, $vert:literal, $frag:literal $(, $fk:literal = $fv:literal)* $(,)?) => {
        $(#[$m])*
        $vis const $id: $crate::pass::GraphicsDecl<$io, $key> =
            $crate::pass::GraphicsDecl::new($name, $vert, $frag, &[$(($fk, $fv)),*]);
        $crate::inventory::submit! {
            $crate::pass::Registered { name: $name, variants: || $id.variants() }
        }
    };
}

/// Every (file, complete define set) the declared passes compile: the shader test's list.
pub fn compiled_files() -> Vec<(&'static str, Defines)> {
    registered().flat_map(|r| (r.variants)()).collect()
}

impl GraphicsStates {
    /// No attachments, no blending, triangles: a raster pass that only writes storage
    /// buffers.
    pub const STORAGE_ONLY: Self = Self {
        color_format: None,
        depth_format: None,
        blend: false,
        topology: vk::PrimitiveTopology::TRIANGLE_LIST,
    };
}

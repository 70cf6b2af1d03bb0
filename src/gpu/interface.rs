//! One checked GPU interface per pass. A pass declares its storage-buffer bindings once, in
//! Rust, with `gpu_interface!`: names and numbers become GLSL `#define`s (`PREFIX_B_NAME`),
//! buffers are bound through a struct with one named field per binding (so two buffers
//! cannot be swapped by position), and every pipeline's layout is checked at creation
//! against its SPIR-V: a binding the shader uses that Rust does not declare, one Rust
//! declares that no stage of the shader declares, a binding of another type or name, or a
//! push-constant struct of another size, is an error naming the pass and the binding.
use super::Buffer;
use crate::error::{Error, Result};
use ash::vk;
use std::collections::BTreeMap;

/// A byte range of a buffer bound as one binding (passes that split large arrays).
#[derive(Clone, Copy)]
pub struct BufferRange<'a> {
    pub buffer: &'a Buffer,
    pub offset: u64,
    pub range: u64,
}

impl BufferRange<'_> {
    pub fn info(&self) -> vk::DescriptorBufferInfo {
        vk::DescriptorBufferInfo {
            buffer: self.buffer.raw,
            offset: self.offset,
            range: self.range,
        }
    }
}

/// One storage-buffer binding of an interface.
#[derive(Clone, Copy, Debug)]
pub struct BindingDecl {
    /// Field name in Rust; the GLSL block's type name must match it ignoring case and `_`.
    pub name: &'static str,
    pub binding: u32,
}

/// A pass's shader interface: its bindings, push-constant type and buffer set.
pub trait Interface {
    /// Name used in errors.
    const NAME: &'static str;
    /// Prefix of the GLSL defines: binding `pos` becomes `PREFIX_B_POS`.
    const PREFIX: &'static str;
    const BINDINGS: &'static [BindingDecl];
    /// The push-constant struct (`()` for none).
    type Push: bytemuck::Pod;
    /// The buffers of one dispatch, one named field per binding.
    type Bufs<'a>;
    /// (binding, descriptor) in declaration order.
    fn buffers(b: &Self::Bufs<'_>) -> Vec<(u32, vk::DescriptorBufferInfo)>;

    /// `#define PREFIX_B_NAME N` for every binding.
    fn defines() -> Vec<(String, String)> {
        Self::BINDINGS
            .iter()
            .map(|b| {
                (
                    format!("{}_B_{}", Self::PREFIX, b.name.to_uppercase()),
                    b.binding.to_string(),
                )
            })
            .collect()
    }
}

/// Declare an interface: a marker type, its buffer struct and the `Interface` impl.
/// ```ignore
/// gpu_interface! {
///     /// glsl/primitives/gather.comp
///     pub Gather / GatherBufs: "GATHER", push u32 { perm = 0, src = 1, dst = 2 }
/// }
/// ```
#[macro_export]
macro_rules! gpu_interface {
    ($(#[$m:meta])* $vis:vis $name:ident / $bufs:ident : $prefix:literal, push $push:ty
        { $($field:ident = $n:literal),* $(,)? }) => {
        $(#[$m])*
        $vis struct $name;
        #[doc = concat!("Buffers of one `", stringify!($name), "` dispatch, by binding name.")]
        $vis struct $bufs<'a> { $(pub $field: &'a $crate::Buffer),* }
        impl $crate::Interface for $name {
            const NAME: &'static str = stringify!($name);
            const PREFIX: &'static str = $prefix;
            const BINDINGS: &'static [$crate::BindingDecl] = &[
                $($crate::BindingDecl { name: stringify!($field), binding: $n }),*
            ];
            type Push = $push;
            type Bufs<'a> = $bufs<'a>;
            fn buffers(b: &$bufs<'_>) -> Vec<(u32, $crate::vk::DescriptorBufferInfo)> {
                vec![$(($n, b.$field.info())),*]
            }
        }
    };
}

/// What one shader stage declares: bindings (number -> (descriptor type, block name)) and
/// the push-constant block's size.
pub struct Reflected {
    pub bindings: BTreeMap<u32, (u32, String)>,
    pub push_size: Option<u32>,
}

/// VkDescriptorType of a storage buffer, as reflection reports it.
const STORAGE_BUFFER: u32 = 7;

pub fn reflect(file: &str, spv: &[u32]) -> Result<Reflected> {
    let bad = |e: &dyn std::fmt::Display| Error::Shader {
        file: format!("glsl/{file}"),
        line: 0,
        message: format!("SPIR-V reflection failed: {e}"),
    };
    let words = without_source_text(spv);
    let r = rspirv_reflect::Reflection::new_from_spirv(bytemuck::cast_slice(&words))
        .map_err(|e| bad(&e))?;
    let sets = r.get_descriptor_sets().map_err(|e| bad(&e))?;
    let names = block_names(&words);
    let mut bindings = BTreeMap::new();
    for (set, list) in sets {
        if set != 0 {
            return Err(bad(&format!("descriptor set {set}: passes use set 0 only")));
        }
        for (binding, info) in list {
            let name = names.get(&binding).cloned().unwrap_or(info.name);
            bindings.insert(binding, (info.ty.0, name));
        }
    }
    let push_size = r
        .get_push_constant_range()
        .map_err(|e| bad(&e))?
        .map(|p| p.size);
    Ok(Reflected {
        bindings,
        push_size,
    })
}

/// The module without OpSource, OpSourceContinued, OpString and OpLine: the embedded
/// source text is split at byte boundaries that the reflection's UTF-8 decoding rejects,
/// and reflection needs only names and decorations.
fn without_source_text(spv: &[u32]) -> Vec<u32> {
    const DROP: [u32; 4] = [2, 3, 7, 8];
    let mut out = spv[..spv.len().min(5)].to_vec();
    for ins in instructions(spv) {
        if !DROP.contains(&(ins[0] & 0xffff)) {
            out.extend_from_slice(ins);
        }
    }
    out
}

/// The module's instructions after its 5-word header, each with its operands (the word
/// count is in the upper half of the first word).
pub(crate) fn instructions(spv: &[u32]) -> impl Iterator<Item = &[u32]> {
    let mut i = 5;
    std::iter::from_fn(move || {
        let first = *spv.get(i)?;
        let end = (i + (first >> 16).max(1) as usize).min(spv.len());
        let ins = &spv[i..end];
        i = end;
        Some(ins)
    })
}

/// A SPIR-V literal string (nul-terminated UTF-8 packed into words).
fn literal_string(words: &[u32]) -> String {
    let bytes: &[u8] = bytemuck::cast_slice(words);
    let end = bytes.iter().position(|b| *b == 0).unwrap_or(bytes.len());
    String::from_utf8_lossy(&bytes[..end]).into_owned()
}

/// Binding number -> type name of the block bound there (`buffer Pos { ... }` gives "Pos"):
/// variables of anonymous blocks carry no name of their own.
fn block_names(words: &[u32]) -> BTreeMap<u32, String> {
    const NAME: u32 = 5;
    const TYPE_POINTER: u32 = 32;
    const VARIABLE: u32 = 59;
    const DECORATE: u32 = 71;
    const BINDING: u32 = 33;
    let (mut names, mut pointee, mut var_type, mut binding) = (
        BTreeMap::new(),
        BTreeMap::new(),
        BTreeMap::new(),
        BTreeMap::new(),
    );
    for ins in instructions(words) {
        match (ins[0] & 0xffff, ins.len()) {
            (NAME, n) if n >= 3 => {
                names.insert(ins[1], literal_string(&ins[2..]));
            }
            (TYPE_POINTER, 4) => {
                pointee.insert(ins[1], ins[3]);
            }
            (VARIABLE, n) if n >= 4 => {
                var_type.insert(ins[2], ins[1]);
            }
            (DECORATE, 4) if ins[2] == BINDING => {
                binding.insert(ins[1], ins[3]);
            }
            _ => {}
        }
    }
    binding
        .into_iter()
        .filter_map(|(var, b)| {
            let block = pointee.get(var_type.get(&var)?)?;
            Some((b, names.get(block)?.clone()))
        })
        .collect()
}

fn plain(s: &str) -> String {
    s.chars()
        .filter(|c| *c != '_')
        .flat_map(|c| c.to_lowercase())
        .collect()
}

/// Check one pipeline's stages (file, reflection) against the Rust declaration.
pub fn check(
    pass: &str,
    stages: &[(&str, &Reflected)],
    decls: &[BindingDecl],
    push_size: usize,
) -> Result<()> {
    let err = |m: String| Err(Error::Interface(format!("pass '{pass}': {m}")));
    let mut seen = vec![false; decls.len()];
    for (file, r) in stages {
        for (binding, (ty, name)) in &r.bindings {
            let Some(i) = decls.iter().position(|d| d.binding == *binding) else {
                return err(format!(
                    "glsl/{file} uses binding {binding} ('{name}') that the Rust interface does not declare"
                ));
            };
            let d = decls[i];
            if *ty != STORAGE_BUFFER {
                return err(format!(
                    "binding {binding} ('{}') is a storage buffer in Rust but descriptor type {ty} in glsl/{file}",
                    d.name
                ));
            }
            if !name.is_empty() && plain(name) != plain(d.name) {
                return err(format!(
                    "binding {binding} is '{}' in Rust but block '{name}' in glsl/{file}",
                    d.name
                ));
            }
            seen[i] = true;
        }
        // A stage may leave the push block out; one that declares it must match.
        if let Some(shader_push) = r.push_size {
            if shader_push as usize != push_size {
                return err(format!(
                    "push constants are {push_size} bytes in Rust but {shader_push} in glsl/{file}"
                ));
            }
        }
    }
    if push_size > 0 && stages.iter().all(|(_, r)| r.push_size.is_none()) {
        return err(format!(
            "push constants are {push_size} bytes in Rust but no stage declares a push block"
        ));
    }
    if let Some(i) = seen.iter().position(|s| !s) {
        let files: Vec<&str> = stages.iter().map(|(f, _)| *f).collect();
        return err(format!(
            "binding {} ('{}') is declared in Rust but by no stage ({})",
            decls[i].binding,
            decls[i].name,
            files.join(", ")
        ));
    }
    Ok(())
}

/// `#define PREFIX_NAME value` for each (name, value) of an enum shared with GLSL, so the
/// shader compares against the Rust values (`#if LIST == LIST_SBUFFER`).
pub fn enum_defines(prefix: &str, values: &[(&str, u32)]) -> Vec<(String, String)> {
    values
        .iter()
        .map(|(n, v)| {
            (
                format!("{prefix}_{}", n.to_uppercase().replace('-', "_")),
                v.to_string(),
            )
        })
        .collect()
}

/// (member name, byte offset) of the struct type `name` in a SPIR-V module, as the GLSL
/// compiler laid it out: the field-offset check of Rust mirrors of GPU structs.
pub fn member_offsets(spv: &[u32], name: &str) -> Vec<(String, u32)> {
    const NAME: u32 = 5;
    let ins: Vec<&[u32]> = instructions(spv).collect();
    // The optimizer may copy a struct into a function-local type of the same name with no
    // layout: take the one that carries offsets.
    ins.iter()
        .filter(|w| w[0] & 0xffff == NAME && w.len() >= 3 && literal_string(&w[2..]) == name)
        .map(|w| layout_of(&ins, w[1]))
        .find(|l| !l.is_empty())
        .unwrap_or_default()
}

fn layout_of(ins: &[&[u32]], id: u32) -> Vec<(String, u32)> {
    const MEMBER_NAME: u32 = 6;
    const MEMBER_DECORATE: u32 = 72;
    const OFFSET: u32 = 35;
    let mut names = BTreeMap::new();
    let mut offsets = BTreeMap::new();
    for w in ins {
        match w[0] & 0xffff {
            MEMBER_NAME if w.len() >= 4 && w[1] == id => {
                names.insert(w[2], literal_string(&w[3..]));
            }
            MEMBER_DECORATE if w.len() >= 5 && w[1] == id && w[3] == OFFSET => {
                offsets.insert(w[2], w[4]);
            }
            _ => {}
        }
    }
    names
        .into_iter()
        .filter_map(|(m, n)| Some((n, *offsets.get(&m)?)))
        .collect()
}

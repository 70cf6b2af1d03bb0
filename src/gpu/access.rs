//! What a shader does with each storage buffer it binds, read from its SPIR-V: loads and
//! atomics read, stores and atomics write, through any access chain rooted at the
//! binding's variable. A block declared `buffer` that a shader only loads from counts as
//! read, so the barrier tracker (`gpu::track`) orders by use, not by declaration.
use std::collections::BTreeMap;

/// Whether a stage reads and writes one binding.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Use {
    pub read: bool,
    pub write: bool,
}

const VARIABLE: u32 = 59;
const LOAD: u32 = 61;
const STORE: u32 = 62;
const COPY_MEMORY: u32 = 63;
const ACCESS_CHAIN: u32 = 65;
const IN_BOUNDS_ACCESS_CHAIN: u32 = 66;
const PTR_ACCESS_CHAIN: u32 = 67;
const DECORATE: u32 = 71;
const COPY_OBJECT: u32 = 83;
const BINDING: u32 = 33;
const ATOMIC_STORE: u32 = 228;
/// OpAtomicLoad (227), then the read-modify-writes up to OpAtomicXor (242), with 228 the
/// store; the float atomics of extensions.
fn atomic_rmw(op: u32) -> bool {
    (229..=242).contains(&op) || matches!(op, 5614 | 5615 | 6035)
}

/// Binding number -> its use by the module (bindings the module never touches are absent).
pub fn buffer_uses(spv: &[u32]) -> BTreeMap<u32, Use> {
    let ins: Vec<&[u32]> = super::interface::instructions(spv).collect();
    // Result id -> the pointer it was derived from (chains and copies), and variable -> binding.
    let mut base = BTreeMap::new();
    let mut binding = BTreeMap::new();
    let mut variables = std::collections::BTreeSet::new();
    for w in &ins {
        match (w[0] & 0xffff, w.len()) {
            (ACCESS_CHAIN | IN_BOUNDS_ACCESS_CHAIN | PTR_ACCESS_CHAIN | COPY_OBJECT, n)
                if n >= 4 =>
            {
                base.insert(w[2], w[3]);
            }
            (VARIABLE, n) if n >= 4 => {
                variables.insert(w[2]);
            }
            (DECORATE, 4) if w[2] == BINDING => {
                binding.insert(w[1], w[3]);
            }
            _ => {}
        }
    }
    let root = |mut id: u32| {
        // (Chains are acyclic; the bound guards against a malformed module.)
        for _ in 0..64 {
            match base.get(&id) {
                Some(&b) => id = b,
                None => break,
            }
        }
        binding
            .get(&id)
            .copied()
            .filter(|_| variables.contains(&id))
    };
    let mut uses: BTreeMap<u32, Use> = BTreeMap::new();
    let mut mark = |ptr: u32, read: bool, write: bool| {
        if let Some(b) = root(ptr) {
            let u = uses.entry(b).or_default();
            u.read |= read;
            u.write |= write;
        }
    };
    for w in &ins {
        let op = w[0] & 0xffff;
        match op {
            LOAD if w.len() >= 4 => mark(w[3], true, false),
            227 if w.len() >= 4 => mark(w[3], true, false),
            STORE | ATOMIC_STORE if w.len() >= 3 => mark(w[1], false, true),
            COPY_MEMORY if w.len() >= 3 => {
                mark(w[1], false, true);
                mark(w[2], true, false);
            }
            _ if atomic_rmw(op) && w.len() >= 4 => mark(w[3], true, true),
            _ => {}
        }
    }
    uses
}

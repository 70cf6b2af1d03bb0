//! Pipelines keyed by what builds them: the interface, the shader files, the complete
//! defines, and the workgroup size and specialization constants (or a raster pass's
//! fixed-function states). Passes, or two renderers of one configuration, that ask for
//! one key share one Vulkan pipeline and its layouts; the last holder's `destroy` destroys
//! them. Creation goes through the driver's pipeline cache, kept between processes
//! (cache.rs).
use super::access::Use;
use ash::vk;
use std::collections::{BTreeMap, HashMap};
use std::sync::Mutex;

/// What a pipeline is built from.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct PipelineKey {
    pub interface: &'static str,
    pub shaders: Vec<String>,
    /// Sorted: the same set in any order is the same pipeline.
    pub defines: Vec<(String, String)>,
    /// Compute: workgroup size, then the specialization constants. Raster: colour and
    /// depth formats, blending and topology.
    pub fixed: Vec<i64>,
}

impl PipelineKey {
    pub fn new(
        interface: &'static str,
        shaders: &[&str],
        defines: &[(String, String)],
        fixed: Vec<i64>,
    ) -> Self {
        let mut defines = defines.to_vec();
        defines.sort();
        Self {
            interface,
            shaders: shaders.iter().map(|s| s.to_string()).collect(),
            defines,
            fixed,
        }
    }
}

/// A built pipeline as its holders see it.
#[derive(Clone)]
pub struct Built {
    pub pipeline: vk::Pipeline,
    pub layout: vk::PipelineLayout,
    pub set_layout: vk::DescriptorSetLayout,
    /// Per stage, what the SPIR-V does with each binding.
    pub uses: Vec<(vk::PipelineStageFlags2, BTreeMap<u32, Use>)>,
}

struct Held {
    built: Built,
    holders: u32,
}

/// The context's keyed pipelines.
#[derive(Default)]
pub struct Pipelines {
    held: Mutex<(
        HashMap<PipelineKey, Held>,
        HashMap<vk::Pipeline, PipelineKey>,
    )>,
}

impl Pipelines {
    /// The pipeline of `key`, one more holder counted, if it was built.
    pub fn acquire(&self, key: &PipelineKey) -> Option<Built> {
        let mut g = self.held.lock().unwrap();
        let h = g.0.get_mut(key)?;
        h.holders += 1;
        Some(h.built.clone())
    }

    /// Keep a newly built pipeline under `key`, with its first holder.
    pub fn insert(&self, key: PipelineKey, built: Built) {
        let mut g = self.held.lock().unwrap();
        g.1.insert(built.pipeline, key.clone());
        g.0.insert(key, Held { built, holders: 1 });
    }

    /// One holder fewer of `pipeline`: true when it was the last (the caller destroys it),
    /// and for a pipeline never kept here.
    pub fn release(&self, pipeline: vk::Pipeline) -> bool {
        let mut g = self.held.lock().unwrap();
        let Some(key) = g.1.get(&pipeline).cloned() else {
            return true;
        };
        let h = g.0.get_mut(&key).expect("a held pipeline has its key");
        h.holders -= 1;
        if h.holders > 0 {
            return false;
        }
        g.0.remove(&key);
        g.1.remove(&pipeline);
        true
    }

    /// Pipelines held now.
    pub fn len(&self) -> usize {
        self.held.lock().unwrap().0.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

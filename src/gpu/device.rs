//! Physical-device listing, the feature check, and the choice by index, name or type.
pub use super::instance::version_string;
use super::instance::{create_instance, load_entry};
use crate::error::{Error, Result, VkContext};
use ash::vk;
use serde::Serialize;

/// What fluidform knows about a physical device.
#[derive(Clone, Debug, Serialize)]
pub struct DeviceInfo {
    pub index: usize,
    pub name: String,
    #[serde(rename = "type")]
    pub kind: String,
    pub driver: String,
    pub api: String,
    pub vendor_id: u32,
    pub device_id: u32,
    pub timestamp_period_ns: f32,
    pub timestamp_valid_bits: u32,
    pub subgroup_size: u32,
    /// Subgroup arithmetic in compute shaders (the scan's fast path).
    pub subgroup_arithmetic: bool,
    /// Subgroup ballots and shuffles in compute shaders (rays marched by several lanes).
    pub subgroup_shuffle: bool,
    pub subgroup_size_control: bool,
    pub max_storage_buffer_range: u64,
    pub max_shared_memory: u32,
    /// Bytes of the device-local memory heaps (on lavapipe: the host's memory).
    pub device_local_bytes: u64,
    /// Loop iterations llvmpipe lets one batch of invocations run before it stops their
    /// loops (hang protection, LP_MAX_TGSI_LOOP_ITERATIONS); None on other drivers.
    pub loop_budget: Option<u32>,
    /// Everything fluidform needs that this device lacks; empty when usable.
    pub missing: Vec<String>,
    #[serde(skip)]
    pub queue_family: Option<u32>,
    #[serde(skip)]
    pub vertex_stores: bool,
    #[serde(skip)]
    pub int64: bool,
    /// Points larger than one pixel (largePoints) up to this size.
    #[serde(skip)]
    pub max_point_size: f32,
    #[serde(skip)]
    pub type_rank: u32,
    /// VK_EXT_calibrated_timestamps: GPU timestamps on the CPU's clock (traces).
    #[serde(skip)]
    pub calibrated: bool,
}

impl DeviceInfo {
    /// A filesystem-friendly name for `results/<slug>/`.
    pub fn slug(&self) -> String {
        let mut s = String::new();
        for c in self.name.to_lowercase().chars() {
            if c.is_ascii_alphanumeric() {
                s.push(c);
            } else if !s.ends_with('-') {
                s.push('-');
            }
        }
        // "llvmpipe (LLVM 15.0.6, 256 bits)" -> "llvmpipe-llvm-15-0-6-256-bits"
        s.trim_matches('-').to_string()
    }
}

/// Read properties and check requirements of one device. Long because it fills
/// `DeviceInfo` field by field from the property and feature chains.
pub fn describe(instance: &ash::Instance, pd: vk::PhysicalDevice, index: usize) -> DeviceInfo {
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut subgroup = vk::PhysicalDeviceSubgroupProperties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default()
        .push_next(&mut driver)
        .push_next(&mut subgroup);
    unsafe { instance.get_physical_device_properties2(pd, &mut props2) };
    let props = props2.properties;
    let mut f12 = vk::PhysicalDeviceVulkan12Features::default();
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut feats2 = vk::PhysicalDeviceFeatures2::default()
        .push_next(&mut f12)
        .push_next(&mut f13);
    unsafe { instance.get_physical_device_features2(pd, &mut feats2) };
    let f = feats2.features;
    let exts = unsafe { instance.enumerate_device_extension_properties(pd) }.unwrap_or_default();
    let has_ext = |n: &std::ffi::CStr| exts.iter().any(|e| e.extension_name_as_c_str() == Ok(n));
    let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
    let want = vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE;
    let queue_family = families
        .iter()
        .position(|q| q.queue_flags.contains(want) && q.timestamp_valid_bits > 0)
        .map(|i| i as u32);
    let valid_bits = queue_family
        .map(|i| families[i as usize].timestamp_valid_bits)
        .unwrap_or(0);

    let push_descriptor = has_ext(ash::khr::push_descriptor::NAME);
    let missing = missing_features(&props, &f, &f12, &f13, push_descriptor, queue_family);
    let kind = match props.device_type {
        vk::PhysicalDeviceType::DISCRETE_GPU => ("discrete", 0),
        vk::PhysicalDeviceType::INTEGRATED_GPU => ("integrated", 1),
        vk::PhysicalDeviceType::VIRTUAL_GPU => ("virtual", 2),
        vk::PhysicalDeviceType::CPU => ("cpu", 3),
        _ => ("other", 4),
    };
    let arith = subgroup
        .supported_operations
        .contains(vk::SubgroupFeatureFlags::ARITHMETIC | vk::SubgroupFeatureFlags::BALLOT)
        && subgroup
            .supported_stages
            .contains(vk::ShaderStageFlags::COMPUTE);
    let shuffle = subgroup
        .supported_operations
        .contains(vk::SubgroupFeatureFlags::BALLOT | vk::SubgroupFeatureFlags::SHUFFLE)
        && subgroup
            .supported_stages
            .contains(vk::ShaderStageFlags::COMPUTE);
    let cstr = |s: &[std::ffi::c_char]| {
        unsafe { std::ffi::CStr::from_ptr(s.as_ptr()) }
            .to_string_lossy()
            .into_owned()
    };
    let driver_name = cstr(&driver.driver_name);
    let driver_info = cstr(&driver.driver_info);
    let calibrated = has_ext(ash::ext::calibrated_timestamps::NAME);
    DeviceInfo {
        calibrated,
        index,
        name: cstr(&props.device_name),
        kind: kind.0.to_string(),
        driver: if driver_info.is_empty() {
            driver_name
        } else {
            format!("{driver_name} {driver_info}")
        },
        api: version_string(props.api_version),
        vendor_id: props.vendor_id,
        device_id: props.device_id,
        timestamp_period_ns: props.limits.timestamp_period,
        timestamp_valid_bits: valid_bits,
        subgroup_size: subgroup.subgroup_size,
        subgroup_arithmetic: arith,
        subgroup_shuffle: shuffle,
        subgroup_size_control: f13.subgroup_size_control == vk::TRUE
            && f13.compute_full_subgroups == vk::TRUE,
        max_storage_buffer_range: props.limits.max_storage_buffer_range as u64,
        max_shared_memory: props.limits.max_compute_shared_memory_size,
        device_local_bytes: {
            let m = unsafe { instance.get_physical_device_memory_properties(pd) };
            m.memory_heaps[..m.memory_heap_count as usize]
                .iter()
                .filter(|h| h.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL))
                .map(|h| h.size)
                .sum()
        },
        loop_budget: (driver.driver_id == vk::DriverId::MESA_LLVMPIPE).then_some(65535),
        missing,
        queue_family,
        vertex_stores: f.vertex_pipeline_stores_and_atomics == vk::TRUE,
        int64: f.shader_int64 == vk::TRUE,
        max_point_size: match f.large_points == vk::TRUE {
            true => props.limits.point_size_range[1],
            false => 1.0,
        },
        type_rank: kind.1,
    }
}

/// What fluidform needs that the device lacks, by the names the spec gives them.
fn missing_features(
    props: &vk::PhysicalDeviceProperties,
    f: &vk::PhysicalDeviceFeatures,
    f12: &vk::PhysicalDeviceVulkan12Features,
    f13: &vk::PhysicalDeviceVulkan13Features,
    push_descriptor: bool,
    queue_family: Option<u32>,
) -> Vec<String> {
    let mut missing = Vec::new();
    if props.api_version < vk::API_VERSION_1_3 {
        missing.push(format!(
            "Vulkan 1.3 (has {})",
            version_string(props.api_version)
        ));
    }
    if queue_family.is_none() {
        missing.push("a graphics+compute queue with timestamps (timestampValidBits > 0)".into());
    }
    if props.limits.timestamp_period <= 0.0 {
        missing.push("timestampPeriod > 0".into());
    }
    for (ok, name) in [
        (
            f.fragment_stores_and_atomics == vk::TRUE,
            "fragmentStoresAndAtomics",
        ),
        (f13.synchronization2 == vk::TRUE, "synchronization2"),
        (f13.dynamic_rendering == vk::TRUE, "dynamicRendering"),
        (f12.host_query_reset == vk::TRUE, "hostQueryReset"),
        (push_descriptor, "VK_KHR_push_descriptor"),
        (
            props.limits.max_compute_work_group_invocations >= 256,
            "maxComputeWorkGroupInvocations >= 256",
        ),
        (
            props.limits.max_compute_shared_memory_size >= 16384,
            "maxComputeSharedMemorySize >= 16384",
        ),
    ] {
        if !ok {
            missing.push(name.to_string());
        }
    }
    missing
}

fn enumerate(instance: &ash::Instance) -> Result<Vec<(vk::PhysicalDevice, DeviceInfo)>> {
    let pds = unsafe { instance.enumerate_physical_devices() }.ctx("list devices")?;
    Ok(pds
        .into_iter()
        .enumerate()
        .map(|(i, pd)| (pd, describe(instance, pd, i)))
        .collect())
}

/// Every Vulkan device with its properties (for `fluidform devices`).
pub fn list_devices() -> Result<Vec<DeviceInfo>> {
    let entry = load_entry()?;
    let (instance, _) = create_instance(&entry, false, &[])?;
    let r = enumerate(&instance);
    unsafe { instance.destroy_instance(None) };
    Ok(r?.into_iter().map(|(_, i)| i).collect())
}

/// Choose by index or name substring, else the best usable device
/// (discrete > integrated > virtual > CPU).
pub fn pick(
    instance: &ash::Instance,
    wanted: Option<&str>,
) -> Result<(vk::PhysicalDevice, DeviceInfo)> {
    let all = enumerate(instance)?;
    if all.is_empty() {
        return Err(Error::NoDevice(
            " (is a Vulkan driver installed? run scripts/setup.sh for Mesa lavapipe)".into(),
        ));
    }
    let names = || {
        all.iter()
            .map(|(_, i)| format!("{}: {}", i.index, i.name))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let chosen = match wanted {
        Some(w) => {
            let w = w.trim();
            let found = match w.parse::<usize>() {
                Ok(i) => all.get(i),
                Err(_) => {
                    let lw = w.to_lowercase();
                    all.iter()
                        .find(|(_, i)| i.name.to_lowercase().contains(&lw))
                }
            };
            found.ok_or_else(|| {
                Error::NoDevice(format!(" matching --device '{w}' (devices: {})", names()))
            })?
        }
        None => all
            .iter()
            .filter(|(_, i)| i.missing.is_empty())
            .min_by_key(|(_, i)| i.type_rank)
            .ok_or_else(|| {
                Error::NoDevice(format!(
                    " with every feature fluidform needs (devices: {}; see `fluidform devices`)",
                    names()
                ))
            })?,
    };
    let (pd, info) = chosen.clone();
    if let Some(m) = info.missing.first() {
        return Err(Error::MissingFeature {
            device: info.name.clone(),
            feature: m.clone(),
        });
    }
    Ok((pd, info))
}

/// `fluidform devices`: every device, its limits and whether fluidform can use it.
pub fn print_devices(json: bool) -> Result<()> {
    let list = list_devices()?;
    if json {
        let text = serde_json::to_string_pretty(&list)
            .map_err(|e| crate::Error::Param(format!("devices as JSON: {e}")))?;
        println!("{text}");
        return Ok(());
    }
    if list.is_empty() {
        return Err(crate::Error::Unsupported(
            "no Vulkan device found (run scripts/setup.sh for Mesa lavapipe)".into(),
        ));
    }
    for d in &list {
        println!("[{}] {} ({})", d.index, d.name, d.kind);
        println!("    driver: {}  api: {}", d.driver, d.api);
        println!(
            "    timestampPeriod: {} ns  timestampValidBits: {}",
            d.timestamp_period_ns, d.timestamp_valid_bits
        );
        println!(
            "    subgroup size: {}  subgroup arithmetic: {}  maxStorageBufferRange: {}",
            d.subgroup_size, d.subgroup_arithmetic, d.max_storage_buffer_range
        );
        if d.missing.is_empty() {
            println!("    fluidform: all required features present");
        } else {
            println!("    fluidform: UNUSABLE, missing {}", d.missing.join(", "));
        }
    }
    Ok(())
}

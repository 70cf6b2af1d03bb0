//! The device owner: instance (with optional Khronos validation), physical-device choice,
//! logical device, queue, allocator, shader compiler. The only GPU type that implements Drop
//! (beside the construction guards of gpu/guard.rs).
use super::device::{self, DeviceInfo};
use super::instance::{create_instance, load_entry};
use super::shader::ShaderCompiler;
use crate::error::{Error, Result, VkContext};
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use std::collections::BTreeMap;
use std::ffi::{c_void, CStr, CString};
use std::mem::ManuallyDrop;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Mutex;

/// How to open a device.
#[derive(Clone, Debug, Default)]
pub struct ContextOptions {
    /// Device index or case-insensitive name substring; None picks the best.
    pub device: Option<String>,
    /// Enable the Khronos validation layer and count its messages.
    pub validation: bool,
    /// The display a window will show frames on (`fluidform view`): enables the surface
    /// extensions it needs and VK_KHR_swapchain. None: headless.
    pub present: Option<raw_window_handle::RawDisplayHandle>,
}

/// Validation messages seen so far; tests fail on any error.
#[derive(Default)]
pub struct MessageCounts {
    pub errors: AtomicU32,
    pub warnings: AtomicU32,
    pub first: Mutex<Vec<String>>,
}

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    kind: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    let counts = &*(user as *const MessageCounts);
    let msg = if data.is_null() || (*data).p_message.is_null() {
        String::from("(no message)")
    } else {
        CStr::from_ptr((*data).p_message)
            .to_string_lossy()
            .into_owned()
    };
    let is_error = severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR);
    // A driver's or the loader's own warning (GENERAL alone) is printed, not counted: the
    // warnings counted are the validation layer's findings. (lavapipe 22.3's SPIR-V parser
    // warns on `invariant gl_Position`, which glslang emits as a decoration of
    // gl_PerVertex's member, as SPIR-V allows; the layer's spirv-val accepts it.)
    let remark = kind == vk::DebugUtilsMessageTypeFlagsEXT::GENERAL;
    if is_error {
        counts.errors.fetch_add(1, Ordering::Relaxed);
    } else if !remark {
        counts.warnings.fetch_add(1, Ordering::Relaxed);
    }
    let mut first = counts.first.lock().unwrap();
    if first.len() < 16 {
        first.push(msg.clone());
    }
    eprintln!("[vulkan {severity:?} {kind:?}] {msg}");
    vk::FALSE
}

pub struct Context {
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    pub device: ash::Device,
    pub physical: vk::PhysicalDevice,
    pub info: DeviceInfo,
    pub limits: vk::PhysicalDeviceLimits,
    pub queue: vk::Queue,
    pub queue_family: u32,
    pub push_descriptor: ash::khr::push_descriptor::Device,
    pub shaders: ShaderCompiler,
    /// The driver's pipeline cache, kept between processes (gpu/cache.rs).
    pub pipeline_cache: vk::PipelineCache,
    /// Pipelines keyed by what builds them, shared by their holders (gpu/pipelines.rs).
    pub pipelines: super::pipelines::Pipelines,
    debug_instance: Option<ash::ext::debug_utils::Instance>,
    debug_device: Option<ash::ext::debug_utils::Device>,
    messenger: vk::DebugUtilsMessengerEXT,
    messages: Box<MessageCounts>,
    allocator: ManuallyDrop<Mutex<Allocator>>,
    one_shot_pool: Mutex<vk::CommandPool>,
    pub(crate) memory: Mutex<BTreeMap<String, u64>>,
    /// Live pipelines, buffers, images, pools: what an error path could leak.
    objects: Mutex<BTreeMap<&'static str, i64>>,
    /// Buffer hazards of the command buffers being recorded (`gpu::track`).
    pub(crate) trackers: Mutex<super::track::Trackers>,
}

/// The debug-utils instance functions (when the loader has them) and, with validation,
/// a messenger counting the layer's errors and warnings into `messages`. On failure the
/// instance is destroyed.
fn create_messenger(
    entry: &ash::Entry,
    instance: &ash::Instance,
    has_debug: bool,
    validation: bool,
    messages: &MessageCounts,
) -> Result<(
    Option<ash::ext::debug_utils::Instance>,
    vk::DebugUtilsMessengerEXT,
)> {
    let mut debug_instance = None;
    let mut messenger = vk::DebugUtilsMessengerEXT::null();
    if has_debug {
        let di = ash::ext::debug_utils::Instance::new(entry, instance);
        if validation {
            let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(
                    vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                        | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
                )
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                        | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                        | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
                )
                .pfn_user_callback(Some(debug_callback))
                .user_data(messages as *const MessageCounts as *mut c_void);
            match unsafe { di.create_debug_utils_messenger(&info, None) } {
                Ok(m) => messenger = m,
                Err(e) => {
                    unsafe { instance.destroy_instance(None) };
                    return Err(Error::Vulkan {
                        context: "create debug messenger".into(),
                        result: e,
                    });
                }
            }
        }
        debug_instance = Some(di);
    }
    Ok((debug_instance, messenger))
}

impl Context {
    /// Open the chosen device headless: the one constructor for tests, benches and the CLI.
    /// Long because every failure releases what was made before it (device, messenger,
    /// instance) on its own path.
    pub fn new(opts: &ContextOptions) -> Result<Self> {
        let entry = load_entry()?;
        let surface_exts = match opts.present {
            Some(d) => ash_window::enumerate_required_extensions(d)
                .map_err(|e| {
                    Error::Unsupported(format!("this display has no Vulkan surface: {e}"))
                })?
                .to_vec(),
            None => Vec::new(),
        };
        let (instance, has_debug) = create_instance(&entry, opts.validation, &surface_exts)?;
        let messages = Box::<MessageCounts>::default();
        let (debug_instance, messenger) =
            create_messenger(&entry, &instance, has_debug, opts.validation, &messages)?;
        let cleanup = |di: &Option<ash::ext::debug_utils::Instance>| unsafe {
            if let Some(di) = di {
                if messenger != vk::DebugUtilsMessengerEXT::null() {
                    di.destroy_debug_utils_messenger(messenger, None);
                }
            }
            instance.destroy_instance(None);
        };
        let picked = device::pick(&instance, opts.device.as_deref());
        let (physical, info) = match picked {
            Ok(p) => p,
            Err(e) => {
                cleanup(&debug_instance);
                return Err(e);
            }
        };
        let opened = open_device(&instance, physical, &info, opts.present.is_some());
        let (device, queue_family) = match opened {
            Ok(d) => d,
            Err(e) => {
                cleanup(&debug_instance);
                return Err(e);
            }
        };
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let props = unsafe { instance.get_physical_device_properties(physical) };
        let limits = props.limits;
        let push_descriptor = ash::khr::push_descriptor::Device::new(&instance, &device);
        let debug_device = debug_instance
            .as_ref()
            .map(|_| ash::ext::debug_utils::Device::new(&instance, &device));
        // Everything below can fail: release the device and the instance on every path.
        let rest = (|| -> Result<_> {
            let shaders = ShaderCompiler::new()?;
            let allocator = Allocator::new(&AllocatorCreateDesc {
                instance: instance.clone(),
                device: device.clone(),
                physical_device: physical,
                debug_settings: Default::default(),
                buffer_device_address: false,
                allocation_sizes: Default::default(),
            })
            .map_err(|e| Error::Memory(format!("create allocator: {e}")))?;
            let pool_info = vk::CommandPoolCreateInfo::default()
                .queue_family_index(queue_family)
                .flags(vk::CommandPoolCreateFlags::TRANSIENT);
            let pool =
                unsafe { device.create_command_pool(&pool_info, None) }.ctx("command pool")?;
            Ok((shaders, allocator, pool))
        })();
        let pipeline_cache = super::cache::open_pipeline_cache(&device, &props);
        let (shaders, allocator, pool) = match rest {
            Ok(r) => r,
            Err(e) => {
                unsafe {
                    device.destroy_pipeline_cache(pipeline_cache, None);
                    device.destroy_device(None);
                }
                cleanup(&debug_instance);
                return Err(e);
            }
        };
        let ctx = Self {
            entry,
            instance,
            device,
            physical,
            info,
            limits,
            queue,
            queue_family,
            push_descriptor,
            shaders,
            pipeline_cache,
            pipelines: Default::default(),
            debug_instance,
            debug_device,
            messenger,
            messages,
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            one_shot_pool: Mutex::new(pool),
            memory: Mutex::new(BTreeMap::new()),
            objects: Mutex::new(BTreeMap::new()),
            trackers: Mutex::new(super::track::Trackers::new()),
        };
        ctx.set_name(pool, "one-shot command pool");
        ctx.set_name(ctx.queue, "main queue");
        Ok(ctx)
    }

    pub(crate) fn allocator(&self) -> std::sync::MutexGuard<'_, Allocator> {
        self.allocator.lock().unwrap()
    }

    /// (errors, warnings) reported by the validation layer so far.
    pub fn validation_counts(&self) -> (u32, u32) {
        (
            self.messages.errors.load(Ordering::Relaxed),
            self.messages.warnings.load(Ordering::Relaxed),
        )
    }

    /// The first validation messages, for error reports.
    pub fn validation_messages(&self) -> Vec<String> {
        self.messages.first.lock().unwrap().clone()
    }

    /// Bytes held by each named buffer and image now alive.
    pub fn memory_bytes(&self) -> BTreeMap<String, u64> {
        self.memory.lock().unwrap().clone()
    }

    /// Count a created (+1) or destroyed (-1) object of `kind`.
    pub(crate) fn count_object(&self, kind: &'static str, delta: i64) {
        let mut m = self.objects.lock().unwrap();
        let v = m.entry(kind).or_default();
        *v += delta;
        if *v == 0 {
            m.remove(kind);
        }
    }

    /// Objects of each kind created through this context and not yet destroyed.
    pub fn live_objects(&self) -> BTreeMap<&'static str, i64> {
        self.objects.lock().unwrap().clone()
    }

    /// Give a Vulkan object a debug name (shown by validation messages and capture tools).
    pub fn set_name<H: vk::Handle>(&self, handle: H, name: &str) {
        if let Some(d) = &self.debug_device {
            let name = CString::new(name.replace('\0', " ")).unwrap();
            let info = vk::DebugUtilsObjectNameInfoEXT::default()
                .object_handle(handle)
                .object_name(&name);
            unsafe {
                let _ = d.set_debug_utils_object_name(&info);
            }
        }
    }

    pub fn begin_label(&self, cmd: vk::CommandBuffer, name: &str) {
        if let Some(d) = &self.debug_device {
            let name = CString::new(name.replace('\0', " ")).unwrap();
            let label = vk::DebugUtilsLabelEXT::default().label_name(&name);
            unsafe { d.cmd_begin_debug_utils_label(cmd, &label) };
        }
    }

    pub fn end_label(&self, cmd: vk::CommandBuffer) {
        if let Some(d) = &self.debug_device {
            unsafe { d.cmd_end_debug_utils_label(cmd) };
        }
    }

    /// Record with `f`, submit, wait: for uploads, readbacks, tests and setup work.
    pub fn one_shot<R>(&self, f: impl FnOnce(vk::CommandBuffer) -> R) -> Result<R> {
        let pool = self.one_shot_pool.lock().unwrap();
        let info = vk::CommandBufferAllocateInfo::default()
            .command_pool(*pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        let cmd =
            unsafe { self.device.allocate_command_buffers(&info) }.ctx("allocate command")?[0];
        let fence = unsafe {
            self.device
                .create_fence(&vk::FenceCreateInfo::default(), None)
        }
        .ctx("create fence")?;
        let result = (|| {
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            unsafe { self.device.begin_command_buffer(cmd, &begin) }.ctx("begin command")?;
            self.trackers.lock().unwrap().begin(cmd);
            let r = f(cmd);
            unsafe { self.device.end_command_buffer(cmd) }.ctx("end command")?;
            self.submit(cmd, fence)?;
            self.wait(fence)?;
            Ok(r)
        })();
        unsafe {
            self.device.destroy_fence(fence, None);
            self.device.free_command_buffers(*pool, &[cmd]);
        }
        result
    }

    pub fn submit(&self, cmd: vk::CommandBuffer, fence: vk::Fence) -> Result<()> {
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmds);
        self.trackers.lock().unwrap().end(cmd);
        unsafe { self.device.queue_submit2(self.queue, &[submit], fence) }.ctx("queue submit")
    }

    /// Wait for a fence; a lost device or a 10-minute stall is an error, not a hang.
    pub fn wait(&self, fence: vk::Fence) -> Result<()> {
        const TIMEOUT_NS: u64 = 600_000_000_000;
        match unsafe { self.device.wait_for_fences(&[fence], true, TIMEOUT_NS) } {
            Ok(()) => Ok(()),
            Err(vk::Result::TIMEOUT) => Err(Error::Unsupported(
                "the GPU did not finish within 10 minutes".into(),
            )),
            Err(e) => Err(e).ctx("wait for fence"),
        }
    }

    /// Largest range one storage-buffer binding may cover.
    pub fn max_storage_range(&self) -> u64 {
        self.limits.max_storage_buffer_range as u64
    }
}

fn open_device(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    info: &DeviceInfo,
    present: bool,
) -> Result<(ash::Device, u32)> {
    let family = info.queue_family.ok_or_else(|| Error::MissingFeature {
        device: info.name.clone(),
        feature: "a graphics+compute queue with timestamps".into(),
    })?;
    let priorities = [1.0];
    let queues = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(family)
        .queue_priorities(&priorities)];
    let mut exts = vec![ash::khr::push_descriptor::NAME.as_ptr()];
    if info.calibrated {
        exts.push(ash::ext::calibrated_timestamps::NAME.as_ptr());
    }
    if present {
        let has = unsafe { instance.enumerate_device_extension_properties(physical) }
            .unwrap_or_default()
            .iter()
            .any(|e| e.extension_name_as_c_str() == Ok(ash::khr::swapchain::NAME));
        if !has {
            return Err(Error::MissingFeature {
                device: info.name.clone(),
                feature: "VK_KHR_swapchain (a window)".into(),
            });
        }
        exts.push(ash::khr::swapchain::NAME.as_ptr());
    }
    let mut f12 = vk::PhysicalDeviceVulkan12Features::default().host_query_reset(true);
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default()
        .synchronization2(true)
        .dynamic_rendering(true)
        .subgroup_size_control(info.subgroup_size_control)
        .compute_full_subgroups(info.subgroup_size_control);
    let features = vk::PhysicalDeviceFeatures::default()
        .fragment_stores_and_atomics(true)
        .vertex_pipeline_stores_and_atomics(info.vertex_stores)
        .shader_int64(info.int64)
        .large_points(info.max_point_size > 1.0);
    let create = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queues)
        .enabled_extension_names(&exts)
        .enabled_features(&features)
        .push_next(&mut f12)
        .push_next(&mut f13);
    let device = unsafe { instance.create_device(physical, &create, None) }.ctx("create device")?;
    Ok((device, family))
}

impl Drop for Context {
    fn drop(&mut self) {
        unsafe {
            let _ = self.device.device_wait_idle();
            let leaked = self.memory.lock().unwrap().clone();
            let objects = self.live_objects();
            if !leaked.is_empty() || !objects.is_empty() {
                eprintln!("fluidform: GPU objects not destroyed: {leaked:?} {objects:?}");
            }
            ManuallyDrop::drop(&mut self.allocator);
            let props = self.instance.get_physical_device_properties(self.physical);
            super::cache::close_pipeline_cache(&self.device, &props, self.pipeline_cache);
            self.device
                .destroy_command_pool(*self.one_shot_pool.lock().unwrap(), None);
            self.device.destroy_device(None);
            if let Some(di) = &self.debug_instance {
                if self.messenger != vk::DebugUtilsMessengerEXT::null() {
                    di.destroy_debug_utils_messenger(self.messenger, None);
                }
            }
            self.instance.destroy_instance(None);
        }
    }
}

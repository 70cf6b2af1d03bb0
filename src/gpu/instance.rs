//! The Vulkan loader and instance (optionally with the Khronos validation layer, its
//! synchronization validation on), shared by device listing and the context.
use crate::error::{Error, Result, VkContext};
use ash::vk;
use std::ffi::CStr;

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

pub(crate) fn load_entry() -> Result<ash::Entry> {
    unsafe { ash::Entry::load() }.map_err(|e| Error::Loader(e.to_string()))
}

/// Create an instance; with `validation`, the Khronos layer with synchronization validation.
/// Returns whether VK_EXT_debug_utils is on (the context adds its messenger).
pub(crate) fn create_instance(
    entry: &ash::Entry,
    validation: bool,
    surface_exts: &[*const std::ffi::c_char],
) -> Result<(ash::Instance, bool)> {
    let layers = unsafe { entry.enumerate_instance_layer_properties() }.ctx("list layers")?;
    let has_layer = layers
        .iter()
        .any(|l| l.layer_name_as_c_str().ok() == Some(VALIDATION_LAYER));
    if validation && !has_layer {
        return Err(Error::Unsupported(
            "--validation: the Khronos validation layer is not installed (Debian package \
             vulkan-validationlayers; run scripts/setup.sh)"
                .into(),
        ));
    }
    let exts = unsafe { entry.enumerate_instance_extension_properties(None) }
        .ctx("list instance extensions")?;
    let has_debug = exts
        .iter()
        .any(|e| e.extension_name_as_c_str().ok() == Some(ash::ext::debug_utils::NAME));
    let version = unsafe { entry.try_enumerate_instance_version() }
        .ctx("instance version")?
        .unwrap_or(vk::API_VERSION_1_0);
    if version < vk::API_VERSION_1_3 {
        return Err(Error::Unsupported(format!(
            "the Vulkan loader supports {}, fluidform needs 1.3",
            version_string(version)
        )));
    }
    let app = vk::ApplicationInfo::default()
        .application_name(c"fluidform")
        .engine_name(c"fluidform")
        .api_version(vk::API_VERSION_1_3);
    let layer_ptrs = if validation {
        vec![VALIDATION_LAYER.as_ptr()]
    } else {
        vec![]
    };
    let mut ext_ptrs = if has_debug {
        vec![ash::ext::debug_utils::NAME.as_ptr()]
    } else {
        vec![]
    };
    ext_ptrs.extend_from_slice(surface_exts);
    if validation {
        // VkValidationFeaturesEXT is read only with this extension, which the layer provides.
        let layer_exts =
            unsafe { entry.enumerate_instance_extension_properties(Some(VALIDATION_LAYER)) }
                .ctx("list validation layer extensions")?;
        let name = ash::ext::validation_features::NAME;
        if !layer_exts
            .iter()
            .any(|e| e.extension_name_as_c_str().ok() == Some(name))
        {
            return Err(Error::Unsupported(
                "--validation: the validation layer lacks VK_EXT_validation_features, needed \
                 for synchronization validation"
                    .into(),
            ));
        }
        ext_ptrs.push(name.as_ptr());
    }
    // With validation, also synchronization validation: narrow barriers must not hide
    // hazards (every hazard is reported as an error).
    let enabled = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&enabled);
    let mut info = vk::InstanceCreateInfo::default()
        .application_info(&app)
        .enabled_layer_names(&layer_ptrs)
        .enabled_extension_names(&ext_ptrs);
    if validation {
        info = info.push_next(&mut features);
    }
    let instance = unsafe { entry.create_instance(&info, None) }.ctx("create instance")?;
    Ok((instance, has_debug))
}

pub fn version_string(v: u32) -> String {
    format!(
        "{}.{}.{}",
        vk::api_version_major(v),
        vk::api_version_minor(v),
        vk::api_version_patch(v)
    )
}

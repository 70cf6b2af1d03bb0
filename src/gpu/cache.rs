//! What a process keeps for the next one, so a short GPU lease is not spent compiling:
//! SPIR-V by (shader, defines) and the driver's Vulkan pipeline cache, under
//! `FLUIDFORM_CACHE_DIR` (else `$XDG_CACHE_HOME/fluidform`, else `~/.cache/fluidform`;
//! `FLUIDFORM_CACHE_DIR=off` keeps nothing). A file is trusted only when it names this
//! binary (`build_id`: the embedded GLSL is part of it) and, for pipelines, this device
//! and driver; any other is ignored with one line and replaced.
use ash::vk;
use std::hash::{Hash, Hasher};
use std::path::PathBuf;

pub const CACHE_ENV: &str = "FLUIDFORM_CACHE_DIR";

/// Our header in front of the driver's pipeline-cache data.
const MAGIC: &[u8; 8] = b"FFPCACHE";

/// The cache directory, None when caching is off or no home is known.
pub fn dir() -> Option<PathBuf> {
    match std::env::var_os(CACHE_ENV) {
        Some(v) if v == "off" => None,
        Some(v) => Some(PathBuf::from(v)),
        None => std::env::var_os("XDG_CACHE_HOME")
            .map(PathBuf::from)
            .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
            .map(|d| d.join("fluidform")),
    }
}

/// This binary: its path, size and modification time (a rebuild changes them), hashed
/// once; the embedded GLSL is part of the binary.
pub fn build_id() -> u64 {
    static ID: std::sync::OnceLock<u64> = std::sync::OnceLock::new();
    *ID.get_or_init(|| {
        let mut h = std::collections::hash_map::DefaultHasher::new();
        if let Ok(exe) = std::env::current_exe() {
            exe.hash(&mut h);
            if let Ok(m) = std::fs::metadata(&exe) {
                m.len().hash(&mut h);
                m.modified().ok().hash(&mut h);
            }
        }
        h.finish()
    })
}

/// A file write that a concurrent reader never sees half-done: a temporary, then rename.
fn write_atomic(path: &std::path::Path, bytes: &[u8]) -> std::io::Result<()> {
    if let Some(d) = path.parent() {
        std::fs::create_dir_all(d)?;
    }
    let tmp = path.with_extension(format!("tmp{}", std::process::id()));
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path)
}

/// SPIR-V of one (shader, defines, level) compile: the file it is kept in.
pub fn spirv_path(build: u64, key: &impl Hash) -> Option<PathBuf> {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    build.hash(&mut h);
    key.hash(&mut h);
    Some(
        dir()?
            .join("spirv")
            .join(format!("{:016x}.spv", h.finish())),
    )
}

/// Kept SPIR-V, when the file holds a SPIR-V module (magic number first).
pub fn load_spirv(path: &std::path::Path) -> Option<Vec<u32>> {
    let bytes = std::fs::read(path).ok()?;
    if bytes.len() < 20 || bytes.len() % 4 != 0 {
        return None;
    }
    let words: Vec<u32> = bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    (words[0] == 0x0723_0203).then_some(words)
}

pub fn save_spirv(path: &std::path::Path, words: &[u32]) {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    let _ = write_atomic(path, &bytes);
}

/// Where this device's pipeline cache is kept.
pub fn pipeline_path(props: &vk::PhysicalDeviceProperties) -> Option<PathBuf> {
    let uuid: String = props
        .pipeline_cache_uuid
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    // One file per binary and device, so two binaries (tests, the CLI) never clobber
    // each other's.
    Some(dir()?.join(format!(
        "pipelines-{:04x}-{:04x}-{uuid}-{:016x}.bin",
        props.vendor_id,
        props.device_id,
        build_id()
    )))
}

/// Our header: the magic, this binary's build id, the driver's version, then Vulkan's own
/// header (vendor, device, cache UUID), which `accept` checks too.
fn header(build: u64, props: &vk::PhysicalDeviceProperties) -> Vec<u8> {
    let mut h = MAGIC.to_vec();
    h.extend(build.to_le_bytes());
    h.extend(props.driver_version.to_le_bytes());
    h
}

/// The driver's data in a kept pipeline cache, or why it is not to be trusted.
pub fn accept(
    bytes: &[u8],
    build: u64,
    props: &vk::PhysicalDeviceProperties,
) -> Result<Vec<u8>, &'static str> {
    let ours = header(build, props);
    if bytes.len() < ours.len() + 32 || bytes[..8] != ours[..8] {
        return Err("not a fluidform pipeline cache");
    }
    if bytes[8..16] != ours[8..16] {
        return Err("made by another fluidform binary");
    }
    if bytes[16..20] != ours[16..20] {
        return Err("made by another driver version");
    }
    // VkPipelineCacheHeaderVersionOne: length, version, vendor, device, UUID.
    let data = &bytes[ours.len()..];
    let word = |i: usize| u32::from_le_bytes([data[i], data[i + 1], data[i + 2], data[i + 3]]);
    if word(8) != props.vendor_id
        || word(12) != props.device_id
        || data[16..32] != props.pipeline_cache_uuid
    {
        return Err("made for another device or driver");
    }
    Ok(data.to_vec())
}

/// The bytes to keep: our header, then the driver's data.
pub fn wrap(data: &[u8], build: u64, props: &vk::PhysicalDeviceProperties) -> Vec<u8> {
    let mut v = header(build, props);
    v.extend_from_slice(data);
    v
}

/// Files of the cache older than this are removed (each rebuild keys its own files, so a
/// developer's cache would otherwise only grow).
const KEEP_DAYS: u64 = 14;

/// Remove files under `dir` (and its `spirv/`) not modified for `days`; returns how many.
pub fn prune(dir: &std::path::Path, days: u64) -> usize {
    let old = std::time::Duration::from_secs(days * 86_400);
    let mut removed = 0;
    for d in [dir.to_path_buf(), dir.join("spirv")] {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            let stale = e
                .metadata()
                .ok()
                .filter(|m| m.is_file())
                .and_then(|m| m.modified().ok())
                .and_then(|t| t.elapsed().ok())
                .is_some_and(|age| age > old);
            if stale && std::fs::remove_file(&p).is_ok() {
                removed += 1;
            }
        }
    }
    removed
}

/// Make the pipeline cache from the kept file where it is this device's and binary's; a
/// stale or broken one is ignored with one line.
pub fn open_pipeline_cache(
    device: &ash::Device,
    props: &vk::PhysicalDeviceProperties,
) -> vk::PipelineCache {
    let build = build_id();
    if let Some(d) = dir() {
        prune(&d, KEEP_DAYS);
    }
    let initial = pipeline_path(props).and_then(|p| {
        let bytes = std::fs::read(&p).ok()?;
        match accept(&bytes, build, props) {
            Ok(d) => Some(d),
            Err(why) => {
                eprintln!(
                    "fluidform: ignoring the pipeline cache {}: {why}",
                    p.display()
                );
                None
            }
        }
    });
    let make = |data: &[u8]| {
        let info = vk::PipelineCacheCreateInfo::default().initial_data(data);
        unsafe { device.create_pipeline_cache(&info, None) }
    };
    match initial.as_deref().map(make) {
        Some(Ok(c)) => c,
        // The driver refused the data: start empty (a cache only saves time).
        _ => make(&[]).unwrap_or(vk::PipelineCache::null()),
    }
}

/// Keep the pipeline cache for the next process, then destroy it.
pub fn close_pipeline_cache(
    device: &ash::Device,
    props: &vk::PhysicalDeviceProperties,
    cache: vk::PipelineCache,
) {
    if cache == vk::PipelineCache::null() {
        return;
    }
    if let (Some(p), Ok(data)) = (pipeline_path(props), unsafe {
        device.get_pipeline_cache_data(cache)
    }) {
        if data.len() >= 32 {
            let _ = write_atomic(&p, &wrap(&data, build_id(), props));
        }
    }
    unsafe { device.destroy_pipeline_cache(cache, None) };
}

#[cfg(test)]
mod tests {
    use super::*;

    fn props(vendor: u32, device: u32, uuid: u8, driver: u32) -> vk::PhysicalDeviceProperties {
        vk::PhysicalDeviceProperties {
            vendor_id: vendor,
            device_id: device,
            pipeline_cache_uuid: [uuid; 16],
            driver_version: driver,
            ..Default::default()
        }
    }

    /// The driver's data as Vulkan lays it out: header (length, version, vendor, device,
    /// UUID), then its own bytes.
    fn driver_data(p: &vk::PhysicalDeviceProperties) -> Vec<u8> {
        let mut d = Vec::new();
        d.extend(32u32.to_le_bytes());
        d.extend(1u32.to_le_bytes());
        d.extend(p.vendor_id.to_le_bytes());
        d.extend(p.device_id.to_le_bytes());
        d.extend(p.pipeline_cache_uuid);
        d.extend([7u8; 40]);
        d
    }

    #[test]
    fn only_this_binary_device_and_driver_are_trusted() {
        let p = props(0x10de, 0x2330, 3, 550);
        let data = driver_data(&p);
        let kept = wrap(&data, 42, &p);
        assert_eq!(accept(&kept, 42, &p), Ok(data.clone()));
        assert_eq!(
            accept(&kept, 43, &p),
            Err("made by another fluidform binary")
        );
        let newer = props(0x10de, 0x2330, 3, 560);
        assert_eq!(
            accept(&kept, 42, &newer),
            Err("made by another driver version")
        );
        let other = props(0x10de, 0x2331, 3, 550);
        assert_eq!(
            accept(&wrap(&data, 42, &other), 42, &other),
            Err("made for another device or driver")
        );
        let uuid = props(0x10de, 0x2330, 4, 550);
        assert_eq!(
            accept(&wrap(&data, 42, &uuid), 42, &uuid),
            Err("made for another device or driver")
        );
        assert_eq!(
            accept(b"garbage", 42, &p),
            Err("not a fluidform pipeline cache")
        );
        assert_eq!(
            accept(&kept[..30], 42, &p),
            Err("not a fluidform pipeline cache")
        );
    }

    #[test]
    fn spirv_files_must_hold_spirv() {
        let d = tempfile_dir();
        let good = d.join("good.spv");
        save_spirv(&good, &[0x0723_0203, 1, 2, 3, 4, 5]);
        assert_eq!(load_spirv(&good), Some(vec![0x0723_0203, 1, 2, 3, 4, 5]));
        let bad = d.join("bad.spv");
        std::fs::write(&bad, [1u8; 24]).unwrap();
        assert_eq!(load_spirv(&bad), None);
        std::fs::write(&bad, [3u8; 7]).unwrap();
        assert_eq!(load_spirv(&bad), None);
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn prune_removes_only_old_files() {
        let d = tempfile_dir().join("prune");
        std::fs::create_dir_all(d.join("spirv")).unwrap();
        let (a, b) = (d.join("pipelines-x.bin"), d.join("spirv").join("y.spv"));
        std::fs::write(&a, b"a").unwrap();
        std::fs::write(&b, b"b").unwrap();
        // Nothing is 14 days old: nothing goes.
        assert_eq!(prune(&d, 14), 0);
        assert!(a.exists() && b.exists());
        // Backdated a month: both go.
        let month = std::time::SystemTime::now() - std::time::Duration::from_secs(30 * 86_400);
        for p in [&a, &b] {
            let f = std::fs::File::options().write(true).open(p).unwrap();
            f.set_modified(month).unwrap();
        }
        assert_eq!(prune(&d, 14), 2);
        assert!(!a.exists() && !b.exists());
        let _ = std::fs::remove_dir_all(&d);
    }

    fn tempfile_dir() -> PathBuf {
        let d = std::env::temp_dir().join(format!("fluidform-cache-test-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }
}

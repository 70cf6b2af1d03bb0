//! The CPU's clock beside the GPU's: CLOCK_MONOTONIC in ns, and where the device can say
//! so (VK_EXT_calibrated_timestamps), which GPU timestamp is which CPU time, so a trace
//! can put the GPU's passes and the CPU's recording on one timeline.
use super::Context;
use ash::vk;

/// Set to any value: behave as a device without calibrated timestamps (the trace's
/// GPU-only path, for tests).
pub const NO_CALIBRATION_ENV: &str = "FLUIDFORM_NO_CALIBRATION";

/// CLOCK_MONOTONIC now, in ns.
pub fn monotonic_ns() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes the timespec it is given; CLOCK_MONOTONIC always exists
    // on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut t) };
    t.tv_sec as f64 * 1e9 + t.tv_nsec as f64
}

/// One GPU timestamp and the CPU time it was taken at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Calibration {
    /// The device's timestamp, ns (ticks times the period).
    pub gpu_ns: f64,
    /// CLOCK_MONOTONIC at the same instant, ns.
    pub cpu_ns: f64,
    /// How far apart the two samples may be, ns (the driver's deviation).
    pub deviation_ns: f64,
}

impl Calibration {
    /// A GPU time (ns of the device's clock) on the CPU's clock.
    pub fn to_cpu(&self, gpu_ns: f64) -> f64 {
        gpu_ns - self.gpu_ns + self.cpu_ns
    }
}

/// Sample both clocks together, where the device has calibrated timestamps on both the
/// device and CLOCK_MONOTONIC domains; None elsewhere.
pub fn calibrate(ctx: &Context) -> Option<Calibration> {
    if !ctx.info.calibrated || std::env::var_os(NO_CALIBRATION_ENV).is_some() {
        return None;
    }
    let inst = ash::ext::calibrated_timestamps::Instance::new(&ctx.entry, &ctx.instance);
    let domains =
        unsafe { inst.get_physical_device_calibrateable_time_domains(ctx.physical) }.ok()?;
    let want = [
        vk::TimeDomainKHR::DEVICE,
        vk::TimeDomainKHR::CLOCK_MONOTONIC,
    ];
    if !want.iter().all(|d| domains.contains(d)) {
        return None;
    }
    let dev = ash::ext::calibrated_timestamps::Device::new(&ctx.instance, &ctx.device);
    let infos = want.map(|d| vk::CalibratedTimestampInfoKHR::default().time_domain(d));
    let (ts, deviation) = unsafe { dev.get_calibrated_timestamps(&infos) }.ok()?;
    let bits = ctx.info.timestamp_valid_bits;
    let mask = if bits >= 64 {
        u64::MAX
    } else {
        (1u64 << bits) - 1
    };
    Some(Calibration {
        gpu_ns: (ts[0] & mask) as f64 * ctx.info.timestamp_period_ns as f64,
        cpu_ns: ts[1] as f64,
        deviation_ns: deviation as f64,
    })
}

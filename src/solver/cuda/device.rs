//! The GPU: its libraries found and opened ([`super::libraries`]), its context and stream,
//! what it is (`cuda_device`, which `precursors info` prints), and the crate's errors of
//! CUDA calls. Every failure to start is [`Error::CudaUnavailable`] with what to do; a
//! panic inside the bindings (a symbol missing from a too-old library) is caught and
//! reported the same way.

use super::libraries;
use crate::error::{Error, Result};
use cudarc::driver::{CudaContext, CudaStream};
use std::path::PathBuf;
use std::sync::Arc;

/// A usable NVIDIA GPU, as the CUDA backend sees it ([`cuda_device`]).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct CudaDevice {
    /// The device's name (`NVIDIA H200`).
    pub name: String,
    /// Its ordinal among the driver's devices (the backend uses device 0).
    pub ordinal: usize,
    /// Compute capability `(major, minor)`.
    pub compute_capability: (u32, u32),
    /// Device memory (bytes).
    pub total_memory_bytes: f64,
    /// Device memory free when asked (bytes).
    pub free_memory_bytes: f64,
    /// The CUDA driver's version (`13000` for 13.0).
    pub driver_version: u32,
    /// The libraries opened, by path (`libcuda`, `libcufft`, `libnvrtc`).
    pub libraries: Vec<PathBuf>,
}

impl std::fmt::Display for CudaDevice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (major, minor) = self.compute_capability;
        write!(
            f,
            "{} (device {}, compute capability {major}.{minor}, {} of {} free, driver CUDA {}.{})",
            self.name,
            self.ordinal,
            crate::format::format_bytes(self.free_memory_bytes),
            crate::format::format_bytes(self.total_memory_bytes),
            self.driver_version / 1000,
            (self.driver_version % 1000) / 10
        )
    }
}

/// The first GPU, if the CUDA backend can run on it: the libraries it needs are found
/// and opened, the driver answers and the device has a context.
///
/// ```no_run
/// match precursors::solver::cuda_device() {
///     Ok(gpu) => println!("GPU: {gpu}"),
///     Err(e) => println!("no GPU: {e}"),
/// }
/// ```
///
/// # Errors
/// [`Error::CudaUnavailable`] naming what is missing (the libraries searched, the
/// driver's answer) and what to install or set.
pub fn cuda_device() -> Result<CudaDevice> {
    Ok(Gpu::open()?.info)
}

/// The GPU the backend runs on: context, one stream, what it is.
pub(crate) struct Gpu {
    pub(crate) ctx: Arc<CudaContext>,
    pub(crate) stream: Arc<CudaStream>,
    pub(crate) info: CudaDevice,
}

impl std::fmt::Debug for Gpu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Gpu").field("info", &self.info).finish()
    }
}

impl Gpu {
    /// Opens device 0 (the libraries first, by path).
    pub(crate) fn open() -> Result<Gpu> {
        let libraries = libraries::load()?;
        let unavailable = |reason: String| Error::CudaUnavailable {
            reason,
            hint: libraries::HINT.to_string(),
        };
        let opened = guarded("cuInit and the device's context", || {
            let count = CudaContext::device_count()
                .map_err(|e| format!("the CUDA driver does not answer ({e})"))?;
            if count < 1 {
                return Err("the CUDA driver sees no GPU".to_string());
            }
            let ctx = CudaContext::new(0).map_err(|e| format!("device 0 has no context ({e})"))?;
            let name = ctx.name().map_err(|e| e.to_string())?;
            let (major, minor) = ctx.compute_capability().map_err(|e| e.to_string())?;
            let (free, total) = ctx.mem_get_info().map_err(|e| e.to_string())?;
            let mut driver_version: std::ffi::c_int = 0;
            // SAFETY: the driver writes one int; cuInit ran (device_count).
            unsafe { cudarc::driver::sys::cuDriverGetVersion(&mut driver_version) }
                .result()
                .map_err(|e| e.to_string())?;
            // One stream and no cross-stream events: the backend orders its work itself.
            // SAFETY: every launch and copy of the backend goes to this one stream.
            unsafe { ctx.disable_event_tracking() };
            let stream = ctx.default_stream();
            Ok((
                ctx,
                stream,
                name,
                (major, minor),
                (free, total),
                driver_version,
            ))
        })
        .map_err(unavailable)?;
        let (ctx, stream, name, (major, minor), (free, total), driver_version) = opened;
        Ok(Gpu {
            ctx,
            stream,
            info: CudaDevice {
                name,
                ordinal: 0,
                compute_capability: (major.max(0) as u32, minor.max(0) as u32),
                total_memory_bytes: total as f64,
                free_memory_bytes: free as f64,
                driver_version: driver_version.max(0) as u32,
                libraries,
            },
        })
    }

    /// Device memory free now (bytes).
    pub(crate) fn free_bytes(&self) -> Result<f64> {
        let (free, _) = self
            .ctx
            .mem_get_info()
            .map_err(|e| cuda_error("cuMemGetInfo", e))?;
        Ok(free as f64)
    }
}

/// Runs `f`, a panic inside the bindings (a library without a symbol they expect) turned
/// into a reason naming `what`.
pub(crate) fn guarded<T>(
    what: &str,
    f: impl FnOnce() -> std::result::Result<T, String>,
) -> std::result::Result<T, String> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)) {
        Ok(result) => result,
        Err(payload) => {
            let message = payload
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "a panic without a message".into());
            Err(format!(
                "{what} failed inside the CUDA bindings ({message}): a library may be too old"
            ))
        }
    }
}

/// `len` zeros on the device (every buffer of the backend is allocated through here).
pub(crate) fn zeros<T: cudarc::driver::DeviceRepr + cudarc::driver::ValidAsZeroBits>(
    stream: &Arc<CudaStream>,
    len: usize,
) -> Result<cudarc::driver::CudaSlice<T>> {
    stream
        .alloc_zeros::<T>(len)
        .map_err(|e| cuda_error("cuMemAlloc", e))
}

/// A failed CUDA call during a solve.
pub(crate) fn cuda_error(call: &'static str, e: impl std::fmt::Display) -> Error {
    Error::Cuda {
        call,
        message: e.to_string(),
    }
}

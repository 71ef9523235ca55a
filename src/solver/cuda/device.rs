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
/// into a reason naming `what`, with nothing printed: the panic's message goes into the
/// reason, and the panic hook stays quiet for it (see [`quiet_panics`]).
///
/// Under `panic = "abort"` (a profile setting of the program that links the crate) no
/// panic can be caught: the hook prints the bindings' message (`Missing symbol cuInit:
/// ...`) and the process aborts (SIGABRT) instead of returning `CudaUnavailable`. Only a
/// library that the search of `libraries.rs` found and opened but that lacks a function
/// the bindings call (older than CUDA 12) can panic here; a missing library is an error
/// of that search, before the bindings are called, under either setting.
pub(crate) fn guarded<T>(
    what: &str,
    f: impl FnOnce() -> std::result::Result<T, String>,
) -> std::result::Result<T, String> {
    let caught = quiet_panics(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)));
    match caught {
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

thread_local! {
    /// Whether this thread is inside [`quiet_panics`].
    static QUIET: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Runs `f` with the panic hook silent for panics of this thread (they are caught and
/// reported by [`guarded`]). The hook is the process's: on first use it is wrapped once,
/// and the wrapper hands every other panic (other threads, or this one outside `f`) to
/// the hook it replaced. Under `panic = "abort"` the hook is left alone: a panic there
/// ends the process, and its message is then all that says why.
fn quiet_panics<T>(f: impl FnOnce() -> T) -> T {
    if cfg!(not(panic = "unwind")) {
        return f();
    }
    static WRAPPED: std::sync::Once = std::sync::Once::new();
    WRAPPED.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(|q| q.get()) {
                previous(info);
            }
        }));
    });
    let outer = QUIET.with(|q| q.replace(true));
    let result = f();
    QUIET.with(|q| q.set(outer));
    result
}

/// A failed CUDA call during a solve.
pub(crate) fn cuda_error(call: &'static str, e: impl std::fmt::Display) -> Error {
    Error::Cuda {
        call,
        message: e.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::process::Command;

    /// Libraries that open but lack the driver's functions (a driver older than the
    /// bindings): the bindings panic inside (`Missing symbol cuInit`), the backend answers
    /// `CudaUnavailable` with that message, and nothing else is printed. Run in a process
    /// of its own (this test binary again, with fake libraries first in
    /// `LD_LIBRARY_PATH`): the bindings keep the library they open for the process. The
    /// panic hook writes to the real stderr there (`--nocapture`), so without the quiet
    /// hook the child's stderr has "panicked at".
    #[test]
    fn a_library_without_the_bindings_functions_is_unavailable_without_panic_text() {
        const CHILD: &str = "PRECURSORS_TEST_FAKE_CUDA_CHILD";
        if std::env::var_os(CHILD).is_some() {
            match cuda_device() {
                Err(e) => println!("RESULT {e}"),
                Ok(gpu) => println!("RESULT a GPU: {gpu}"),
            }
            return;
        }
        let dir = std::env::temp_dir().join(format!("precursors-fake-cuda-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        // The driver's library answers its version (CUDA 13) and nothing else; cuFFT and
        // NVRTC are empty. Each has its SONAME, as the real ones do.
        let sources = [
            (
                "libcuda.so.1",
                "int cuDriverGetVersion(int* v) { *v = 13000; return 0; }\n",
            ),
            ("libcufft.so.12", "int precursors_fake_cufft;\n"),
            ("libnvrtc.so.13", "int precursors_fake_nvrtc;\n"),
        ];
        for (name, source) in sources {
            let c = dir.join(format!("{name}.c"));
            std::fs::write(&c, source).unwrap();
            let status = Command::new("cc")
                .args(["-shared", "-fPIC", &format!("-Wl,-soname,{name}"), "-o"])
                .arg(dir.join(name))
                .arg(&c)
                .status()
                .expect("a C compiler `cc` (the emulator's tests need `c++` too)");
            assert!(status.success(), "cc failed on {name}");
        }
        let name = "solver::cuda::device::tests::\
                    a_library_without_the_bindings_functions_is_unavailable_without_panic_text";
        let child = Command::new(std::env::current_exe().unwrap())
            .args(["--exact", name, "--nocapture", "--test-threads=1"])
            .env(CHILD, "1")
            .env("LD_LIBRARY_PATH", &dir)
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&child.stdout);
        let stderr = String::from_utf8_lossy(&child.stderr);
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(child.status.success(), "{stdout}\n{stderr}");
        // The child's line follows libtest's `test NAME ... ` on the same line.
        let result = stdout
            .split_once("RESULT ")
            .and_then(|(_, r)| r.lines().next())
            .unwrap_or_else(|| panic!("no result line: {stdout}\n{stderr}"));
        assert!(
            result.starts_with("the CUDA backend is unavailable: cuInit and the device's context failed inside the CUDA bindings (Missing symbol cuInit"),
            "{result}"
        );
        assert!(
            !stderr.contains("panicked"),
            "panic text printed:\n{stderr}"
        );
        assert!(
            !stdout.contains("panicked"),
            "panic text printed:\n{stdout}"
        );
    }

    /// The hook is quiet only inside [`guarded`], nested ones included, and the error
    /// carries the panic's message. (That other panics still reach the hook it replaced
    /// is not tested: the harness captures what that hook prints.)
    #[test]
    fn the_quiet_hook_is_only_for_guarded_panics() {
        let caught = guarded("a test", || -> std::result::Result<(), String> {
            panic!("planted")
        });
        assert_eq!(
            caught.unwrap_err(),
            "a test failed inside the CUDA bindings (planted): a library may be too old"
        );
        assert!(!QUIET.with(|q| q.get()));
        let nested = guarded("outer", || {
            let inner = guarded("inner", || -> std::result::Result<(), String> {
                panic!("x")
            });
            assert!(QUIET.with(|q| q.get()), "still quiet after an inner guard");
            inner
        });
        assert!(nested.unwrap_err().starts_with("inner failed"));
        assert!(!QUIET.with(|q| q.get()));
    }
}

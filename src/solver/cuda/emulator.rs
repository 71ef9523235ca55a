//! The host emulator: a [`Device`] for the tests that runs kernels.cu's own source,
//! compiled for the host by the C++ compiler (emulated.cpp, a shared library loaded by
//! path), under the backend's own launch code. What it keeps of a GPU:
//!
//! - Blocks of `threads` threads (1, 4 or the device's [`THREADS`]), more than one
//!   running as real threads meeting at a barrier for `__syncthreads`; several blocks of
//!   a launch at once on OS threads (`std::thread::scope`, one per lane of the library),
//!   each lane with its own `__shared__` memory. A race between blocks, or in a block,
//!   can show.
//! - cuFFT's real transforms as NVIDIA documents them (cuFFT API reference, "Data
//!   Layout"): a `D2Z` of dimensions `n_0 x ... x n_{r-1}` writes `n_{r-1}/2 + 1`
//!   complex values along the last dimension, row-major, batches one after the other;
//!   `Z2D` reads that layout; neither normalises (`Z2D(D2Z(x)) = (Π n) x`), and `Z2D`
//!   overwrites its input (here with NaN, so a later read shows). By direct DFTs.
//! - Launch shapes: a block size other than the build's, or a 2-D grid, is refused.
//! - Copies past a buffer's end are errors.
//! - Faults: a step of each kind (allocation, launch, copy, plan, synchronisation) can
//!   be made to fail ([`Emulator::fail`]), as a failed CUDA call would.

use super::device::cuda_error;
use super::kernels::{threads_define, Kernel, SOURCE, THREADS};
use super::seam::{check_copy, Arg, Device, Elem, FftKind, KernelId};
use crate::error::Result;
use cudarc::cufft::sys::double2;
use cudarc::driver::LaunchConfig;
use std::ffi::c_void;
use std::path::PathBuf;
use std::process::Command;
use std::sync::Mutex;

/// The kinds of device step a fault can be planted in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Step {
    Alloc,
    Launch,
    Copy,
    Plan,
    Synchronize,
}

impl Step {
    pub(super) const ALL: [Step; 5] = [
        Step::Alloc,
        Step::Launch,
        Step::Copy,
        Step::Plan,
        Step::Synchronize,
    ];
}

/// `precursors_emulated_block(lane, kernel, grid, block, params)`.
type BlockFn = unsafe extern "C" fn(i32, i32, u32, u32, *mut *mut c_void) -> i32;

/// One build of emulated.cpp, loaded for the rest of the process.
struct Build {
    _library: libloading::Library,
    block: BlockFn,
    most_in_flight: unsafe extern "C" fn() -> i32,
    lanes: u32,
    /// Launches on this build one at a time: its lanes' `__shared__` memory is the
    /// library's, shared by every emulator of the process.
    serial: Mutex<()>,
}

/// A buffer of the emulated device.
pub(super) struct HostBuffer<T>(pub(super) Vec<T>);

/// An emulated cuFFT plan.
#[derive(Debug)]
pub(super) struct HostPlan {
    kind: FftKind,
    dims: Vec<usize>,
    batch: usize,
}

/// Steps counted by kind, and the planted fault.
#[derive(Debug, Default)]
struct Faults {
    counts: [usize; 5],
    /// Per kernel ([`Kernel`] as index), whether it was launched.
    launched: Vec<bool>,
    /// Fail the step of this kind whose count (from zero) is this.
    fail: Option<(Step, usize)>,
}

/// The host emulator of a GPU.
pub(super) struct Emulator {
    build: &'static Build,
    threads: u32,
    faults: Mutex<Faults>,
}

impl std::fmt::Debug for Emulator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the host emulator ({} threads per block)", self.threads)
    }
}

/// The emulator's thread counts per block: one (the sequential reference), four, and the
/// device's [`THREADS`].
pub(super) const VARIANTS: [u32; 3] = [1, 4, THREADS];

impl Emulator {
    /// An emulator of blocks of `threads` threads (emulated.cpp built once per process
    /// and version of its sources).
    pub(super) fn new(threads: u32) -> Emulator {
        Emulator {
            build: build(threads),
            threads,
            faults: Mutex::new(Faults::default()),
        }
    }

    /// Makes the step of kind `step` numbered `nth` (counted from zero since the
    /// emulator was made) fail, as a failed CUDA call: `Error::Cuda` naming the call.
    pub(super) fn fail(&self, step: Step, nth: usize) {
        self.faults().fail = Some((step, nth));
    }

    /// The kernels launched so far.
    pub(super) fn launched(&self) -> Vec<Kernel> {
        let faults = self.faults();
        Kernel::ALL
            .iter()
            .copied()
            .filter(|&k| faults.launched.get(k as usize) == Some(&true))
            .collect()
    }

    /// Steps of kind `step` asked for so far.
    pub(super) fn count(&self, step: Step) -> usize {
        self.faults().counts[step as usize]
    }

    /// The most blocks that ran at once on this build since the last call (any emulator
    /// of the process with the same thread count).
    pub(super) fn most_in_flight(&self) -> i32 {
        let _serial = lock(&self.build.serial);
        // SAFETY: a function of the loaded library without arguments.
        unsafe { (self.build.most_in_flight)() }
    }

    fn faults(&self) -> std::sync::MutexGuard<'_, Faults> {
        lock(&self.faults)
    }

    /// Counts a step; the planted fault fails it.
    fn step(&self, step: Step, what: &'static str) -> Result<()> {
        let mut faults = self.faults();
        let count = faults.counts[step as usize];
        faults.counts[step as usize] += 1;
        if faults.fail == Some((step, count)) {
            return Err(cuda_error(what, format!("planted fault ({step:?})")));
        }
        Ok(())
    }
}

fn lock<T>(mutex: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    mutex.lock().unwrap_or_else(|e| e.into_inner())
}

/// A kernel argument as cuLaunchKernel takes it: a pointer to the argument's value.
#[repr(C)]
union Slot {
    pointer: *mut c_void,
    int: i32,
    real: f64,
}

/// The argument pointers, shared with the threads that run the blocks (which only read
/// them; the buffers they point to are the launch's).
#[derive(Clone, Copy)]
struct Params(*mut *mut c_void);
// SAFETY: the pointers outlive the threads (a scope); the kernels' writes are the
// device's, as on a GPU.
unsafe impl Send for Params {}

impl Device for Emulator {
    type Buffer<T: Elem> = HostBuffer<T>;
    type Plan = HostPlan;

    fn threads(&self) -> u32 {
        self.threads
    }
    fn zeros<T: Elem>(&self, len: usize) -> Result<HostBuffer<T>> {
        self.step(Step::Alloc, "cuMemAlloc")?;
        // SAFETY: `T: ValidAsZeroBits`.
        Ok(HostBuffer(vec![unsafe { std::mem::zeroed::<T>() }; len]))
    }
    fn len<T: Elem>(buffer: &HostBuffer<T>) -> usize {
        buffer.0.len()
    }
    fn htod<T: Elem>(&self, what: &'static str, src: &[T], dst: &mut HostBuffer<T>) -> Result<()> {
        self.step(Step::Copy, what)?;
        check_copy(what, src.len(), dst.0.len())?;
        dst.0[..src.len()].copy_from_slice(src);
        Ok(())
    }
    fn dtoh<T: Elem>(&self, what: &'static str, src: &HostBuffer<T>, dst: &mut [T]) -> Result<()> {
        self.step(Step::Copy, what)?;
        check_copy(what, dst.len(), src.0.len())?;
        dst.copy_from_slice(&src.0[..dst.len()]);
        Ok(())
    }
    fn dtod<T: Elem>(
        &self,
        what: &'static str,
        src: &HostBuffer<T>,
        dst: &mut HostBuffer<T>,
    ) -> Result<()> {
        self.step(Step::Copy, what)?;
        check_copy(what, src.0.len(), dst.0.len())?;
        dst.0[..src.0.len()].copy_from_slice(&src.0);
        Ok(())
    }
    unsafe fn launch(
        &self,
        kernel: KernelId,
        cfg: LaunchConfig,
        args: &mut [Arg<'_, Self>],
    ) -> Result<()> {
        let name = kernel.name;
        self.step(Step::Launch, name)?;
        {
            let mut faults = self.faults();
            faults.launched.resize(Kernel::ALL.len(), false);
            faults.launched[kernel.index] = true;
        }
        if cfg.block_dim != (self.threads, 1, 1)
            || (cfg.grid_dim.1, cfg.grid_dim.2) != (1, 1)
            || cfg.grid_dim.0 == 0
        {
            return Err(cuda_error(
                name,
                format!(
                    "launch of {:?} blocks of {:?} threads: the emulator runs 1-D grids of \
                     blocks of {} threads",
                    cfg.grid_dim, cfg.block_dim, self.threads
                ),
            ));
        }
        let mut slots: Vec<Slot> = args
            .iter_mut()
            .map(|arg| match arg {
                Arg::Real(b) => Slot {
                    pointer: b.0.as_ptr() as *mut c_void,
                },
                Arg::RealMut(b) => Slot {
                    pointer: b.0.as_mut_ptr().cast(),
                },
                Arg::Int(b) => Slot {
                    pointer: b.0.as_ptr() as *mut c_void,
                },
                Arg::IntMut(b) => Slot {
                    pointer: b.0.as_mut_ptr().cast(),
                },
                Arg::Complex(b) => Slot {
                    pointer: b.0.as_ptr() as *mut c_void,
                },
                Arg::ComplexMut(b) => Slot {
                    pointer: b.0.as_mut_ptr().cast(),
                },
                Arg::I32(v) => Slot { int: *v },
                Arg::F64(v) => Slot { real: *v },
            })
            .collect();
        let mut pointers: Vec<*mut c_void> = slots
            .iter_mut()
            .map(|s| (s as *mut Slot).cast::<c_void>())
            .collect();
        let params = Params(pointers.as_mut_ptr());
        let grid = cfg.grid_dim.0;
        let (block, workers) = (self.build.block, self.build.lanes.min(grid));
        let _serial = lock(&self.build.serial);
        // Worker `w` runs blocks w, w + workers, ... in lane `w`.
        let status = std::thread::scope(|scope| {
            let running: Vec<_> = (0..workers)
                .map(|w| {
                    scope.spawn(move || {
                        let params = params;
                        let mut b = w;
                        while b < grid {
                            // SAFETY: the arguments are the kernel's (the caller's), each
                            // slot alive until the scope ends.
                            let status =
                                unsafe { block(w as i32, kernel.index as i32, grid, b, params.0) };
                            if status != 0 {
                                return status;
                            }
                            b += workers;
                        }
                        0
                    })
                })
                .collect();
            running
                .into_iter()
                .map(|r| r.join().unwrap_or(3))
                .max()
                .unwrap_or(0)
        });
        match status {
            0 => Ok(()),
            2 => Err(cuda_error(
                name,
                "a block's threads did not all reach a barrier (__syncthreads)",
            )),
            _ => Err(cuda_error(name, "the emulator has no such kernel")),
        }
    }
    fn plan(&self, kind: FftKind, n: &[usize], batch: usize) -> Result<HostPlan> {
        self.step(Step::Plan, "cufftPlanMany")?;
        if n.is_empty() || n.len() > 3 || n.contains(&0) || batch == 0 {
            return Err(cuda_error(
                "cufftPlanMany",
                format!("no plan of {n:?} x {batch}"),
            ));
        }
        Ok(HostPlan {
            kind,
            dims: n.to_vec(),
            batch,
        })
    }
    fn d2z(
        &self,
        what: &'static str,
        plan: &HostPlan,
        input: &HostBuffer<f64>,
        output: &mut HostBuffer<double2>,
    ) -> Result<()> {
        self.step(Step::Launch, what)?;
        plan.check(what, FftKind::D2Z, input.0.len(), output.0.len())?;
        let (real, half) = (plan.real_len(), plan.half_len());
        for b in 0..plan.batch {
            d2z(
                &plan.dims,
                &input.0[b * real..(b + 1) * real],
                &mut output.0[b * half..(b + 1) * half],
            );
        }
        Ok(())
    }
    fn z2d(
        &self,
        what: &'static str,
        plan: &HostPlan,
        input: &mut HostBuffer<double2>,
        output: &mut HostBuffer<f64>,
    ) -> Result<()> {
        self.step(Step::Launch, what)?;
        plan.check(what, FftKind::Z2D, output.0.len(), input.0.len())?;
        let (real, half) = (plan.real_len(), plan.half_len());
        for b in 0..plan.batch {
            z2d(
                &plan.dims,
                &input.0[b * half..(b + 1) * half],
                &mut output.0[b * real..(b + 1) * real],
            );
        }
        let nan = double2 {
            x: f64::NAN,
            y: f64::NAN,
        };
        input.0[..plan.batch * half].fill(nan);
        Ok(())
    }
    fn synchronize(&self, what: &'static str) -> Result<()> {
        self.step(Step::Synchronize, what)
    }
}

impl HostPlan {
    /// Real values per transform.
    fn real_len(&self) -> usize {
        self.dims.iter().product()
    }
    /// Complex values per transform (the last dimension halved).
    fn half_len(&self) -> usize {
        let (last, rest) = self.dims.split_last().expect("a plan has dimensions");
        rest.iter().product::<usize>() * (last / 2 + 1)
    }
    /// The plan's kind, and buffers that hold its batches.
    fn check(&self, what: &'static str, kind: FftKind, real: usize, half: usize) -> Result<()> {
        if self.kind != kind {
            return Err(cuda_error(
                what,
                format!("a {:?} plan run as {kind:?}", self.kind),
            ));
        }
        if real < self.batch * self.real_len() || half < self.batch * self.half_len() {
            return Err(cuda_error(
                what,
                format!(
                    "buffers of {real} real and {half} complex values for {} transforms of {:?}",
                    self.batch, self.dims
                ),
            ));
        }
        Ok(())
    }
}

/// `index`'s coordinates in the row-major array of dimensions `dims`.
fn unravel(mut index: usize, dims: &[usize], out: &mut [usize]) {
    for (d, &n) in dims.iter().enumerate().rev() {
        out[d] = index % n;
        index /= n;
    }
}

/// `e^{i 2π Σ_d j_d k_d / n_d}` (`sign` = 1) or its conjugate (-1), each dimension's
/// phase reduced modulo its length before the angle is formed.
fn phase(j: &[usize], k: &[usize], dims: &[usize], sign: f64) -> (f64, f64) {
    let (mut re, mut im) = (1.0f64, 0.0f64);
    for ((&j, &k), &n) in j.iter().zip(k).zip(dims) {
        let angle = 2.0 * std::f64::consts::PI * ((j * k) % n) as f64 / n as f64;
        let (s, c) = (sign * angle.sin(), angle.cos());
        (re, im) = (re * c - im * s, re * s + im * c);
    }
    (re, im)
}

/// One `D2Z` transform: `X[k] = Σ_j x[j] e^{-i 2π j·k / n}`, `k` over the half spectrum.
fn d2z(dims: &[usize], x: &[f64], out: &mut [double2]) {
    let mut half = dims.to_vec();
    let last = half.len() - 1;
    half[last] = dims[last] / 2 + 1;
    let (mut j, mut k) = (vec![0; dims.len()], vec![0; dims.len()]);
    for (o, value) in out.iter_mut().enumerate() {
        unravel(o, &half, &mut k);
        let (mut re, mut im) = (0.0, 0.0);
        for (i, &xi) in x.iter().enumerate() {
            unravel(i, dims, &mut j);
            let (c, s) = phase(&j, &k, dims, -1.0);
            re += xi * c;
            im += xi * s;
        }
        *value = double2 { x: re, y: im };
    }
}

/// One `Z2D` transform: `x[j] = Σ_k X[k] e^{+i 2π j·k / n}` over the full spectrum, its
/// other half by Hermitian symmetry (`X[k] = conj(X[-k])`).
fn z2d(dims: &[usize], spectrum: &[double2], out: &mut [f64]) {
    let rank = dims.len();
    let last = rank - 1;
    let half_last = dims[last] / 2 + 1;
    let (mut j, mut k, mut mirrored) = (vec![0; rank], vec![0; rank], vec![0; rank]);
    let full: usize = dims.iter().product();
    for (o, value) in out.iter_mut().enumerate() {
        unravel(o, dims, &mut j);
        let mut sum = 0.0;
        for f in 0..full {
            unravel(f, dims, &mut k);
            let z = if k[last] < half_last {
                spectrum[at_half(&k, dims, half_last)]
            } else {
                for ((m, &kd), &n) in mirrored.iter_mut().zip(&k).zip(dims) {
                    *m = (n - kd) % n;
                }
                let z = spectrum[at_half(&mirrored, dims, half_last)];
                double2 { x: z.x, y: -z.y }
            };
            let (c, s) = phase(&j, &k, dims, 1.0);
            sum += z.x * c - z.y * s;
        }
        *value = sum;
    }
}

/// The index of `k` in a half spectrum (last dimension `half_last` long).
fn at_half(k: &[usize], dims: &[usize], half_last: usize) -> usize {
    let last = dims.len() - 1;
    let index = k[..last]
        .iter()
        .zip(&dims[..last])
        .fold(0, |index, (&kd, &n)| index * n + kd);
    index * half_last + k[last]
}

/// emulated.cpp built with `threads` threads per block and loaded, once per process and
/// version of its sources (kernels.cu, emulated.cpp, the kernel list): the library sits
/// beside the test binary (under `target/`), named by a hash of them, so later test
/// processes reuse it. Written under a name of this process's, then renamed: two test
/// processes never see half a library.
fn build(threads: u32) -> &'static Build {
    use std::hash::{Hash, Hasher};
    static BUILDS: Mutex<Vec<(u32, &'static Build)>> = Mutex::new(Vec::new());
    let mut builds = lock(&BUILDS);
    if let Some((_, b)) = builds.iter().find(|(t, _)| *t == threads) {
        return b;
    }
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src/solver/cuda");
    let shim = std::fs::read(here.join("emulated.cpp")).expect("emulated.cpp");
    // kernels.cu without `extern "C"`, so that each lane's namespace has its own copy.
    let host_source = SOURCE.replace("extern \"C\" ", "");
    let list: String = Kernel::ALL
        .iter()
        .map(|k| format!("KERNEL({})\n", k.name()))
        .collect();
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    (&shim, &host_source, &list).hash(&mut hasher);
    let dir = std::env::current_exe()
        .ok()
        .and_then(|exe| exe.parent().map(PathBuf::from))
        .unwrap_or_else(std::env::temp_dir)
        .join(format!(
            "precursors-emulated-{threads}-{:016x}",
            hasher.finish()
        ));
    let library = dir.join("libemulated.so");
    if !library.exists() {
        let partial = dir.with_extension(format!("{}.partial", std::process::id()));
        let _ = std::fs::remove_dir_all(&partial);
        std::fs::create_dir_all(&partial).expect("the emulator's directory");
        std::fs::write(partial.join("kernels_host.cu"), &host_source).expect("written");
        std::fs::write(partial.join("kernel_list.inc"), &list).expect("written");
        let status = Command::new("c++")
            .args(["-O2", "-std=c++17", "-pthread", "-shared", "-fPIC"])
            .arg(threads_define(threads))
            .arg("-I")
            .arg(&partial)
            .arg("-o")
            .arg(partial.join("libemulated.so"))
            .arg(here.join("emulated.cpp"))
            .status()
            .expect("a C++ compiler (c++) runs kernels.cu on the host");
        assert!(status.success(), "emulated.cpp does not compile");
        // Another process may have put its own in place meanwhile: either will do.
        if std::fs::rename(&partial, &dir).is_err() {
            let _ = std::fs::remove_dir_all(&partial);
        }
    }
    // SAFETY: the library is emulated.cpp, whose initialisers have no effects; it stays
    // loaded for the process (the build is leaked).
    let loaded = unsafe { libloading::Library::new(&library) }.expect("the emulator loads");
    // SAFETY: the symbols' types are emulated.cpp's `extern "C"` functions.
    let build = unsafe {
        let block: BlockFn = *loaded
            .get::<BlockFn>(b"precursors_emulated_block\0")
            .expect("symbol");
        let most_in_flight = *loaded
            .get::<unsafe extern "C" fn() -> i32>(b"precursors_emulated_most_in_flight\0")
            .expect("symbol");
        let lanes = loaded
            .get::<unsafe extern "C" fn() -> i32>(b"precursors_emulated_lanes\0")
            .expect("symbol")();
        let built_threads = loaded
            .get::<unsafe extern "C" fn() -> i32>(b"precursors_emulated_threads\0")
            .expect("symbol")();
        assert_eq!(built_threads as u32, threads);
        Build {
            block,
            most_in_flight,
            lanes: lanes as u32,
            serial: Mutex::new(()),
            _library: loaded,
        }
    };
    let build: &'static Build = Box::leak(Box::new(build));
    builds.push((threads, build));
    build
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A direct 2-D DFT written here: `X[k0][k1] = Σ x[j0][j1] e^{-2πi (j0 k0/n0 + j1
    /// k1/n1)}`, the angle formed in one expression.
    fn direct(x: &[f64], n0: usize, n1: usize, k0: usize, k1: usize) -> (f64, f64) {
        let (mut re, mut im) = (0.0, 0.0);
        for j0 in 0..n0 {
            for j1 in 0..n1 {
                let t = -2.0
                    * std::f64::consts::PI
                    * (j0 as f64 * k0 as f64 / n0 as f64 + j1 as f64 * k1 as f64 / n1 as f64);
                re += x[j0 * n1 + j1] * t.cos();
                im += x[j0 * n1 + j1] * t.sin();
            }
        }
        (re, im)
    }

    /// cuFFT's layout (n0 x (n1/2 + 1) complex values, row-major) and its normalisation
    /// (none: Z2D(D2Z(x)) = n0 n1 x), on an even and an odd grid, two batches each; and
    /// the batched 1-D plans of the backend (lines one after the other).
    #[test]
    fn the_ffts_are_cuffts_packed_and_unnormalised() {
        let device = Emulator::new(1);
        for (n0, n1) in [(4, 6), (5, 3)] {
            let (real, half) = (n0 * n1, n0 * (n1 / 2 + 1));
            let batch = 2;
            let x: Vec<f64> = (0..batch * real)
                .map(|i| ((i * 37 + 11) % 17) as f64 - 8.0)
                .collect();
            let input = device.upload("test", &x).unwrap();
            let mut spectrum = device.zeros::<double2>(batch * half).unwrap();
            let forward = device.plan(FftKind::D2Z, &[n0, n1], batch).unwrap();
            device.d2z("test", &forward, &input, &mut spectrum).unwrap();
            assert_eq!(spectrum.0.len(), batch * n0 * (n1 / 2 + 1));
            for b in 0..batch {
                for k0 in 0..n0 {
                    for k1 in 0..n1 / 2 + 1 {
                        let (re, im) = direct(&x[b * real..], n0, n1, k0, k1);
                        let z = spectrum.0[b * half + k0 * (n1 / 2 + 1) + k1];
                        assert!(
                            (z.x - re).abs() < 1e-12 && (z.y - im).abs() < 1e-12,
                            "{n0} x {n1}, batch {b}, ({k0}, {k1}): {z:?} against ({re}, {im})"
                        );
                    }
                }
            }
            let inverse = device.plan(FftKind::Z2D, &[n0, n1], batch).unwrap();
            let mut back = device.zeros::<f64>(batch * real).unwrap();
            device
                .z2d("test", &inverse, &mut spectrum, &mut back)
                .unwrap();
            for (i, (b, x)) in back.0.iter().zip(&x).enumerate() {
                assert!(
                    (b - real as f64 * x).abs() < 1e-11,
                    "{n0} x {n1}, value {i}: {b} against {real} x {x}"
                );
            }
            assert!(spectrum.0.iter().all(|z| z.x.is_nan()), "Z2D's input spent");
            // The wrong kind, or buffers too small, are refused.
            assert!(device.d2z("test", &inverse, &input, &mut spectrum).is_err());
            let mut small = device.zeros::<double2>(half).unwrap();
            assert!(device.d2z("test", &forward, &input, &mut small).is_err());
        }
        // Batched 1-D lines of 6 and of 5: each line's half spectrum after the last.
        for n in [6, 5] {
            let lines = 3;
            let x: Vec<f64> = (0..lines * n).map(|i| (i % 7) as f64 - 2.5).collect();
            let input = device.upload("test", &x).unwrap();
            let mut spectrum = device.zeros::<double2>(lines * (n / 2 + 1)).unwrap();
            let plan = device.plan(FftKind::D2Z, &[n], lines).unwrap();
            device.d2z("test", &plan, &input, &mut spectrum).unwrap();
            for l in 0..lines {
                for k in 0..n / 2 + 1 {
                    let (re, im) = direct(&x[l * n..], 1, n, 0, k);
                    let z = spectrum.0[l * (n / 2 + 1) + k];
                    assert!((z.x - re).abs() < 1e-12 && (z.y - im).abs() < 1e-12);
                }
            }
        }
    }

    /// Copies past a buffer's end and launch shapes the build does not run are errors.
    #[test]
    fn bad_copies_and_shapes_are_refused() {
        let device = Emulator::new(4);
        let mut small = device.zeros::<f64>(2).unwrap();
        let e = device
            .htod("cuMemcpyHtoD (x)", &[1.0; 3], &mut small)
            .unwrap_err();
        assert!(e.to_string().contains("cuMemcpyHtoD (x)"), "{e}");
        let mut out = [0.0; 3];
        assert!(device.dtoh("d", &small, &mut out).is_err());
        let r = device.zeros::<f64>(4).unwrap();
        let mut z = device.zeros::<f64>(4).unwrap();
        let d = device.zeros::<f64>(4).unwrap();
        let cfg = super::super::seam::blocks(THREADS, "test", 1).unwrap();
        use super::super::kernels::Launch;
        // SAFETY: every buffer holds 4 values.
        let e = unsafe { device.jacobi(cfg, &r, &d, 1.0, &mut z, 4) }.unwrap_err();
        assert!(e.to_string().contains("jacobi"), "{e}");
    }
}

//! The one seam between the backend's launch code and a device: allocation, copies,
//! kernel launches by typed kernel (kernels.rs), cuFFT's real transforms and
//! synchronisation. Everything above it (operator.rs, phases.rs, fsai.rs, coarse.rs,
//! mod.rs: grid and block sizes, offsets, copy lengths, plans) is one code for every
//! device. Two devices implement it: the GPU through cudarc (`device::Cuda`) and, in the
//! tests, a host emulator that runs kernels.cu compiled by the C++ compiler
//! (`emulator.rs`), so the launch code runs in the tests as on the GPU.
//!
//! Every step returns a `Result`: a failed step is [`Error::Cuda`] naming the call and the
//! step it served (`cuMemcpyDtoH (reduction)`, a kernel's name), and nothing after it
//! runs.

use super::kernels::{self, Kernel};
use crate::error::{Error, Result};
use cudarc::cufft::sys::double2;
use cudarc::driver::{DeviceRepr, LaunchConfig, ValidAsZeroBits};

/// A value type the kernels' buffers hold (`double`, `int`, `double2`).
pub(crate) trait Elem: DeviceRepr + ValidAsZeroBits + Copy + Send + Sync + 'static {
    /// A buffer of these as a kernel argument it reads.
    fn arg<D: Device + ?Sized>(buffer: &D::Buffer<Self>) -> Arg<'_, D>;
    /// A buffer of these as a kernel argument it writes.
    fn arg_mut<D: Device + ?Sized>(buffer: &mut D::Buffer<Self>) -> Arg<'_, D>;
}

impl Elem for f64 {
    fn arg<D: Device + ?Sized>(buffer: &D::Buffer<Self>) -> Arg<'_, D> {
        Arg::Real(buffer)
    }
    fn arg_mut<D: Device + ?Sized>(buffer: &mut D::Buffer<Self>) -> Arg<'_, D> {
        Arg::RealMut(buffer)
    }
}

impl Elem for i32 {
    fn arg<D: Device + ?Sized>(buffer: &D::Buffer<Self>) -> Arg<'_, D> {
        Arg::Int(buffer)
    }
    fn arg_mut<D: Device + ?Sized>(buffer: &mut D::Buffer<Self>) -> Arg<'_, D> {
        Arg::IntMut(buffer)
    }
}

impl Elem for double2 {
    fn arg<D: Device + ?Sized>(buffer: &D::Buffer<Self>) -> Arg<'_, D> {
        Arg::Complex(buffer)
    }
    fn arg_mut<D: Device + ?Sized>(buffer: &mut D::Buffer<Self>) -> Arg<'_, D> {
        Arg::ComplexMut(buffer)
    }
}

/// A value a kernel takes by value (`int`, `double`).
pub(crate) trait Value: Copy {
    /// As a kernel argument.
    fn arg<'a, D: Device + ?Sized>(self) -> Arg<'a, D>;
}

impl Value for i32 {
    fn arg<'a, D: Device + ?Sized>(self) -> Arg<'a, D> {
        Arg::I32(self)
    }
}

impl Value for f64 {
    fn arg<'a, D: Device + ?Sized>(self) -> Arg<'a, D> {
        Arg::F64(self)
    }
}

/// One kernel argument, as kernels.rs's typed launches pass it (in the kernel's order).
pub(crate) enum Arg<'a, D: Device + ?Sized> {
    Real(&'a D::Buffer<f64>),
    RealMut(&'a mut D::Buffer<f64>),
    Int(&'a D::Buffer<i32>),
    IntMut(&'a mut D::Buffer<i32>),
    Complex(&'a D::Buffer<double2>),
    ComplexMut(&'a mut D::Buffer<double2>),
    I32(i32),
    F64(f64),
}

/// cuFFT's real transforms (double precision), unnormalised both ways.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum FftKind {
    /// Real to complex (`CUFFT_D2Z`): `n/2 + 1` outputs along the last dimension.
    D2Z,
    /// Complex to real (`CUFFT_Z2D`): the inverse of the same half spectra.
    Z2D,
}

/// A device: where the backend's buffers live and its kernels run. Work runs in the order
/// it is asked for (one stream); the host reads a copy's values after a
/// [`Device::synchronize`].
pub(crate) trait Device: std::fmt::Debug + Send + Sync {
    /// `len` values on the device.
    type Buffer<T: Elem>: Send + Sync;
    /// A cuFFT plan.
    type Plan: Send + Sync;

    /// Threads per block of every launch (kernels.cu's `THREADS` as this device was
    /// given it).
    fn threads(&self) -> u32;
    /// `len` zeros (every buffer of the backend is allocated here).
    fn zeros<T: Elem>(&self, len: usize) -> Result<Self::Buffer<T>>;
    /// The values `buffer` holds.
    fn len<T: Elem>(buffer: &Self::Buffer<T>) -> usize;
    /// `src` to the first `src.len()` values of `dst`.
    fn htod<T: Elem>(&self, what: &'static str, src: &[T], dst: &mut Self::Buffer<T>)
        -> Result<()>;
    /// The first `dst.len()` values of `src` to the host.
    fn dtoh<T: Elem>(&self, what: &'static str, src: &Self::Buffer<T>, dst: &mut [T])
        -> Result<()>;
    /// All of `src` to the first values of `dst`.
    fn dtod<T: Elem>(
        &self,
        what: &'static str,
        src: &Self::Buffer<T>,
        dst: &mut Self::Buffer<T>,
    ) -> Result<()>;
    /// Launches `kernel` with `args` (kernels.rs's typed launches build them).
    ///
    /// # Safety
    /// The arguments are the kernel's parameters in its order and types, and every buffer
    /// holds the values the kernel reads or writes under `cfg`.
    unsafe fn launch(
        &self,
        kernel: Kernel,
        cfg: LaunchConfig,
        args: &mut [Arg<'_, Self>],
    ) -> Result<()>;
    /// A plan of `batch` transforms of `kind`, each of the dimensions `n` (row-major, the
    /// last one halved in the spectrum), in cuFFT's basic layout: contiguous, one after
    /// the other.
    fn plan(&self, kind: FftKind, n: &[usize], batch: usize) -> Result<Self::Plan>;
    /// A `D2Z` plan's transforms of `input` into `output`.
    fn d2z(
        &self,
        what: &'static str,
        plan: &Self::Plan,
        input: &Self::Buffer<f64>,
        output: &mut Self::Buffer<double2>,
    ) -> Result<()>;
    /// A `Z2D` plan's transforms of `input` into `output`. `input` is overwritten (cuFFT
    /// documents that an out-of-place complex-to-real transform may overwrite it).
    fn z2d(
        &self,
        what: &'static str,
        plan: &Self::Plan,
        input: &mut Self::Buffer<double2>,
        output: &mut Self::Buffer<f64>,
    ) -> Result<()>;
    /// Waits until everything asked for has run.
    fn synchronize(&self, what: &'static str) -> Result<()>;
    /// Makes the device current on the calling thread (before buffers are freed on a
    /// thread other than the one that made them).
    fn bind_to_thread(&self) {}

    /// `values` in a new buffer.
    fn upload<T: Elem>(&self, what: &'static str, values: &[T]) -> Result<Self::Buffer<T>> {
        let mut buffer = self.zeros(values.len())?;
        self.htod(what, values, &mut buffer)?;
        Ok(buffer)
    }
    /// One thread per element of `n` in blocks of [`Device::threads`], `None` for none.
    fn over(&self, what: &'static str, n: usize) -> Result<Option<LaunchConfig>> {
        kernels::over(self.threads(), what, n)
    }
    /// `count` blocks of [`Device::threads`].
    fn blocks(&self, what: &'static str, count: usize) -> Result<LaunchConfig> {
        kernels::blocks(self.threads(), what, count)
    }
}

/// A copy's lengths checked (a copy past a buffer's end is an error of the call, never a
/// write past it).
pub(crate) fn check_copy(what: &'static str, from: usize, into: usize) -> Result<()> {
    if from > into {
        return Err(Error::Cuda {
            call: what,
            message: format!("a copy of {from} values into {into}"),
        });
    }
    Ok(())
}

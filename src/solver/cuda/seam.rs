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

/// A kernel of kernels.cu as a device finds it (kernels.rs's `Kernel`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct KernelId {
    /// Its index among kernels.rs's declarations.
    pub(crate) index: usize,
    /// Its name in kernels.cu.
    pub(crate) name: &'static str,
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
        kernel: KernelId,
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
        over(self.threads(), what, n)
    }
    /// `count` blocks of [`Device::threads`].
    fn blocks(&self, what: &'static str, count: usize) -> Result<LaunchConfig> {
        blocks(self.threads(), what, count)
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

/// `value` as the kernels' `int`, else [`Error::DeviceLimit`] naming `what`.
pub(crate) fn int(what: &'static str, value: usize) -> Result<i32> {
    i32::try_from(value).map_err(|_| Error::DeviceLimit {
        what,
        value: value as u64,
        limit: i32::MAX as u64,
    })
}

/// `blocks` blocks of `threads` threads (a grid's x dimension is a `u32`): the device's
/// own count ([`Device::blocks`]), kernels.rs's `THREADS` on a GPU.
pub(crate) fn blocks(threads: u32, what: &'static str, blocks: usize) -> Result<LaunchConfig> {
    let grid = u32::try_from(blocks).map_err(|_| Error::DeviceLimit {
        what,
        value: blocks as u64,
        limit: u32::MAX as u64,
    })?;
    Ok(LaunchConfig {
        grid_dim: (grid, 1, 1),
        block_dim: (threads, 1, 1),
        shared_mem_bytes: 0,
    })
}

/// One thread per element of `n` in blocks of `threads`, `None` for none (a launch of no
/// blocks is an error). The kernels index the elements with an `int`, so `n` must fit
/// one.
pub(crate) fn over(threads: u32, what: &'static str, n: usize) -> Result<Option<LaunchConfig>> {
    if n == 0 {
        return Ok(None);
    }
    int(what, n)?;
    blocks(threads, what, n.div_ceil(threads as usize)).map(Some)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::cuda::kernels::THREADS;

    #[test]
    fn sizes_past_the_kernels_integers_are_errors() {
        assert_eq!(int("m", 7).unwrap(), 7);
        let limit = i32::MAX as usize;
        assert_eq!(int("m", limit).unwrap(), i32::MAX);
        let e = int("sites in the set", limit + 1).unwrap_err();
        assert!(
            matches!(e, Error::DeviceLimit { what: "sites in the set", value, limit }
                if value == 1 << 31 && limit == (1 << 31) - 1),
            "{e:?}"
        );
        assert!(over(THREADS, "m", 0).unwrap().is_none());
        let one = over(THREADS, "m", 1).unwrap().unwrap();
        assert_eq!((one.grid_dim, one.block_dim), ((1, 1, 1), (THREADS, 1, 1)));
        let last = over(THREADS, "m", limit).unwrap().unwrap();
        assert_eq!(last.grid_dim.0, (limit as u32).div_ceil(THREADS));
        assert!(matches!(
            over(THREADS, "m", limit + 1),
            Err(Error::DeviceLimit { .. })
        ));
        let four = over(4, "m", 9).unwrap().unwrap();
        assert_eq!((four.grid_dim, four.block_dim), ((3, 1, 1), (4, 1, 1)));
        assert_eq!(
            blocks(THREADS, "b", u32::MAX as usize).unwrap().grid_dim.0,
            u32::MAX
        );
        assert!(matches!(
            blocks(THREADS, "b", u32::MAX as usize + 1),
            Err(Error::DeviceLimit { what: "b", .. })
        ));
    }
}

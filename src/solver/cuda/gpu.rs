//! The GPU as the backend's [`Device`] (the seam, seam.rs): cudarc's buffers, kernel
//! launches, copies and cuFFT plans on the GPU's one stream.

use super::device::{cuda_error, Gpu};
use super::kernels::{Kernels, THREADS};
use super::seam::{check_copy, int, Arg, Device, Elem, FftKind, KernelId};
use crate::error::Result;
use cudarc::cufft::sys::{cufftType, double2};
use cudarc::cufft::CudaFft;
use cudarc::driver::{CudaSlice, LaunchConfig, PushKernelArg};

/// The GPU as the backend's [`Device`]: its stream, the kernels loaded on it, cuFFT's
/// plans on the same stream.
pub(crate) struct Cuda {
    pub(super) gpu: Gpu,
    pub(super) kernels: Kernels,
}

impl std::fmt::Debug for Cuda {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.gpu.fmt(f)
    }
}

/// A cuFFT plan and its kind.
pub(crate) struct CudaPlan {
    fft: CudaFft,
    kind: FftKind,
}

/// A plan executed as the other kind would write past its buffers: refused.
fn check_kind(what: &'static str, plan: &CudaPlan, kind: FftKind) -> Result<()> {
    if plan.kind != kind {
        return Err(cuda_error(
            what,
            format!("a {:?} plan run as {kind:?}", plan.kind),
        ));
    }
    Ok(())
}

impl Device for Cuda {
    type Buffer<T: Elem> = CudaSlice<T>;
    type Plan = CudaPlan;

    fn threads(&self) -> u32 {
        THREADS
    }
    fn zeros<T: Elem>(&self, len: usize) -> Result<CudaSlice<T>> {
        self.gpu
            .stream
            .alloc_zeros::<T>(len)
            .map_err(|e| cuda_error("cuMemAlloc", e))
    }
    fn len<T: Elem>(buffer: &CudaSlice<T>) -> usize {
        buffer.len()
    }
    fn htod<T: Elem>(&self, what: &'static str, src: &[T], dst: &mut CudaSlice<T>) -> Result<()> {
        check_copy(what, src.len(), dst.len())?;
        if src.is_empty() {
            return Ok(());
        }
        self.gpu
            .stream
            .memcpy_htod(src, &mut dst.slice_mut(0..src.len()))
            .map_err(|e| cuda_error(what, e))
    }
    fn dtoh<T: Elem>(&self, what: &'static str, src: &CudaSlice<T>, dst: &mut [T]) -> Result<()> {
        check_copy(what, dst.len(), src.len())?;
        if dst.is_empty() {
            return Ok(());
        }
        self.gpu
            .stream
            .memcpy_dtoh(&src.slice(0..dst.len()), dst)
            .map_err(|e| cuda_error(what, e))
    }
    fn dtod<T: Elem>(
        &self,
        what: &'static str,
        src: &CudaSlice<T>,
        dst: &mut CudaSlice<T>,
    ) -> Result<()> {
        check_copy(what, src.len(), dst.len())?;
        if src.is_empty() {
            return Ok(());
        }
        self.gpu
            .stream
            .memcpy_dtod(src, &mut dst.slice_mut(0..src.len()))
            .map_err(|e| cuda_error(what, e))
    }
    unsafe fn launch(
        &self,
        kernel: KernelId,
        cfg: LaunchConfig,
        args: &mut [Arg<'_, Self>],
    ) -> Result<()> {
        let mut builder = self
            .gpu
            .stream
            .launch_builder(self.kernels.function(kernel));
        for arg in args.iter_mut() {
            match arg {
                Arg::Real(b) => builder.arg(*b),
                Arg::RealMut(b) => builder.arg(&mut **b),
                Arg::Int(b) => builder.arg(*b),
                Arg::IntMut(b) => builder.arg(&mut **b),
                Arg::Complex(b) => builder.arg(*b),
                Arg::ComplexMut(b) => builder.arg(&mut **b),
                Arg::I32(v) => builder.arg(&*v),
                Arg::F64(v) => builder.arg(&*v),
            };
        }
        // SAFETY: the caller's (the arguments are the kernel's, the buffers large enough).
        unsafe { builder.launch(cfg) }
            .map(|_| ())
            .map_err(|e| cuda_error(kernel.name, e))
    }
    fn plan(&self, kind: FftKind, n: &[usize], batch: usize) -> Result<CudaPlan> {
        let dims = n
            .iter()
            .map(|&len| int("FFT length", len))
            .collect::<Result<Vec<i32>>>()?;
        let batch = int("FFT batch", batch)?;
        let kind_c = match kind {
            FftKind::D2Z => cufftType::CUFFT_D2Z,
            FftKind::Z2D => cufftType::CUFFT_Z2D,
        };
        let fft = CudaFft::plan_many(
            &dims,
            None,
            1,
            0,
            None,
            1,
            0,
            kind_c,
            batch,
            self.gpu.stream.clone(),
        )
        .map_err(|e| cuda_error("cufftPlanMany", e))?;
        Ok(CudaPlan { fft, kind })
    }
    fn d2z(
        &self,
        what: &'static str,
        plan: &CudaPlan,
        input: &CudaSlice<f64>,
        output: &mut CudaSlice<double2>,
    ) -> Result<()> {
        check_kind(what, plan, FftKind::D2Z)?;
        plan.fft
            .exec_d2z(input, output)
            .map_err(|e| cuda_error(what, e))
    }
    fn z2d(
        &self,
        what: &'static str,
        plan: &CudaPlan,
        input: &mut CudaSlice<double2>,
        output: &mut CudaSlice<f64>,
    ) -> Result<()> {
        check_kind(what, plan, FftKind::Z2D)?;
        plan.fft
            .exec_z2d(input, output)
            .map_err(|e| cuda_error(what, e))
    }
    fn synchronize(&self, what: &'static str) -> Result<()> {
        self.gpu
            .stream
            .synchronize()
            .map_err(|e| cuda_error(what, e))
    }
    fn bind_to_thread(&self) {
        let _ = self.gpu.ctx.bind_to_thread();
    }
}

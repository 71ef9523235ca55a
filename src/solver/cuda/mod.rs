//! The CUDA backend (feature `cuda`): the spectral backend's rule on an NVIDIA GPU.

// Kernel launches, copies and libraries opened by path are unsafe calls of the bindings;
// each says why it is sound.
#![allow(unsafe_code)]

mod device;
mod libraries;

pub use device::{cuda_device, CudaDevice};

use super::pcg::Effort;
use super::set::{SetProblem, SetSolve};
use super::spectral::Precond;
use super::system::Compliance;
use crate::error::{Error, Result};
use crate::green::InfluencePlan;
use device::Gpu;

/// The device's state kept between solves.
#[derive(Debug)]
pub(crate) struct CudaCore {
    _gpu: Gpu,
    inverse_mean: Option<f64>,
}

impl CudaCore {
    pub(crate) fn new(_plan: &InfluencePlan, _compliance: Compliance) -> Result<Self> {
        let _gpu = Gpu::open()?;
        Err(Error::CudaUnavailable {
            reason: "the device solves are not built yet".into(),
            hint: "use backend \"spectral\"".into(),
        })
    }

    pub(crate) fn preconditioner_mean(&self) -> Option<f64> {
        self.inverse_mean
    }

    pub(crate) fn restore_preconditioner(&mut self, mean: Option<f64>) {
        self.inverse_mean = mean;
    }

    pub(crate) fn solve(
        &mut self,
        _problem: SetProblem<'_>,
        _precond: Precond,
        _f: Vec<f64>,
        _effort: Effort,
    ) -> Result<SetSolve> {
        Err(Error::CudaUnavailable {
            reason: "the device solves are not built yet".into(),
            hint: "use backend \"spectral\"".into(),
        })
    }
}

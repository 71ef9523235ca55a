//! The CUDA libraries the backend needs (`libcuda`, `libcufft`, `libnvrtc`): where they are
//! searched, opened by path so that the bindings, which open them by name, find them.

use crate::error::Result;
use std::path::PathBuf;

/// What to do when a library is missing (every [`crate::Error::CudaUnavailable`] of the
/// libraries and the driver says it).
pub(crate) const HINT: &str = "install the NVIDIA driver and the CUDA 12 or 13 libraries \
    (cuFFT, NVRTC), or list their directory in LD_LIBRARY_PATH (docs/gpu.md)";

/// Finds and opens the libraries; returns their paths.
pub(crate) fn load() -> Result<Vec<PathBuf>> {
    Ok(Vec::new())
}

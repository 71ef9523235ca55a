//! The FSAI preconditioner on the device: the host builds and caches `G`'s rows (solver/
//! fsai.rs, the spectral backend's own factor), the device keeps a copy of its weight
//! planes and applies `z = Gᵀ G r` with two stencil kernels (kernels.cu).
//!
//! Why the rows stay on the host: a rupture changes a few rows (the pattern box around
//! each changed site), each a small dense solve, so per set solve only those rows cross
//! (`(4 + 8 stride)` bytes each), not the planes.

use super::device::{cuda_error, zeros};
use super::kernels::{int, over, Kernels};
use crate::error::Result;
use crate::solver::fsai::Fsai;
use cudarc::driver::{CudaSlice, CudaStream};
use std::sync::Arc;

/// The device's copy of a [`Fsai`] factor and the scratch of its product.
pub(super) struct DeviceFsai {
    stride: usize,
    /// `stride` planes of one weight per cell.
    planes: CudaSlice<f64>,
    /// Per slot, cells back to the neighbour.
    offsets: CudaSlice<i32>,
    /// `G r` on the set.
    pub(super) y: CudaSlice<f64>,
    /// Whether the planes equal the host's after its last update. False until the first
    /// copy, and after a failed one: then every row is copied again.
    synced: bool,
}

/// The bytes of a [`DeviceFsai`] of `stride` slots on a grid of `n` cells.
pub(super) fn fsai_bytes(n: usize, stride: usize) -> f64 {
    8.0 * ((stride + 1) * n) as f64 + 4.0 * stride as f64
}

/// The rows the last update refreshed, as their cells and their `stride` weights each
/// (zero weights for a row off the set).
pub(super) fn rows_to_copy(fsai: &Fsai) -> (Vec<i32>, Vec<f64>) {
    let layout = fsai.layout();
    let (stride, planes) = (layout.stride, layout.planes);
    let n = planes.len() / stride;
    let cells = layout.refreshed;
    let weights = cells
        .iter()
        .flat_map(|&i| (0..stride).map(move |k| planes[k * n + i]))
        .collect();
    // Cells below N, which fits an `int` (`CudaCore::new`).
    (cells.iter().map(|&i| i as i32).collect(), weights)
}

impl DeviceFsai {
    /// Zero planes for `fsai`'s pattern on a grid of `n` cells.
    pub(super) fn new(stream: &Arc<CudaStream>, fsai: &Fsai, n: usize) -> Result<Self> {
        // Offsets below N, which fits an `int` (`CudaCore::new`).
        let layout = fsai.layout();
        let offsets: Vec<i32> = layout.offsets.iter().map(|&o| o as i32).collect();
        Ok(DeviceFsai {
            stride: layout.stride,
            planes: zeros(stream, layout.stride * n)?,
            offsets: stream
                .clone_htod(&offsets)
                .map_err(|e| cuda_error("cuMemcpyHtoD (FSAI offsets)", e))?,
            y: zeros(stream, n)?,
            synced: false,
        })
    }

    /// Brings the planes up to date with `fsai` after its update: the refreshed rows
    /// through a scatter kernel, or the whole planes when the copy is not known to be
    /// current.
    pub(super) fn sync(
        &mut self,
        stream: &Arc<CudaStream>,
        kernels: &Kernels,
        fsai: &Fsai,
    ) -> Result<()> {
        if !self.synced {
            // Every row: the planes as they are (no lists, no scratch on the device).
            stream
                .memcpy_htod(fsai.layout().planes, &mut self.planes)
                .map_err(|e| cuda_error("cuMemcpyHtoD (FSAI planes)", e))?;
            self.synced = true;
            return Ok(());
        }
        self.synced = false;
        let (cells, weights) = rows_to_copy(fsai);
        let Some(cfg) = over("FSAI weights to copy", weights.len())? else {
            self.synced = true;
            return Ok(());
        };
        let copy = |e| cuda_error("cuMemcpyHtoD (FSAI rows)", e);
        let cells_d = stream.clone_htod(&cells).map_err(copy)?;
        let weights_d = stream.clone_htod(&weights).map_err(copy)?;
        let (count, stride, n) = (
            int("FSAI rows to copy", cells.len())?,
            int("FSAI pattern slots", self.stride)?,
            int("grid cells", self.planes.len() / self.stride)?,
        );
        // SAFETY: `cells` holds `count` cells of the grid, `weights` `count * stride`
        // values, the planes `stride * n`.
        unsafe {
            kernels.fsai_scatter(
                stream,
                cfg,
                &cells_d,
                &weights_d,
                count,
                &mut self.planes,
                stride,
                n,
            )
        }?;
        self.synced = true;
        Ok(())
    }

    /// `z = Gᵀ G r` on the `m` sites of `set` (`pos` the set position of every cell).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn apply(
        &mut self,
        stream: &Arc<CudaStream>,
        kernels: &Kernels,
        set: &CudaSlice<i32>,
        pos: &CudaSlice<i32>,
        r: &CudaSlice<f64>,
        z: &mut CudaSlice<f64>,
        m: usize,
    ) -> Result<()> {
        let Some(cfg) = over("sites in the set", m)? else {
            return Ok(());
        };
        let (stride, m32, n) = (
            int("FSAI pattern slots", self.stride)?,
            int("sites in the set", m)?,
            int("grid cells", self.planes.len() / self.stride)?,
        );
        // SAFETY: set, r, y and z hold at least m values, pos and every plane n, offsets
        // `stride`.
        unsafe {
            kernels.fsai_g(
                stream,
                cfg,
                &self.planes,
                &self.offsets,
                stride,
                set,
                pos,
                r,
                &mut self.y,
                m32,
                n,
            )
        }?;
        // SAFETY: as above.
        unsafe {
            kernels.fsai_gt(
                stream,
                cfg,
                &self.planes,
                &self.offsets,
                stride,
                set,
                pos,
                &self.y,
                z,
                m32,
                n,
            )
        }
    }
}

//! The FSAI preconditioner on the device: the host builds and caches `G`'s rows (solver/
//! fsai.rs, the spectral backend's own factor), the device keeps a copy of its weight
//! planes and applies `z = Gᵀ G r` with two stencil kernels (kernels.cu).
//!
//! Why the rows stay on the host: a rupture changes a few rows (the pattern box around
//! each changed site), each a small dense solve, so per set solve only those rows cross
//! (`(4 + 8 stride)` bytes each), not the planes.

use super::kernels::Launch;
use super::seam::{int, Device};
use crate::error::Result;
use crate::solver::fsai::Fsai;

/// The device's copy of a [`Fsai`] factor and the scratch of its product.
pub(super) struct DeviceFsai<D: Device> {
    stride: usize,
    /// `stride` planes of one weight per cell.
    planes: D::Buffer<f64>,
    /// Per slot, cells back to the neighbour.
    offsets: D::Buffer<i32>,
    /// `G r` on the set.
    pub(super) y: D::Buffer<f64>,
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

impl<D: Device> DeviceFsai<D> {
    /// Zero planes for `fsai`'s pattern on a grid of `n` cells.
    pub(super) fn new(device: &D, fsai: &Fsai, n: usize) -> Result<Self> {
        // Offsets below N, which fits an `int` (`CudaCore::new`).
        let layout = fsai.layout();
        let offsets: Vec<i32> = layout.offsets.iter().map(|&o| o as i32).collect();
        Ok(DeviceFsai {
            stride: layout.stride,
            planes: device.zeros(layout.stride * n)?,
            offsets: device.upload("cuMemcpyHtoD (FSAI offsets)", &offsets)?,
            y: device.zeros(n)?,
            synced: false,
        })
    }

    /// Brings the planes up to date with `fsai` after its update: the refreshed rows
    /// through a scatter kernel, or the whole planes when the copy is not known to be
    /// current.
    pub(super) fn sync(&mut self, device: &D, fsai: &Fsai) -> Result<()> {
        if !self.synced {
            // Every row: the planes as they are (no lists, no scratch on the device).
            device.htod(
                "cuMemcpyHtoD (FSAI planes)",
                fsai.layout().planes,
                &mut self.planes,
            )?;
            self.synced = true;
            return Ok(());
        }
        self.synced = false;
        let (cells, weights) = rows_to_copy(fsai);
        let Some(cfg) = device.over("FSAI weights to copy", weights.len())? else {
            self.synced = true;
            return Ok(());
        };
        let copy = "cuMemcpyHtoD (FSAI rows)";
        let cells_d = device.upload(copy, &cells)?;
        let weights_d = device.upload(copy, &weights)?;
        let (count, stride, n) = (
            int("FSAI rows to copy", cells.len())?,
            int("FSAI pattern slots", self.stride)?,
            int("grid cells", D::len(&self.planes) / self.stride)?,
        );
        // SAFETY: `cells` holds `count` cells of the grid, `weights` `count * stride`
        // values, the planes `stride * n`.
        unsafe {
            device.fsai_scatter(
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
        device: &D,
        set: &D::Buffer<i32>,
        pos: &D::Buffer<i32>,
        r: &D::Buffer<f64>,
        z: &mut D::Buffer<f64>,
        m: usize,
    ) -> Result<()> {
        let Some(cfg) = device.over("sites in the set", m)? else {
            return Ok(());
        };
        let (stride, m32, n) = (
            int("FSAI pattern slots", self.stride)?,
            int("sites in the set", m)?,
            int("grid cells", D::len(&self.planes) / self.stride)?,
        );
        // SAFETY: set, r, y and z hold at least m values, pos and every plane n, offsets
        // `stride`.
        unsafe {
            device.fsai_g(
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
            device.fsai_gt(
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

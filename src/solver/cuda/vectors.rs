//! The set vectors of a device solve (the CG's, the problem's, the coarse correction's)
//! and the reductions' buffers, shared by the phases and the coarse space's upkeep.

use super::seam::Device;
use crate::error::Result;

/// Blocks of a reduction's first pass, at most: fixed by the vector's length alone, so the
/// order of the additions (hence the bits) is too.
pub(super) const REDUCTION_BLOCKS: usize = 1024;

/// The set's vectors on the device, each of capacity `N` (the set's first `m` values are
/// used), and the reductions' buffers.
pub(super) struct SetVectors<D: Device> {
    pub(super) set: D::Buffer<i32>,
    /// The set position of every cell, or -1.
    pub(super) pos: D::Buffer<i32>,
    pub(super) d: D::Buffer<f64>,
    pub(super) b: D::Buffer<f64>,
    pub(super) f: D::Buffer<f64>,
    pub(super) r: D::Buffer<f64>,
    pub(super) z: D::Buffer<f64>,
    pub(super) p: D::Buffer<f64>,
    pub(super) q: D::Buffer<f64>,
    pub(super) w: D::Buffer<f64>,
    pub(super) best: D::Buffer<f64>,
    /// `A z` of the coarse correction.
    pub(super) t: D::Buffer<f64>,
    pub(super) partials: D::Buffer<f64>,
    pub(super) scalars: D::Buffer<f64>,
}

/// The bytes of [`SetVectors`] on a grid of `n` cells.
pub(super) fn vector_bytes(n: usize) -> f64 {
    (2.0 * 4.0 + 10.0 * 8.0) * n as f64 + 8.0 * (3 * REDUCTION_BLOCKS + 3) as f64
}

impl<D: Device> SetVectors<D> {
    pub(super) fn new(device: &D, n: usize) -> Result<Self> {
        let real = |len: usize| device.zeros::<f64>(len);
        let int = |len: usize| device.zeros::<i32>(len);
        Ok(SetVectors {
            set: int(n)?,
            pos: int(n)?,
            d: real(n)?,
            b: real(n)?,
            f: real(n)?,
            r: real(n)?,
            z: real(n)?,
            p: real(n)?,
            q: real(n)?,
            w: real(n)?,
            best: real(n)?,
            t: real(n)?,
            partials: real(3 * REDUCTION_BLOCKS)?,
            scalars: real(3)?,
        })
    }
}

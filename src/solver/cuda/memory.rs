//! The device memory a CUDA solver needs, estimated and checked against what the GPU has
//! free before anything is allocated.

use super::coarse::coarse_bytes;
use super::fsai::fsai_bytes;
use super::operator::transform_bytes;
use super::vectors::vector_bytes;
use crate::error::{Error, Result};
use crate::solver::coarse::Aggregates;
use crate::solver::fsai::pattern_slots;
use crate::solver::spectral::FSAI_RADIUS;

/// cuFFT's work areas, at most (bytes per cell): a batched real transform's work area is
/// at most the size of its complex output, and the four plans hold one each.
const FFT_WORK_PER_CELL: f64 = 4.0 * 16.0;

/// What the context, the module and cuFFT's own tables take beside the buffers (bytes).
const FIXED_BYTES: f64 = 64.0 * 1024.0 * 1024.0;

/// The bytes a CUDA solver of an `nx x ny` grid allocates on its device, at most: the set
/// vectors, the transforms' buffers, two diagonal tables (the operator's and the spectral
/// preconditioner's), the grid product, the FSAI factor's copy, the FFT work areas and a
/// fixed part.
pub(super) fn device_bytes(nx: usize, ny: usize) -> f64 {
    let n = (nx * ny) as f64;
    vector_bytes(nx * ny)
        + transform_bytes(nx, ny)
        + fsai_bytes(nx * ny, pattern_slots(FSAI_RADIUS))
        + coarse_bytes(Aggregates::new(nx, ny).count())
        + 3.0 * 8.0 * n
        + FFT_WORK_PER_CELL * n
        + FIXED_BYTES
}

/// Refuses `needed` bytes on `device` when more than what it has free.
pub(super) fn check_fits(device: &str, needed: f64, free: f64) -> Result<()> {
    if needed > free {
        return Err(Error::DeviceOutOfMemory {
            device: device.to_string(),
            needed_bytes: needed,
            free_bytes: free,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The estimate counted by hand for a 4 x 3 grid (12 cells): per cell 2 index arrays
    /// (4 B) and 10 set vectors (8 B), 2 real grids (8 B), 3 tables/grid outputs (8 B),
    /// FSAI's 5 weight planes and its scratch vector (8 B) and 64 B of FFT work; half
    /// spectra 3·3 (rows) and 4·2 twice (columns) of 16 B; the reductions' 3·1024 + 3
    /// values; FSAI's 5 offsets (4 B); the coarse space of one aggregate: `E`, its factor
    /// and inverse (1 value each), 5 vectors of 1 and 2 more values (8 B); 64 MiB fixed.
    #[test]
    fn the_estimate_counts_every_buffer() {
        let per_cell = 2.0 * 4.0 + 10.0 * 8.0 + 2.0 * 8.0 + 3.0 * 8.0 + 6.0 * 8.0 + 64.0;
        let spectra = 16.0 * (9.0 + 2.0 * 8.0);
        let reductions = 8.0 * (3.0 * 1024.0 + 3.0);
        let coarse = 8.0 * (3.0 + 5.0 + 2.0);
        let expected =
            12.0 * per_cell + spectra + reductions + 5.0 * 4.0 + coarse + 64.0 * 1024.0 * 1024.0;
        assert_eq!(device_bytes(4, 3), expected);
    }

    /// N = 1e7 fits an 80 GB GPU with room to spare (about 2.5 GB by this count, not
    /// measured on a GPU): memory O(N).
    #[test]
    fn ten_million_cells_need_a_few_gigabytes() {
        let bytes = device_bytes(10_000, 1_000);
        assert!(bytes > 1.5e9 && bytes < 3e9, "{bytes}");
        assert!(device_bytes(20_000, 1_000) < 2.0 * bytes);
    }

    #[test]
    fn a_grid_beyond_the_free_memory_is_refused_naming_the_device() {
        assert!(check_fits("GPU 0", 1e9, 2e9).is_ok());
        let e = check_fits("NVIDIA H200 (device 0)", 3e9, 2e9).unwrap_err();
        let text = e.to_string();
        assert!(text.contains("NVIDIA H200 (device 0)"), "{text}");
        assert!(matches!(e, Error::DeviceOutOfMemory { .. }));
    }
}

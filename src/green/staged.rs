//! The part-by-part (staged) application of an operator with `Ĝ`'s eigenvectors, for
//! solvers that share the work of one product between threads.
//!
//! The grid is cut into a [`Partition`] fixed by the grid alone (never by a thread
//! count): parts are blocks of whole rows (for the x-transforms) and, for the
//! y-transforms, blocks of whole columns. A product `y = T x` runs in three stages; the
//! stages of one part touch only that part's buffers, except where stated, and every
//! stage must finish on every part before the next one starts on any:
//!
//! 0. [`Staging::forward_rows`]: the caller writes `x` on part `k`'s cells, then the
//!    x-DCT-II of its rows;
//! 1. [`Staging::filter_columns`]: column block `k` is gathered from every part's rows,
//!    through the y-DCT-II, the diagonal of `T` and the y-DCT-III;
//! 2. [`Staging::inverse_rows`]: part `k`'s rows are gathered from every column block,
//!    through the x-DCT-III, and handed to the caller.
//!
//! Each value is computed by the same arithmetic whichever thread runs its part, so the
//! result does not depend on how the parts are spread over threads.

use super::dct::Diag;
use super::plan::{InfluencePlan, SpectralTable};
use std::ops::Range;
use std::sync::{Mutex, RwLock};

/// Most parts a grid is cut into.
const MAX_PARTS: usize = 16;
/// Fewest cells per part: below this a part's fixed costs (a claim, locks, short loops)
/// outweigh what a thread gains.
const MIN_PART_CELLS: usize = 1024;

/// The grid cut into parts: row blocks (cells `rows[k]·Nx .. rows[k+1]·Nx`) and column
/// blocks (`cols[k] .. cols[k+1]`), as many of each.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Partition {
    nx: usize,
    ny: usize,
    rows: Vec<usize>,
    cols: Vec<usize>,
}

impl Partition {
    /// The partition of `plan`'s grid: a power of two of parts (so that 1, 2, 4, 8 threads
    /// share them evenly), at most [`MAX_PARTS`], at least [`MIN_PART_CELLS`] cells each;
    /// on the paired-FFT path every part has an even number of rows and columns (the
    /// transforms pair lines).
    pub(crate) fn of(plan: &InfluencePlan) -> Self {
        let grid = plan.grid();
        let (nx, ny) = (grid.nx(), grid.ny());
        let pairs = plan.dct().pairs_lines();
        let unit = if pairs { 2 } else { 1 };
        let (row_units, col_units) = ((ny / unit).max(1), (nx / unit).max(1));
        let limit = MAX_PARTS
            .min((nx * ny / MIN_PART_CELLS).max(1))
            .min(row_units)
            .min(col_units);
        let mut parts = 1;
        while parts * 2 <= limit {
            parts *= 2;
        }
        Self::with_parts(nx, ny, parts, unit)
    }

    /// One part: the whole grid.
    pub(crate) fn single(nx: usize, ny: usize) -> Self {
        Self::with_parts(nx, ny, 1, 1)
    }

    fn with_parts(nx: usize, ny: usize, parts: usize, unit: usize) -> Self {
        // Units (lines or pairs of lines) shared as evenly as integers allow; the last
        // block takes the odd line of an odd length.
        let cut = |len: usize| -> Vec<usize> {
            let units = len / unit;
            let mut v: Vec<usize> = (0..=parts).map(|k| k * units / parts * unit).collect();
            v[parts] = len;
            v
        };
        Self {
            nx,
            ny,
            rows: cut(ny),
            cols: cut(nx),
        }
    }

    /// Number of parts.
    pub(crate) fn parts(&self) -> usize {
        self.rows.len() - 1
    }

    /// The cells of part `k`.
    pub(crate) fn cells(&self, k: usize) -> Range<usize> {
        self.rows[k] * self.nx..self.rows[k + 1] * self.nx
    }

    /// The columns of column block `k`.
    fn columns(&self, k: usize) -> Range<usize> {
        self.cols[k]..self.cols[k + 1]
    }

    /// Cells of the grid.
    pub(crate) fn len(&self) -> usize {
        self.nx * self.ny
    }
}

/// The buffers of staged products on one partition: each part's rows and each column
/// block, behind locks (a stage writes its own part's buffer and reads the others').
#[derive(Debug)]
pub(crate) struct Staging {
    plan: InfluencePlan,
    partition: Partition,
    /// Part `k`'s rows, row-major (`rows x Nx`).
    rows: Vec<RwLock<Vec<f64>>>,
    /// Column block `k`, row-major (`Ny x width`).
    blocks: Vec<RwLock<Vec<f64>>>,
    /// Scratch of the transforms, per part, sized once for the part's rows and its
    /// column block.
    work: Vec<Mutex<Vec<f64>>>,
}

impl Staging {
    pub(crate) fn new(plan: &InfluencePlan, partition: Partition) -> Self {
        let parts = partition.parts();
        let buffers = |len: &dyn Fn(usize) -> usize| -> Vec<RwLock<Vec<f64>>> {
            (0..parts).map(|k| RwLock::new(vec![0.0; len(k)])).collect()
        };
        let rows = buffers(&|k| partition.cells(k).len());
        let blocks = buffers(&|k| partition.columns(k).len() * partition.ny);
        Self {
            plan: plan.clone(),
            work: (0..parts)
                .map(|k| {
                    let dct = plan.dct();
                    let len = dct
                        .rows_scratch_len(partition.cells(k).len() / partition.nx)
                        .max(dct.columns_scratch_len(partition.columns(k).len()));
                    Mutex::new(vec![0.0; len])
                })
                .collect(),
            rows,
            blocks,
            partition,
        }
    }

    /// The partition.
    pub(crate) fn partition(&self) -> &Partition {
        &self.partition
    }

    /// Stage 0 on part `k`: `load` writes the input on the part's cells (given as
    /// zeros), then the rows go through the x-DCT-II.
    pub(crate) fn forward_rows(&self, k: usize, load: impl FnOnce(&mut [f64])) {
        let mut rows = write(&self.rows[k]);
        rows.fill(0.0);
        load(&mut rows);
        self.plan
            .dct()
            .rows(&mut rows, true, &mut lock(&self.work[k]));
    }

    /// Stage 1 on column block `k`: gathered from every part's rows, through the
    /// y-transforms and `table`.
    pub(crate) fn filter_columns(&self, k: usize, table: &SpectralTable) {
        let (nx, cols) = (self.partition.nx, self.partition.columns(k));
        let width = cols.len();
        let mut block = write(&self.blocks[k]);
        if width == 0 {
            return;
        }
        let mut lines = block.chunks_exact_mut(width);
        for part in &self.rows {
            for row in read(part).chunks_exact(nx) {
                if let Some(line) = lines.next() {
                    line.copy_from_slice(&row[cols.clone()]);
                }
            }
        }
        let diag = Diag {
            values: &table.values()[cols.start..],
            stride: nx,
        };
        self.plan
            .dct()
            .columns(&mut block, width, diag, &mut lock(&self.work[k]));
    }

    /// Stage 2 on part `k`: its rows gathered from every column block, through the
    /// x-DCT-III; `unload` reads them (`T x` on the part's cells).
    pub(crate) fn inverse_rows<R>(&self, k: usize, unload: impl FnOnce(&[f64]) -> R) -> R {
        let nx = self.partition.nx;
        let mut rows = write(&self.rows[k]);
        let first = self.partition.rows[k];
        for (b, block) in self.blocks.iter().enumerate() {
            let cols = self.partition.columns(b);
            let width = cols.len();
            if width == 0 {
                continue;
            }
            let block = read(block);
            for (y, row) in rows.chunks_exact_mut(nx).enumerate() {
                let line = &block[(first + y) * width..(first + y + 1) * width];
                row[cols.clone()].copy_from_slice(line);
            }
        }
        self.plan
            .dct()
            .rows(&mut rows, false, &mut lock(&self.work[k]));
        unload(&rows)
    }

    /// The last product on every cell (after stage 2 on every part).
    pub(crate) fn result(&self, out: &mut [f64]) {
        for (k, rows) in self.rows.iter().enumerate() {
            out[self.partition.cells(k)].copy_from_slice(&read(rows));
        }
    }
}

/// The poison-tolerant guards of the parts' buffers (their one copy is in `lock.rs`).
pub(crate) use crate::lock::{lock, read, write};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Block, Grid};

    /// Staged products, stage by stage over the parts, equal the whole-grid filter on every
    /// transform path (paired FFT rows, matrix-product, direct and FFT columns, rustdct).
    #[test]
    fn staged_product_equals_whole_grid_product() {
        for (nx, ny) in [
            (200, 50),
            (64, 130),
            (60, 40),
            (21, 30),
            (15, 67),
            (1, 20),
            (20, 1),
            (128, 8),
        ] {
            let block = Block::new(nx as f64 * 1e-3, ny as f64 * 1e-3, 0.075).unwrap();
            let plan = InfluencePlan::builder(Grid::new(block, nx, ny).unwrap())
                .build()
                .unwrap();
            let n = nx * ny;
            let x: Vec<f64> = (0..n).map(|i| ((i * 7919) % 101) as f64 - 50.0).collect();
            let mut whole = x.clone();
            plan.apply_with_scratch(&mut whole, &mut vec![0.0; plan.scratch_len()])
                .unwrap();
            for partition in [Partition::of(&plan), Partition::single(nx, ny)] {
                let staging = Staging::new(&plan, partition.clone());
                let parts = partition.parts();
                for k in 0..parts {
                    let cells = partition.cells(k);
                    staging.forward_rows(k, |rows| rows.copy_from_slice(&x[cells]));
                }
                for k in 0..parts {
                    staging.filter_columns(k, plan.operator_table());
                }
                let mut staged = vec![0.0; n];
                for k in 0..parts {
                    let cells = partition.cells(k);
                    staging.inverse_rows(k, |rows| staged[cells].copy_from_slice(rows));
                }
                let mut again = vec![0.0; n];
                staging.result(&mut again);
                assert_eq!(staged, again);
                let scale = whole.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for (a, b) in staged.iter().zip(&whole) {
                    assert!(
                        (a - b).abs() <= 1e-13 * scale,
                        "{nx}x{ny} {parts} parts: {a} vs {b}"
                    );
                }
            }
        }
    }

    /// Parts are fixed by the grid: a power of two, rows and columns cover the grid, even
    /// lines on the paired path.
    #[test]
    fn partition_covers_the_grid() {
        for (nx, ny) in [
            (200, 50),
            (1000, 100),
            (140, 7),
            (3, 3),
            (1, 2000),
            (2000, 1),
        ] {
            let block = Block::new(nx as f64 * 1e-3, ny as f64 * 1e-3, 0.075).unwrap();
            let plan = InfluencePlan::builder(Grid::new(block, nx, ny).unwrap())
                .plan_tolerance(1e-3)
                .build()
                .unwrap();
            let p = Partition::of(&plan);
            assert!(p.parts().is_power_of_two() && p.parts() <= MAX_PARTS);
            assert_eq!(p.cells(0).start, 0);
            assert_eq!(p.cells(p.parts() - 1).end, nx * ny);
            for k in 1..p.parts() {
                assert_eq!(p.cells(k - 1).end, p.cells(k).start);
                assert!(!p.cells(k).is_empty() && !p.columns(k).is_empty());
                if plan.dct().pairs_lines() {
                    assert_eq!(p.cells(k).start % (2 * nx), 0);
                    assert_eq!(p.columns(k).start % 2, 0);
                }
            }
        }
    }
}

//! What a grid costs (below the geometry and the operator: every layer above checks it), estimated before anything is allocated, and the guard that refuses
//! grids above a limit of cells (docs/performance.md, "Grid-size guard").

use crate::error::{Error, Result};

/// Largest grid the [`crate::solver::Backend::Auto`] choice solves densely (cells). Defined here,
/// below the solver, because the cost estimate needs it too.
pub const AUTO_DENSE_LIMIT: usize = 2500;

/// Default limit on the cells of a plan or scene ([`InfluencePlanBuilder::max_cells`],
/// [`crate::SceneBuilder::max_cells`]): `1e6`, ten times the largest run documented
/// (`N = 1e5`, 1000 x 100). At the limit a scene needs about 240 MB, 1.5 s to plan and
/// 28 s per cold equilibrium ([`GridCost`]); 10000 x 10000 cells would need about 24 GB,
/// minutes to plan and hours per equilibrium.
///
/// [`InfluencePlanBuilder::max_cells`]: crate::green::InfluencePlanBuilder::max_cells
pub const DEFAULT_MAX_CELLS: usize = 1_000_000;

/// Bytes per cell of a spectral scene and its driver (plan, interface, load table,
/// solver buffers, equilibria), measured (docs/performance.md).
const BYTES_PER_CELL: f64 = 240.0;
/// Bytes per entry of the dense backend's `N x N` matrices (the operator and its factor).
const DENSE_BYTES_PER_ENTRY: f64 = 16.0;
/// Planning time per cell (s, one thread, release build), measured.
const PLAN_SECONDS_PER_CELL: f64 = 1.5e-6;
/// One cold equilibrium (normal and tangential) takes `SOLVE_SECONDS · N^SOLVE_EXPONENT`
/// (s, one thread, release build), fitted to N = 1e4, 1e5 and 4e5.
const SOLVE_SECONDS: f64 = 1.1e-7;
/// See [`SOLVE_SECONDS`].
const SOLVE_EXPONENT: f64 = 1.4;

/// The estimated cost of a scene on a grid of `Nx x Ny` cells: its memory, the time to
/// plan its operator and the time of one cold equilibrium, from the measurements of
/// docs/performance.md ("Grid-size guard": the formula and the command that checks it,
/// `cargo run --release --example grid_cost Nx Ny`). Estimates within a factor of about
/// two on the machine measured; one thread, release build (a debug build of the crate is
/// about 190 times slower).
///
/// ```
/// use precursors::GridCost;
/// let cost = GridCost::of(10_000, 10_000);
/// assert!(cost.memory_bytes > 1e10 && cost.solve_seconds > 3600.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct GridCost {
    /// `Nx·Ny` (exact).
    pub cells: u128,
    /// Peak memory of a scene and its driver (bytes): 240 B per cell, plus the two
    /// `N x N` matrices of the dense backend when [`crate::solver::Backend::Auto`] picks it.
    pub memory_bytes: f64,
    /// Time to plan the operator (s): 1.5 µs per cell.
    pub plan_seconds: f64,
    /// Time of one cold normal and tangential equilibrium (s): `1.1e-7 · N^1.4`.
    pub solve_seconds: f64,
}

impl GridCost {
    /// The estimate for `nx x ny` cells.
    pub fn of(nx: usize, ny: usize) -> Self {
        let cells = nx as u128 * ny as u128;
        let n = cells as f64;
        let dense = if cells <= AUTO_DENSE_LIMIT as u128 {
            dense_bytes(n)
        } else {
            0.0
        };
        Self {
            cells,
            memory_bytes: BYTES_PER_CELL * n + dense,
            plan_seconds: PLAN_SECONDS_PER_CELL * n,
            solve_seconds: SOLVE_SECONDS * n.powf(SOLVE_EXPONENT),
        }
    }
}

/// Bytes of the dense backend's two `N x N` matrices for `cells` cells.
pub(crate) fn dense_bytes(cells: f64) -> f64 {
    DENSE_BYTES_PER_ENTRY * cells * cells
}

/// Refuses `nx x ny` cells above `limit` with [`Error::GridTooLarge`].
pub(crate) fn check_cells(nx: usize, ny: usize, limit: usize) -> Result<()> {
    let cost = GridCost::of(nx, ny);
    if cost.cells > limit as u128 {
        return Err(Error::GridTooLarge {
            nx,
            ny,
            cells: cost.cells,
            limit,
            memory_bytes: cost.memory_bytes,
            plan_seconds: cost.plan_seconds,
            solve_seconds: cost.solve_seconds,
        });
    }
    Ok(())
}

/// The memory the machine can give a new allocation without swapping (bytes):
/// `MemAvailable` of `/proc/meminfo` on Linux, `None` elsewhere or when it cannot be read
/// (then no check is made).
pub(crate) fn available_memory() -> Option<f64> {
    if !cfg!(target_os = "linux") {
        return None;
    }
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let mut fields = line.split_whitespace().skip(1);
    let value: f64 = fields.next()?.parse().ok()?;
    match fields.next() {
        Some("kB") => Some(value * 1024.0),
        _ => None,
    }
}

/// Refuses `bytes` of `what` above the memory available ([`available_memory`]) with
/// [`Error::OutOfMemory`], before anything is allocated: an allocation that fails aborts
/// the process, it cannot be reported.
pub(crate) fn check_memory(
    what: impl FnOnce() -> String,
    bytes: f64,
    hint: &'static str,
) -> Result<()> {
    match available_memory() {
        Some(available) if bytes.is_nan() || bytes > available => Err(Error::OutOfMemory {
            what: what(),
            needed_bytes: bytes,
            available_bytes: available,
            hint,
        }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_limit_admits_the_documented_runs_and_refuses_1e8_cells() {
        for (nx, ny) in [(140, 7), (200, 50), (1000, 100), (1000, 1000)] {
            assert!(check_cells(nx, ny, DEFAULT_MAX_CELLS).is_ok());
        }
        let e = check_cells(10_000, 10_000, DEFAULT_MAX_CELLS).unwrap_err();
        assert!(matches!(
            e,
            Error::GridTooLarge {
                cells: 100_000_000,
                ..
            }
        ));
        let text = e.to_string();
        assert!(
            text.contains("24.000 GB") && text.contains("2.500 min"),
            "{text}"
        );
        // Nx·Ny overflowing usize is still reported exactly.
        let e = check_cells(usize::MAX, 2, DEFAULT_MAX_CELLS).unwrap_err();
        assert!(matches!(e, Error::GridTooLarge { cells, .. } if cells == 2 * usize::MAX as u128));
    }
}

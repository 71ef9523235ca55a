//! A set problem of the interface, how hard to solve it, and its solution: the types every
//! backend (spectral, dense) and the active set share, below all of them.

use super::parallel::Parallelism;
use super::pcg::{PcgOutcome, PcgSettings};

/// One equality-constrained solve on a set: the tractions, how it went, and `C_s f` on
/// every cell (from the solve's last product).
pub(crate) struct SetSolve {
    pub f: Vec<f64>,
    pub outcome: PcgOutcome,
    pub grid_product: Vec<f64>,
}

/// A set problem: `(C_SS + diag(d)) f + U 1 = b`, `Σ f = total` on the sites `set`.
#[derive(Clone, Copy)]
pub(crate) struct SetProblem<'a> {
    pub set: &'a [usize],
    pub d: &'a [f64],
    pub b: &'a [f64],
    pub total: f64,
}

/// How to solve: tolerance, iterations, threads.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Effort {
    pub tolerance: f64,
    pub max_iterations: usize,
    pub parallelism: Parallelism,
}

impl Effort {
    pub(crate) fn settings(&self, total: f64) -> PcgSettings {
        PcgSettings {
            total,
            tolerance: self.tolerance,
            max_iterations: self.max_iterations,
            parallelism: self.parallelism,
        }
    }
}

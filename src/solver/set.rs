//! A set problem of the interface and its solution: the types every backend (spectral,
//! dense) and the active set share, below all of them (how hard to solve it is
//! [`Effort`](super::pcg::Effort), the CG's).

use super::pcg::PcgOutcome;

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

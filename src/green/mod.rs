//! The box's Neumann Green function: point series, analytic load terms and the grid
//! operator.
//!
//! * [`GreenFunction`] (`point.rs`): `G` and `∂G/∂z` at points (raw triple series and the
//!   paper's rapidly converging representation), each with a truncation-error estimate.
//! * the load terms (`loads.rs`): [`top_influence`], [`top_stress_influence`] and
//!   [`RodLoad`] (rod and uniform side), and their transfer to height `z`.
//! * [`InfluencePlan`] (`plan.rs`): the Galerkin influence operator of a grid
//!   (docs/model.md section 2), planned once per geometry ([`Planner`] shares plans) and
//!   applied matrix-free; its eigenvalues come from `spectrum.rs`, its transforms from
//!   the DCT engine `dct.rs`, and `staged.rs` applies it part by part for parallel
//!   solvers.
//! * [`PlaneTransfer`] (`transfer.rs`): bottom tractions carried to a plane at height `z`.

mod dct;
mod loads;
mod plan;
mod planner;
mod point;
mod spectrum;
mod staged;
mod transfer;

pub use crate::cost::DEFAULT_MAX_CELLS;
pub(crate) use crate::cost::{check_cells, check_memory, dense_bytes};
pub use loads::{top_influence, top_stress_influence, RodLoad};
pub(crate) use plan::SpectralTable;
pub use plan::{InfluencePlan, InfluencePlanBuilder, DENSE_LIMIT};
pub use planner::Planner;
pub use point::{Estimate, GreenFunction, SeriesOptions, SummationAxis};
pub(crate) use staged::{Partition, Staging};
pub(crate) use transfer::lowest_plane;
pub use transfer::PlaneTransfer;

/// What the green module built on this thread, counted for the tests of "What a scene
/// leaves out" (docs/architecture.md): they fail when a scene builds a plan, a load
/// series or a plane transfer it does not use. Test builds only.
#[cfg(test)]
pub(crate) mod built {
    use std::cell::Cell;

    thread_local! {
        static COUNTS: Cell<Built> = const { Cell::new(Built { plans: 0, load_series: 0, transfers: 0 }) };
    }

    /// Counts since the last [`take`].
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub(crate) struct Built {
        /// Influence operators planned (eigenvalues and DCT plans).
        pub plans: usize,
        /// Lateral-load series tabulated over the cells (displacements or stresses).
        pub load_series: usize,
        /// Plane transfers of bottom tractions to a height.
        pub transfers: usize,
    }

    pub(crate) fn count(f: impl FnOnce(&mut Built)) {
        COUNTS.with(|c| {
            let mut b = c.get();
            f(&mut b);
            c.set(b);
        });
    }

    /// The counts so far, reset to zero.
    pub(crate) fn take() -> Built {
        COUNTS.with(|c| {
            c.replace(Built {
                plans: 0,
                load_series: 0,
                transfers: 0,
            })
        })
    }
}

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
pub use transfer::PlaneTransfer;

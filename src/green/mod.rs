//! The box's Neumann Green function: point series, analytic load terms and the grid
//! operator.
//!
//! * [`GreenFunction`]: `G` and `∂G/∂z` at points (raw triple series and the paper's
//!   rapidly converging representation), each with a truncation-error estimate.
//! * [`loads`]: the top, rod and uniform-side load terms and their transfer to height `z`.
//! * [`InfluencePlan`]: the Galerkin influence operator of a grid (docs/model.md section 2),
//!   planned once per geometry and applied matrix-free through the DCT, plus the
//!   [`PlaneTransfer`] of bottom tractions to a plane at height `z`.

pub mod loads;
mod operator;
mod point;

pub use loads::RodLoad;
pub(crate) use operator::Dct2d;
pub use operator::{InfluencePlan, InfluencePlanBuilder, PlaneTransfer, DENSE_LIMIT};
pub use point::{Estimate, GreenFunction, SeriesOptions, SummationAxis};

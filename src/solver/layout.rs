//! What a device reads of the host's preconditioners (feature `cuda`): the one interface
//! between the host's FSAI factor and coarse aggregates and their device copies. The
//! host keeps building both (`fsai.rs`, `coarse.rs`, the spectral backend's own code); the
//! CUDA backend copies what these views show and nothing else, so their layouts are
//! promised here:
//!
//! - [`FsaiLayout`]: `G` as `stride` weight planes of one value per cell (slot `k` of
//!   cell `i` at `planes[k N + i]`, the weight of cell `i` on cell `i - offsets[k]`, zero
//!   off the set and for missing neighbours; the last slot is the cell itself, offset
//!   0), and the cells whose weights the last update wrote (every other cell kept its
//!   weights, so a copy is brought up to date by these rows alone).
//! - [`AggregateLayout`]: the aggregates as blocks of `block x block` cells, `blocks_x`
//!   along x (aggregate of cell `i`: `(i / Nx / block) blocks_x + (i % Nx) / block`),
//!   and which ones the last `Aggregates::enter` changed (sites or compliances): the
//!   columns of `E` a device recomputes.

/// The FSAI factor's weight planes ([`crate::solver::fsai::Fsai::layout`]; module docs).
#[derive(Debug, Clone, Copy)]
pub(crate) struct FsaiLayout<'a> {
    /// Pattern slots per row (planes).
    pub(crate) stride: usize,
    /// Per slot, how many cells back its neighbour lies.
    pub(crate) offsets: &'a [usize],
    /// `stride` planes of one weight per cell.
    pub(crate) planes: &'a [f64],
    /// The cells whose weights the last update wrote.
    pub(crate) refreshed: &'a [usize],
}

/// The coarse space's aggregates ([`crate::solver::coarse::Aggregates::layout`]; module
/// docs).
#[derive(Debug, Clone, Copy)]
pub(crate) struct AggregateLayout<'a> {
    /// Cells per block side.
    pub(crate) block: usize,
    /// Blocks along x.
    pub(crate) blocks_x: usize,
    /// Per aggregate: whether the last `Aggregates::enter` changed its sites or their
    /// compliances.
    pub(crate) touched: &'a [bool],
}

//! A cache of influence plans: one plan per geometry and plan tolerance, shared.

use super::plan::InfluencePlan;
use crate::error::Result;
use crate::geometry::Grid;
use std::sync::{Arc, Mutex};

/// Plans influence operators once per grid and plan tolerance and hands out shared clones.
///
/// Planning a grid costs `O(N)` work (its eigenvalues and DCT plans: milliseconds for the
/// paper's 140 x 7 calibration grid, a fraction of a second at `N = 1e5`,
/// docs/accuracy.md); every scene, solver and probe of one geometry can share one plan.
/// A `Planner` is cheap to clone (clones share the cache) and may be used from several
/// threads. Plans stay cached while the planner lives.
///
/// ```
/// use precursors::{green::Planner, Scene};
/// let planner = Planner::new();
/// let a = Scene::builder().seed(1).build_with_planner(&planner)?;
/// let b = Scene::builder().seed(2).build_with_planner(&planner)?;   // same geometry: no new plan
/// assert!(a.plan().same_plan(b.plan()) && planner.len() == 1);
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Default)]
pub struct Planner {
    plans: Arc<Mutex<Vec<InfluencePlan>>>,
}

impl Planner {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// The plan of `grid` with the plan tolerance `plan_tolerance` (dimensionless: the
    /// largest relative error accepted on an eigenvalue,
    /// [`crate::green::InfluencePlanBuilder::plan_tolerance`]), planned on the first
    /// request and shared afterwards.
    ///
    /// Grids above [`DEFAULT_MAX_CELLS`](super::DEFAULT_MAX_CELLS) cells are refused;
    /// [`Planner::plan_with_max_cells`] raises the limit.
    ///
    /// # Errors
    /// Those of [`crate::green::InfluencePlanBuilder::build`]: [`crate::Error::GridTooLarge`],
    /// [`crate::Error::InvalidTolerance`], [`crate::Error::SeriesNotConverged`].
    pub fn plan(&self, grid: Grid, plan_tolerance: f64) -> Result<InfluencePlan> {
        self.plan_with_max_cells(grid, plan_tolerance, super::DEFAULT_MAX_CELLS)
    }

    /// [`Planner::plan`] with a limit of `max_cells` cells instead of the default
    /// ([`crate::green::InfluencePlanBuilder::max_cells`]); a cached plan is returned
    /// whatever the limit.
    ///
    /// # Errors
    /// As [`Planner::plan`].
    pub fn plan_with_max_cells(
        &self,
        grid: Grid,
        plan_tolerance: f64,
        max_cells: usize,
    ) -> Result<InfluencePlan> {
        let same = |p: &InfluencePlan| {
            *p.grid() == grid && p.plan_tolerance().to_bits() == plan_tolerance.to_bits()
        };
        if let Some(plan) = self.lock().iter().find(|p| same(p)) {
            return Ok(plan.clone());
        }
        // Planned outside the lock (other geometries stay available meanwhile); a plan
        // of the same geometry planned meanwhile by another thread wins.
        let plan = InfluencePlan::builder(grid)
            .plan_tolerance(plan_tolerance)
            .max_cells(max_cells)
            .build()?;
        let mut plans = self.lock();
        if let Some(existing) = plans.iter().find(|p| same(p)) {
            return Ok(existing.clone());
        }
        plans.push(plan.clone());
        Ok(plan)
    }

    /// Plans in the cache.
    pub fn len(&self) -> usize {
        self.lock().len()
    }

    /// Whether the cache is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<InfluencePlan>> {
        crate::lock::lock(&self.plans)
    }
}

//! Checkpoints: a [`Driver`] frozen between two events, resumable on its scene.
//!
//! A checkpoint holds everything the protocol and the solvers carry from one event to the
//! next, including the solvers' warm starts, the dense backend's LDLᵀ factors and the
//! spectral preconditioner's `d̄`: iterative solves stop at a tolerance, so their results
//! depend on where they start and how they are preconditioned at the rounding level, and
//! a near-tie between two sites would otherwise let a resumed run pick another rupture.
//! With the full state, a resumed run repeats the uninterrupted one bit for bit (same
//! build, same CPU features: the FFT kernels are chosen at run time).

use super::{Driver, Phase};
use crate::error::{Error, Result};
use crate::interface::SiteState;
use crate::scene::{Scene, SceneBuilder};
use crate::solver::{NormalEquilibrium, SolverState, TangentialResponse};
use crate::Event;

/// Version of the checkpoint layout; a checkpoint of another version is refused.
const FORMAT: u32 = 1;

/// A snapshot of a [`Driver`] between two events ([`Driver::checkpoint`]), resumed by
/// [`Scene::resume`]. With the `serde` feature it serialises in any serde format
/// (`Checkpoint::to_json` for JSON); floats must round-trip exactly (they do in JSON
/// through this crate, which enables `serde_json`'s `float_roundtrip`).
///
/// ```
/// use precursors::{Event, Scene};
/// let scene = Scene::builder().block(0.012, 0.002, 0.010).normal_load(50.0).seed(2).build()?;
/// let mut driver = scene.driver()?;
/// let first: Vec<Event> = driver.by_ref().take(30).collect::<Result<_, _>>()?;
/// let checkpoint = driver.checkpoint();
/// let rest: Vec<Event> = driver.collect::<Result<_, _>>()?;
/// // Later, or in another process (after a round trip through JSON with `serde`):
/// let resumed: Vec<Event> = scene.resume(&checkpoint)?.collect::<Result<_, _>>()?;
/// assert_eq!(resumed, rest);
/// # let _ = first;
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Checkpoint {
    format: u32,
    scene: SceneBuilder,
    states: Vec<SiteState>,
    normal: Option<NormalEquilibrium>,
    response: Option<TangentialResponse>,
    initial_columns: Vec<f64>,
    control: f64,
    pending: Vec<Event>,
    phase: Phase,
    avalanche_ruptures: usize,
    events: usize,
    solver: SolverState,
}

impl Checkpoint {
    /// The scene the checkpoint was taken on (build it to resume in a new process).
    pub fn scene(&self) -> &SceneBuilder {
        &self.scene
    }

    /// Events the driver had returned when the checkpoint was taken.
    pub fn event_count(&self) -> usize {
        self.events
    }

    /// The checkpoint as compact JSON (feature `serde`).
    ///
    /// # Errors
    /// [`Error::InvalidCheckpoint`] if serialisation fails (it does not for a checkpoint
    /// taken by [`Driver::checkpoint`]).
    #[cfg(feature = "serde")]
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string(self).map_err(|e| Error::InvalidCheckpoint {
            reason: format!("cannot be written as JSON: {e}"),
        })
    }

    /// Reads a checkpoint written by [`Checkpoint::to_json`] (feature `serde`).
    ///
    /// # Errors
    /// [`Error::InvalidCheckpoint`] when `text` is not a checkpoint.
    #[cfg(feature = "serde")]
    pub fn from_json_str(text: &str) -> Result<Checkpoint> {
        serde_json::from_str(text).map_err(|e| Error::InvalidCheckpoint {
            reason: format!("not a checkpoint: {e}"),
        })
    }
}

impl Driver {
    /// A snapshot of the driver as it stands (between two events); [`Scene::resume`]
    /// continues from it with exactly the events this driver would return.
    pub fn checkpoint(&self) -> Checkpoint {
        Checkpoint {
            format: FORMAT,
            scene: self.scene.clone(),
            states: self.interface.states().to_vec(),
            normal: self.normal.clone(),
            response: self.response.clone(),
            initial_columns: self.initial_columns.clone(),
            control: self.control,
            pending: self.pending.iter().copied().collect(),
            phase: self.phase,
            avalanche_ruptures: self.avalanche_ruptures,
            events: self.events,
            solver: self.solver.state(),
        }
    }
}

impl Scene {
    /// A driver continuing from `checkpoint`, which must have been taken on this scene
    /// (same builder: block, grid, material, springs, heights, loads, solver options; the
    /// thread count may differ, results do not depend on it).
    /// Errors: [`Error::InvalidCheckpoint`] when it was not, or when it is inconsistent.
    ///
    /// # Errors
    /// [`Error::InvalidCheckpoint`] when the checkpoint was not taken on this scene or is
    /// inconsistent; those of [`Scene::driver`].
    pub fn resume(&self, checkpoint: &Checkpoint) -> Result<Driver> {
        let bad = |reason: String| Err(Error::InvalidCheckpoint { reason });
        if checkpoint.format != FORMAT {
            return bad(format!(
                "layout version {} (this build reads version {FORMAT})",
                checkpoint.format
            ));
        }
        if !checkpoint.scene.same_run(&self.to_builder()) {
            return bad("it was taken on another scene (the builders differ)".into());
        }
        let mut driver = self.driver()?;
        let n = self.grid().len();
        if checkpoint.states.len() != n {
            return bad(format!(
                "{} site states for a grid of {n} cells",
                checkpoint.states.len()
            ));
        }
        let lengths_ok = |v: &[f64]| v.len() == n && v.iter().all(|x| x.is_finite());
        if let Some(normal) = &checkpoint.normal {
            if !(lengths_ok(&normal.traction) && lengths_ok(&normal.displacement)) {
                return bad(format!(
                    "the normal equilibrium does not have {n} finite values"
                ));
            }
        }
        if let Some(response) = &checkpoint.response {
            if !(lengths_ok(&response.traction) && lengths_ok(&response.displacement)) {
                return bad(format!(
                    "the tangential response does not have {n} finite values"
                ));
            }
        }
        let columns = checkpoint.initial_columns.len();
        if !(columns == 0 || columns == self.grid().nx()) {
            return bad(format!(
                "{columns} initial column areas for {} columns",
                self.grid().nx()
            ));
        }
        if !checkpoint.control.is_finite() {
            return bad(format!("the load {} is not finite", checkpoint.control));
        }
        if let Phase::Avalanche { forced: Some(i) } = checkpoint.phase {
            if i >= n {
                return bad(format!("the threshold site {i} is beyond the grid's {n}"));
            }
        }
        for (i, state) in checkpoint.states.iter().enumerate() {
            driver.interface.set_state(i, *state);
        }
        driver.solver.restore(checkpoint.solver.clone())?;
        // λ is a function of the two equilibria: recomputed rather than stored (it holds
        // infinities, which JSON cannot).
        if let (Some(normal), Some(response)) = (&checkpoint.normal, &checkpoint.response) {
            driver.breaking = driver.interface.breaking_loads(
                &normal.traction,
                &response.traction,
                driver.friction,
            )?;
        }
        driver.normal = checkpoint.normal.clone();
        driver.response = checkpoint.response.clone();
        driver.initial_columns = checkpoint.initial_columns.clone();
        driver.control = checkpoint.control;
        driver.pending = checkpoint.pending.iter().copied().collect();
        driver.phase = checkpoint.phase;
        driver.avalanche_ruptures = checkpoint.avalanche_ruptures;
        driver.events = checkpoint.events;
        Ok(driver)
    }
}

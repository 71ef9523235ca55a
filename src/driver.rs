//! The quasi-static protocol (paper Suppl. "Quasi-static dynamics", docs/model.md section 5)
//! as an iterator of [`Event`]s.
//!
//! 1. Normal equilibrium at `F_N`, no shear: the first event is a [`Event::Stable`] state
//!    at zero load.
//! 2. The load is raised to the smallest breaking load `min_i λ_i` of the attached sites
//!    ([`Event::LoadRaised`]); that site is over threshold.
//! 3. At fixed load, the over-threshold site (`|φ_x| ≥ μ φ_z`) with the largest elastic
//!    energy `½ k_x u_x² ΔA` breaks ([`Event::Rupture`]); the normal equilibrium is solved
//!    again (sites [`Event::Detach`] and [`Event::Attach`]), then the tangential one; repeat
//!    3 while a site is over threshold, then [`Event::Stable`] and back to 2.
//! 4. When every site is broken the block slides: [`Event::GlobalSlip`], then the iterator
//!    ends.
//!
//! Under displacement control the load is the drive displacement `U_S`; the spring force
//! `F = K_S (U_S - ⟨u_x⟩)` follows from the state and drops at each rupture.
//!
//! ```
//! use precursors::{Drive, Event, ForceLoad, Scene};
//! let scene = Scene::builder()
//!     .block(0.010, 0.002, 0.010)
//!     .cell_size(1e-3, 1e-3)
//!     .normal_load(40.0)
//!     .drive(Drive::Force(ForceLoad::Top))
//!     .seed(3)
//!     .build()?;
//! let mut driver = scene.driver()?;
//! let mut slip = None;
//! for event in &mut driver {
//!     if let Event::GlobalSlip { load } = event? {
//!         slip = Some(load.force);
//!     }
//! }
//! // Amontons' first law: the block slides at μ F_N.
//! let ratio = slip.unwrap() / (0.5 * 40.0);
//! assert!((ratio - 1.0).abs() < 1e-9);
//! # Ok::<(), precursors::Error>(())
//! ```

use crate::contact::{ContactRule, ContactState, Fields};
use crate::error::{Error, Result};
use crate::geometry::Grid;
use crate::interface::{Interface, Material, SiteState};
use crate::probe::StressProbe;
use crate::scene::{Drive, Scene};
use crate::solver::{AnchorResponse, EquilibriumSolver, NormalEquilibrium, TangentialResponse};
use std::collections::VecDeque;
use std::ops::ControlFlow;

mod checkpoint;
mod observables;
#[cfg(feature = "serde")]
pub(crate) use checkpoint::scene_mismatch;
pub use checkpoint::Checkpoint;
pub(crate) use checkpoint::{RowDifference, RowDigest, TableDigest};
pub use observables::{SlipPerNewton, SlipProfile};

/// A site of the interface grid.
///
/// ```
/// use precursors::{Event, Scene};
/// let scene = Scene::builder()
///     .block(0.010, 0.004, 0.010)       // Lx, Ly, Lz (m)
///     .cells(10, 4)                     // 1 mm cells
///     .normal_load(40.0)                // F_N (N)
///     .seed(1)
///     .build()?;
/// let grid = *scene.grid();
/// let mut broken = Vec::new();
/// for event in scene.driver()? {
///     if let Event::Rupture { site, .. } = event? {
///         // The paper's cell order: i = iy·Nx + ix, column ix from the trailing edge.
///         assert_eq!(site.index, site.iy * grid.nx() + site.ix);
///         assert_eq!(grid.index(site.ix, site.iy), Some(site.index));
///         broken.push(site.index);
///     }
/// }
/// // Every spring breaks once, irreversibly, before the block slides.
/// broken.sort_unstable();
/// assert_eq!(broken, (0..grid.len()).collect::<Vec<_>>());
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct Site {
    /// Index `i = iy·Nx + ix` (the paper's order).
    pub index: usize,
    /// Column (along x, from the trailing edge).
    pub ix: usize,
    /// Row (along y).
    pub iy: usize,
}

impl Site {
    fn new(grid: &Grid, index: usize) -> Self {
        Self {
            index,
            ix: index % grid.nx(),
            iy: index / grid.nx(),
        }
    }
}

/// The applied load at an event.
///
/// Under displacement control the load carries the drive displacement `U_S`, and its force
/// is the driving spring's, `F = K_S (U_S - ⟨u_x⟩)`:
///
/// ```
/// use precursors::{Drive, Event, Lateral, Scene};
/// let k_s = 4e6;                                    // K_S (N/m), the paper's spring
/// let scene = Scene::builder()
///     .block(0.010, 0.004, 0.010)                   // Lx, Ly, Lz (m)
///     .cells(10, 4)                                 // 1 mm cells
///     .normal_load(40.0)                            // F_N (N)
///     .drive(Drive::Spring { stiffness: k_s, lateral: Lateral::Side })
///     .build()?;
/// let mut driver = scene.driver()?;
/// while let Some(event) = driver.step()? {
///     if let Event::LoadRaised { load } = event {
///         let u_s = load.drive_displacement.expect("a spring drive"); // U_S (m)
///         let mean_u_x = driver.mean_shear_displacement()?;          // ⟨u_x⟩ (m)
///         assert!((load.force - k_s * (u_s - mean_u_x)).abs() <= 1e-9 * load.force);
///         assert_eq!(driver.spring_force(), Some(load.force));
///     }
/// }
/// // Under force control there is no drive displacement.
/// let force = scene.to_builder().drive(Drive::default()).build()?;
/// assert_eq!(force.driver()?.load().drive_displacement, None);
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct Load {
    /// Total shear force `F = F_top + F_lat` (N): the control parameter under force
    /// control, the spring force `K_S (U_S - ⟨u_x⟩)` under displacement control.
    pub force: f64,
    /// Drive displacement `U_S` (m) under displacement control, `None` under force
    /// control.
    pub drive_displacement: Option<f64>,
}

/// What happened.
///
/// ```
/// use precursors::{Event, Scene};
/// let scene = Scene::builder()
///     .block(0.010, 0.004, 0.010)       // Lx, Ly, Lz (m)
///     .cells(10, 4)                     // 1 mm cells
///     .normal_load(40.0)                // F_N (N); the paper's rod drive
///     .build()?;
/// let events: Vec<Event> = scene.driver()?.collect::<Result<_, _>>()?;
/// // First the normal equilibrium at zero shear, last global slip.
/// assert!(matches!(events[0], Event::Stable { load, ruptures: 0 } if load.force == 0.0));
/// assert!(matches!(events.last(), Some(Event::GlobalSlip { .. })));
/// // At a stable state no site is over threshold: the load is only ever raised (N).
/// let raised: Vec<f64> = events
///     .iter()
///     .filter_map(|e| match e {
///         Event::LoadRaised { load } => Some(load.force),
///         _ => None,
///     })
///     .collect();
/// assert!(raised.windows(2).all(|w| w[0] <= w[1]));
/// // A rupture releases the elastic energy ½ k_x u_x² ΔA > 0 (J) of its spring.
/// for event in &events {
///     if let Event::Rupture { energy, .. } = event {
///         assert!(*energy > 0.0);
///     }
/// }
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum Event {
    /// The load was raised to the next breaking threshold.
    LoadRaised {
        /// The new load.
        load: Load,
    },
    /// A spring broke (irreversibly: the site slips).
    Rupture {
        /// Which site.
        site: Site,
        /// The load at the rupture (before the re-equilibration it triggers).
        load: Load,
        /// Elastic energy `½ k_x u_x² ΔA` of the spring when it broke (J).
        energy: f64,
    },
    /// A site lost contact in the normal re-equilibration (it may attach again).
    Detach {
        /// Which site.
        site: Site,
    },
    /// A detached site came back into contact.
    Attach {
        /// Which site.
        site: Site,
    },
    /// No site is over threshold at the current load: the end of an avalanche (also the
    /// initial state at zero shear).
    Stable {
        /// The load.
        load: Load,
        /// Ruptures in the avalanche that just ended.
        ruptures: usize,
    },
    /// Every spring is broken: the block slides. The last event of a run.
    GlobalSlip {
        /// The load at which the last spring broke.
        load: Load,
    },
}

impl Event {
    /// The kinds of events, as [`Event::kind`] names them (the `kind` column of a run's
    /// `events.csv`), in the order of the variants.
    pub const KINDS: [&'static str; 6] = [
        "load_raised",
        "rupture",
        "detach",
        "attach",
        "stable",
        "global_slip",
    ];

    /// The event's kind as a run's `events.csv` writes it (one of [`Event::KINDS`]).
    ///
    /// ```
    /// use precursors::{Event, Scene};
    /// let scene = Scene::builder().block(0.010, 0.004, 0.010).normal_load(100.0).build()?;
    /// let mut driver = scene.driver()?;
    /// let first = driver.step()?.expect("a first event");
    /// assert_eq!(first.kind(), "stable"); // the state at zero shear
    /// assert_eq!(driver.step()?.map(|e| e.kind()), Some("load_raised"));
    /// assert!(Event::KINDS.contains(&first.kind()));
    /// # Ok::<(), precursors::Error>(())
    /// ```
    pub fn kind(&self) -> &'static str {
        Self::KINDS[match self {
            Event::LoadRaised { .. } => 0,
            Event::Rupture { .. } => 1,
            Event::Detach { .. } => 2,
            Event::Attach { .. } => 3,
            Event::Stable { .. } => 4,
            Event::GlobalSlip { .. } => 5,
        }]
    }
}

/// Where the protocol stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
enum Phase {
    /// Before the first normal equilibrium.
    Start,
    /// Stable: the next step raises the load (a re-forming rule first re-forms the
    /// sites whose delay has passed).
    Stable,
    /// Stable, with the sites due re-formed and their equilibrium solved: the next step
    /// raises the load.
    Reformed,
    /// At fixed load, possibly with sites over threshold (`forced`: the site that set
    /// the threshold, over it by definition whatever the rounding).
    Avalanche { forced: Option<usize> },
    /// Global slip reported.
    Done,
    /// An error was returned; the run cannot go on.
    Failed,
}

/// Runs a [`Scene`] quasi-statically; an iterator of [`Event`]s.
///
/// ```
/// use precursors::{Error, Event, Scene};
/// let scene = Scene::builder()
///     .block(0.010, 0.004, 0.010)       // Lx, Ly, Lz (m)
///     .cells(10, 4)                     // 1 mm cells: ΔA = 1 mm²
///     .normal_load(40.0)                // F_N (N)
///     .seed(5)
///     .build()?;
/// let mut driver = scene.driver()?;
/// assert!(matches!(driver.normal_traction(), Err(Error::NotSolved { .. })));
/// // The first step solves the normal equilibrium at zero shear.
/// assert!(matches!(driver.step()?, Some(Event::Stable { ruptures: 0, .. })));
/// // The tractions carry the normal load: ΔA Σ φ_z = F_N (N).
/// let cell = driver.grid().cell_area();
/// let carried: f64 = driver.normal_traction()?.iter().map(|phi| phi * cell).sum();
/// assert!((carried - 40.0).abs() < 1e-9 * 40.0);
/// assert!(driver.real_contact_area()? > 0.0);                   // A_R (m²)
/// // On to global slip; then the iterator is done.
/// for event in &mut driver {
///     event?;
/// }
/// assert_eq!(driver.step()?, None);
/// assert_eq!(driver.interface().broken_count(), 40);
/// # Ok::<(), precursors::Error>(())
/// ```
///
/// # Reading the state
///
/// The fields of the current equilibrium exist from the first event on (the stable state
/// at zero shear). Seven readers return a `Result` only to report [`Error::NotSolved`]
/// before it, and never fail after it: [`Driver::normal_traction`],
/// [`Driver::normal_displacement`], [`Driver::shear_traction`],
/// [`Driver::shear_displacement`], [`Driver::mean_shear_displacement`],
/// [`Driver::slip_profile`] and [`Driver::area_exceeds_nominal`]. The contact areas
/// ([`Driver::real_contact_area`], [`Driver::cell_contact_area`],
/// [`Driver::column_contact_area`], and the precursor lengths) can also overflow
/// ([`Error::NonFinite`], under the paper's unbounded area law only);
/// [`Driver::stresses`] needs probes; the others that return a `Result` take input that
/// can be refused, or solve. "Before the first event" is `event_count() == 0`, also when
/// the first step failed. (2.0 is to solve the zero-shear state when the driver is made
/// and drop these `Result`s: docs/compatibility.md.)
#[derive(Debug)]
pub struct Driver {
    /// The scene it runs, shared (its set-up is read from it; checkpoints record its
    /// builder).
    scene: Scene,
    /// The scene's unit-load displacement `e` (m/N) per cell, derived once
    /// ([`Scene::unit_load_displacement`]): the tangential solves' right-hand side.
    unit_load: Vec<f64>,
    /// The scene's probes, then those added by [`Driver::add_probes`], in order.
    probes: Vec<StressProbe>,
    interface: Interface,
    solver: EquilibriumSolver,
    normal: Option<NormalEquilibrium>,
    response: Option<TangentialResponse>,
    /// The anchored rules' state (`None` under the paper's rule).
    contact: Option<ContactState>,
    /// The anchored rules' shear at zero load, `g0` (`None` under the paper's rule and
    /// before the first equilibrium).
    anchor: Option<AnchorResponse>,
    /// `φ_x = F g + g0` (Pa) of the current state (empty before the first equilibrium).
    shear_traction: Vec<f64>,
    /// `u_x = F u_x/F + u0` (m) of the current state (empty before the first equilibrium).
    shear_displacement: Vec<f64>,
    /// Breaking load `λ_i` (N) of each site in the current state (`+∞` off contact).
    breaking: Vec<f64>,
    /// The anchored rules' lower breaking load of each site (N): the site also breaks
    /// once the load falls to it ([`ContactRule::thresholds`]); empty under the paper's.
    breaking_low: Vec<f64>,
    initial_columns: Vec<f64>,
    /// Control parameter: `F` (N) under force control, `U_S` (m) under a spring.
    control: f64,
    pending: VecDeque<Event>,
    phase: Phase,
    avalanche_ruptures: usize,
    events: usize,
    stats: SolveStats,
    /// Why the driver failed: the message, with its causes, of the error that failed it
    /// (repeated by later steps as [`Error::DriverFailed`]); set on resuming a failed
    /// driver's checkpoint too.
    failure: Option<String>,
    /// Whether the failure was returned to the caller, by [`Driver::step`] or the
    /// iterator: from then on the iterator ends.
    failure_returned: bool,
    /// The digests of the table rows covered by the checkpoint this driver was resumed
    /// from, with its event (`RunTables::resume` checks the kept rows against them).
    kept_tables: Option<(usize, Vec<checkpoint::TableDigest>)>,
}

/// Where a [`Driver`]'s run stands ([`Driver::state`]): running, at global slip, or
/// failed. A loop over the events ends at global slip and, when it skips errors, at a
/// failure too; the state tells the two apart.
///
/// ```
/// use precursors::{RunState, Scene};
/// let scene = Scene::builder().block(0.010, 0.004, 0.010).normal_load(100.0).build()?;
/// let mut driver = scene.driver()?;
/// assert_eq!(driver.state(), RunState::Running);
/// while driver.step()?.is_some() {}
/// assert_eq!(driver.state(), RunState::GlobalSlip);
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum RunState {
    /// Events are still to come ([`Driver::step`] returns the next). A new driver is
    /// running: its first step solves the normal equilibrium at zero shear (before it,
    /// [`Driver::event_count`] is 0 and the state's fields are not solved yet: see
    /// [`Driver`] on reading the state).
    Running,
    /// [`Event::GlobalSlip`] was returned: every spring is broken, the block slides, the
    /// run is over (`step` returns `Ok(None)`).
    GlobalSlip,
    /// A step failed: the run cannot go on (`step` returns [`Error::DriverFailed`], with
    /// the first error's message; the iterator has yielded the error and ends). A driver
    /// resumed from a failed driver's checkpoint is failed too.
    Failed,
}

/// Cumulative solver work of a driver since it was created or resumed
/// ([`Driver::solve_stats`]): where a run spends its time.
///
/// ```
/// use precursors::{Event, Scene, SolveStats};
/// use std::ops::ControlFlow;
/// let scene = Scene::builder()
///     .block(0.010, 0.004, 0.010)       // Lx, Ly, Lz (m)
///     .cells(10, 4)                     // 1 mm cells
///     .normal_load(40.0)                // F_N (N)
///     .build()?;
/// let mut driver = scene.driver()?;
/// assert_eq!(driver.solve_stats(), SolveStats::default()); // nothing solved yet
/// let mut ruptures = 0;
/// driver.run(|event, _| {
///     ruptures += matches!(event, Event::Rupture { .. }) as usize;
///     ControlFlow::<()>::Continue(())
/// })?;
/// // One normal and one tangential equilibrium at zero shear and after every rupture
/// // but the last (global slip).
/// let stats = driver.solve_stats();
/// assert_eq!(stats.normal_solves, ruptures);
/// assert_eq!(stats.tangential_solves, ruptures);
/// assert!(stats.normal_active_set_iterations >= stats.normal_solves);
/// println!("{:.3} s in normal solves, {:.3} s in tangential ones",
///          stats.normal_seconds, stats.tangential_seconds);
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct SolveStats {
    /// Normal equilibria solved.
    pub normal_solves: usize,
    /// Active-set iterations, summed over the normal solves.
    pub normal_active_set_iterations: usize,
    /// CG iterations, summed over the normal solves.
    pub normal_iterations: usize,
    /// Wall time in normal solves (s).
    pub normal_seconds: f64,
    /// Tangential responses solved.
    pub tangential_solves: usize,
    /// CG iterations, summed over the tangential solves.
    pub tangential_iterations: usize,
    /// Wall time in tangential solves (s).
    pub tangential_seconds: f64,
}

impl Scene {
    /// A driver at zero shear (the first [`Driver::step`] solves the normal equilibrium).
    ///
    /// # Errors
    /// Those of
    /// [`EquilibriumSolverBuilder::build`](crate::solver::EquilibriumSolverBuilder::build)
    /// ([`Error::TooLargeForDense`], [`Error::DenseThreads`], ...).
    pub fn driver(&self) -> Result<Driver> {
        self.driver_with(self.run_options())
    }

    /// A driver at zero shear, as [`Scene::driver`], observed as `options` ask: it starts
    /// with the probes of [`RunOptions::probes`](crate::RunOptions::probes) where given
    /// (else the scene's, [`Scene::probes`]) and solves with
    /// [`RunOptions::threads`](crate::RunOptions::threads) threads where given (else the
    /// scene's solver options'). Neither changes an event; the options' recordings
    /// (fields, profiles) are [`crate::output::RunTables::create_with`]'s, given the same
    /// options.
    ///
    /// ```
    /// use precursors::{ProbeSpec, RunOptions, Scene};
    /// let scene = Scene::builder().block(0.010, 0.004, 0.010).normal_load(100.0).build()?;
    /// let options = RunOptions::new().probes(ProbeSpec::default().with_plane(0.002)).threads(2);
    /// let mut driver = scene.driver_with(&options)?;
    /// driver.step()?;
    /// assert_eq!(driver.stresses()?.planes.len(), 1);
    /// // At most 2 threads (a grid below 2048 cells is one part: 1).
    /// assert!(driver.threads() <= 2);
    /// // Observers: the events are those of the plain driver.
    /// let plain: Vec<_> = scene.driver()?.collect::<Result<_, _>>()?;
    /// let observed: Vec<_> = scene.driver_with(&options)?.collect::<Result<_, _>>()?;
    /// assert_eq!(plain, observed);
    /// # Ok::<(), precursors::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`Scene::driver`]; for probes that do not fit the scene,
    /// [`Error::OutOfRange`] or [`Error::InvalidParameter`] naming the key `probes.*`;
    /// [`Error::DenseThreads`] for more than one thread when the scene's solver options
    /// ask for the dense backend.
    pub fn driver_with(&self, options: &crate::recording::RunOptions) -> Result<Driver> {
        let probes = match options.probe_spec() {
            Some(spec) if spec != self.probes() => {
                crate::scene::check_probes(spec, self.grid())?;
                crate::scene::plan_probes(self.plan(), spec, self.lateral_load())?
            }
            _ => self.stress_probe().cloned(),
        };
        let mut solver_options = self.solver_options();
        if options.thread_count() > 0 {
            solver_options = solver_options
                .with_parallelism(crate::solver::Parallelism::Threads(options.thread_count()))?;
        }
        let solver = EquilibriumSolver::builder(self.plan().clone())
            .material(self.material())
            .solver_options(solver_options)
            .build()?;
        let n = self.grid().len();
        Ok(Driver {
            scene: self.clone(),
            unit_load: self.unit_load_displacement(),
            probes: probes.into_iter().collect(),
            interface: self.interface().clone(),
            solver,
            normal: None,
            response: None,
            contact: ContactState::new(self.contact_rule(), n),
            anchor: None,
            shear_traction: Vec::new(),
            shear_displacement: Vec::new(),
            breaking: vec![f64::INFINITY; n],
            breaking_low: Vec::new(),
            initial_columns: Vec::new(),
            control: 0.0,
            pending: VecDeque::new(),
            phase: Phase::Start,
            avalanche_ruptures: 0,
            events: 0,
            stats: SolveStats::default(),
            failure: None,
            failure_returned: false,
            kept_tables: None,
        })
    }
}

impl Driver {
    /// The next event, `Ok(None)` after [`Event::GlobalSlip`]. After an error the driver
    /// stays failed ([`Driver::state`]): every later call returns
    /// [`Error::DriverFailed`] with the first error's message, never `Ok(None)`, so a
    /// failed run cannot pass for a finished one. (As an iterator, the driver yields the
    /// failure once and then ends: [`Driver::next`](#method.next).)
    ///
    /// # Errors
    /// The first failure of a solve ([`Error::SolverNotConverged`],
    /// [`Error::Factorization`], [`Error::EmptyContact`], [`Error::NonFinite`],
    /// [`Error::ThreadPool`], ...); the driver then stays failed, and later calls return
    /// [`Error::DriverFailed`].
    pub fn step(&mut self) -> Result<Option<Event>> {
        loop {
            if let Some(event) = self.pending.pop_front() {
                self.events += 1;
                return Ok(Some(event));
            }
            match self.phase {
                Phase::Done => return Ok(None),
                Phase::Failed => {
                    self.failure_returned = true;
                    return Err(Error::DriverFailed {
                        reason: self.failure.clone().unwrap_or_default(),
                    });
                }
                _ => {}
            }
            let advanced = self.advance();
            self.refresh_shear();
            if let Err(e) = advanced {
                self.phase = Phase::Failed;
                // With its causes: the reason is all a later step reports of them.
                self.failure = Some(crate::error::Chain(&e).to_string());
                self.failure_returned = true;
                self.pending.clear();
                return Err(e);
            }
        }
    }

    /// Where the run stands: running, at global slip (returned by [`Driver::step`]), or
    /// failed (a step returned an error; `step` repeats it as [`Error::DriverFailed`]).
    ///
    /// ```
    /// use precursors::solver::{Backend, SolverOptions};
    /// use precursors::{Error, RunState, Scene};
    /// // One conjugate-gradient iteration per solve cannot reach the tolerance.
    /// let options = SolverOptions::default()
    ///     .with_backend(Backend::Spectral)?
    ///     .with_max_linear_iterations(1)?;
    /// let scene = Scene::builder()
    ///     .block(0.020, 0.004, 0.010)
    ///     .normal_load(100.0)
    ///     .solver_options(options)
    ///     .build()?;
    /// let mut driver = scene.driver()?;
    /// assert_eq!(driver.state(), RunState::Running);
    /// assert!(matches!(driver.step(), Err(Error::SolverNotConverged { .. })));
    /// assert_eq!(driver.state(), RunState::Failed);
    /// assert!(matches!(driver.step(), Err(Error::DriverFailed { .. })));
    /// assert!(driver.next().is_none()); // the iterator has nothing more
    /// # Ok::<(), precursors::Error>(())
    /// ```
    pub fn state(&self) -> RunState {
        match self.phase {
            Phase::Failed => RunState::Failed,
            Phase::Done if self.pending.is_empty() => RunState::GlobalSlip,
            _ => RunState::Running,
        }
    }

    /// Runs to global slip (or the first error), calling `observe` after every event with
    /// the driver in the state right after it; `observe` stops the run early by returning
    /// [`ControlFlow::Break`]. Returns the break's value, `None` when the run reached
    /// global slip. The driver stays usable after a break: a later `run` or
    /// [`Driver::step`] continues with the next event.
    ///
    /// ```
    /// use precursors::{Event, Scene};
    /// use std::ops::ControlFlow;
    /// let scene = Scene::builder()
    ///     .block(0.012, 0.002, 0.010)
    ///     .normal_load(50.0)
    ///     .seed(0)
    ///     .build()?;
    /// let mut driver = scene.driver()?;
    /// // Stop at the first rupture and report its site.
    /// let first = driver.run(|event, _| match event {
    ///     Event::Rupture { site, .. } => ControlFlow::Break(*site),
    ///     _ => ControlFlow::Continue(()),
    /// })?;
    /// assert!(first.is_some_and(|site| site.ix < 12));
    /// // To the end: no break value.
    /// let mut stable = 0;
    /// let end = driver.run(|event, _| {
    ///     stable += matches!(event, Event::Stable { .. }) as usize;
    ///     ControlFlow::<()>::Continue(())
    /// })?;
    /// assert!(end.is_none() && stable > 0);
    /// # Ok::<(), precursors::Error>(())
    /// ```
    ///
    /// # Errors
    /// The first error of [`Driver::step`].
    pub fn run<B>(
        &mut self,
        mut observe: impl FnMut(&Event, &Driver) -> ControlFlow<B>,
    ) -> Result<Option<B>> {
        while let Some(event) = self.step()? {
            if let ControlFlow::Break(value) = observe(&event, self) {
                return Ok(Some(value));
            }
        }
        Ok(None)
    }

    /// Recomputes the shear fields of the current state (`F` times the response per
    /// newton, plus the anchors' response under an anchored rule) after the load or the
    /// response changed.
    pub(crate) fn refresh_shear(&mut self) {
        let f = self.force();
        self.shear_traction.clear();
        self.shear_displacement.clear();
        match (&self.response, &self.anchor) {
            (Some(r), None) => {
                self.shear_traction.extend(r.traction.iter().map(|g| f * g));
                self.shear_displacement
                    .extend(r.displacement.iter().map(|u| f * u));
            }
            (Some(r), Some(a)) => {
                let affine = |g: &[f64], g0: &[f64]| -> Vec<f64> {
                    g.iter().zip(g0).map(|(g, g0)| f * g + g0).collect()
                };
                self.shear_traction = affine(&r.traction, &a.traction);
                self.shear_displacement = affine(&r.displacement, &a.displacement);
            }
            (None, _) => {}
        }
    }

    /// One protocol move; queues its events.
    fn advance(&mut self) -> Result<()> {
        match self.phase {
            Phase::Start => {
                self.equilibrate()?;
                self.initial_columns = self.column_contact_area()?;
                self.pending.push_back(Event::Stable {
                    load: self.load(),
                    ruptures: 0,
                });
                self.phase = Phase::Stable;
            }
            Phase::Stable => {
                if self.reform()? {
                    self.phase = Phase::Reformed;
                    return Ok(());
                }
                self.raise(false)?;
            }
            Phase::Reformed => self.raise(true)?,
            Phase::Avalanche { forced } => {
                let force = self.force();
                let best = self.contact_rule().next_rupture(
                    &self.interface,
                    (&self.breaking, &self.breaking_low),
                    force,
                    forced,
                    (
                        &self.response()?.traction,
                        self.anchor.as_ref().map_or(&[][..], |a| &a.traction),
                    ),
                    &self.normal()?.displacement,
                    self.grid().cell_area(),
                )?;
                match best {
                    None => {
                        self.pending.push_back(Event::Stable {
                            load: self.load(),
                            ruptures: self.avalanche_ruptures,
                        });
                        self.phase = Phase::Stable;
                    }
                    Some((i, energy)) => {
                        let load = self.load();
                        self.pending.push_back(Event::Rupture {
                            site: Site::new(self.scene.grid(), i),
                            load,
                            energy,
                        });
                        self.avalanche_ruptures += 1;
                        self.interface.break_site(i)?;
                        if let Some(contact) = &mut self.contact {
                            contact.broke(i, load.force);
                        }
                        if self.contact_rule().global_slip(&self.interface) {
                            self.pending.push_back(Event::GlobalSlip { load });
                            self.phase = Phase::Done;
                            return Ok(());
                        }
                        self.equilibrate()?;
                        self.phase = Phase::Avalanche { forced: None };
                    }
                }
            }
            Phase::Done | Phase::Failed => {}
        }
        Ok(())
    }

    /// The move from a stable state to the next load: the load raised to the next
    /// threshold (after re-formed sites, never lowered: a site they overload may be over
    /// threshold already).
    fn raise(&mut self, reformed: bool) -> Result<()> {
        let (site, threshold) = self.weakest()?;
        let control = match self.scene.drive() {
            Drive::Spring { stiffness, .. } => {
                // F = K_S (U_S - Û0) / (1 + K_S Û): invert for the U_S that makes F = λ.
                let u_s =
                    threshold * (1.0 + stiffness * self.response()?.offset_per_newton) / stiffness;
                match &self.anchor {
                    Some(a) => u_s + a.offset,
                    None => u_s,
                }
            }
            Drive::Force(_) => threshold,
        };
        self.control = match reformed {
            true => control.max(self.control),
            false => control,
        };
        self.pending
            .push_back(Event::LoadRaised { load: self.load() });
        self.avalanche_ruptures = 0;
        self.phase = Phase::Avalanche { forced: Some(site) };
        Ok(())
    }

    /// A re-forming rule's tick of the quasi-static clock at a stable state: the broken
    /// sites whose delay has passed become detached, and the equilibrium of the new site
    /// set is solved (queueing the sites that attach, anchored). Whether any re-formed.
    fn reform(&mut self) -> Result<bool> {
        let force = self.force();
        let load_scale = self.friction_limit();
        let friction_coefficient = self.friction_coefficient();
        let Some(contact) = &mut self.contact else {
            return Ok(false);
        };
        let normal = self.normal.as_ref().ok_or(Error::NotSolved {
            what: "the normal equilibrium",
        })?;
        let fields = Fields {
            states: self.interface.states(),
            normal_traction: &normal.traction,
            normal_displacement: &normal.displacement,
            friction_coefficient,
            friction_map: self.interface.friction_map(),
            force,
        };
        let due = contact.tick(self.scene.contact_rule(), &fields, load_scale);
        if due.is_empty() {
            return Ok(false);
        }
        for i in due {
            self.interface.set_state(i, SiteState::Detached);
        }
        self.equilibrate()?;
        Ok(true)
    }

    /// Normal then tangential equilibrium of the current site set; queues the sites that
    /// detached or attached.
    fn equilibrate(&mut self) -> Result<()> {
        let before = self.interface.states().to_vec();
        let clock = std::time::Instant::now();
        let normal = self
            .solver
            .solve_normal(&self.interface, self.scene.normal_load())?;
        self.interface.set_states(&normal.states)?;
        self.stats.normal_seconds += clock.elapsed().as_secs_f64();
        self.stats.normal_solves += 1;
        self.stats.normal_active_set_iterations += normal.report.active_set_iterations;
        self.stats.normal_iterations += normal.report.linear_iterations;
        let mut attached_now = Vec::new();
        let anchors = self.scene.contact_rule().anchors();
        if self.normal.is_some() {
            let grid = self.scene.grid();
            let pending = &mut self.pending;
            self.scene
                .contact_rule()
                .changes(&before, self.interface.states(), |i, attached| {
                    let site = Site::new(grid, i);
                    if attached && anchors {
                        attached_now.push(i);
                    }
                    pending.push_back(match attached {
                        true => Event::Attach { site },
                        false => Event::Detach { site },
                    })
                });
        }
        if anchors {
            self.anchor_new_sites(&normal.displacement, &attached_now)?;
        }
        let clock = std::time::Instant::now();
        let response =
            self.solver
                .solve_tangential(&self.interface, &normal.displacement, &self.unit_load)?;
        self.stats.tangential_seconds += clock.elapsed().as_secs_f64();
        self.stats.tangential_solves += 1;
        self.stats.tangential_iterations += response.report.linear_iterations;
        self.check_spring(&response)?;
        match self.contact.as_ref().map(|c| c.anchors.clone()) {
            None => {
                self.breaking = self.contact_rule().breaking_loads(
                    &self.interface,
                    &normal.traction,
                    &response.traction,
                    self.friction_coefficient(),
                )?;
            }
            Some(anchor_at) => {
                let anchor = match anchors {
                    true => Some(self.solve_anchor(&normal.displacement, &anchor_at)?),
                    false => None,
                };
                let rule = self.scene.contact_rule();
                let taus = match rule {
                    ContactRule::Custom(_) => {
                        let force = self.drive_force(
                            response.offset_per_newton,
                            anchor.as_ref().map_or(0.0, |a| a.offset),
                        );
                        let fields = Fields {
                            states: self.interface.states(),
                            normal_traction: &normal.traction,
                            normal_displacement: &normal.displacement,
                            friction_coefficient: self.friction_coefficient(),
                            friction_map: self.interface.friction_map(),
                            force,
                        };
                        self.contact
                            .as_ref()
                            .map(|c| c.custom_thresholds(rule, &fields))
                            .transpose()?
                            .flatten()
                    }
                    _ => None,
                };
                (self.breaking, self.breaking_low) = rule.thresholds(
                    &self.interface,
                    (&normal.traction, &response.traction),
                    anchor.as_ref().map(|a| &a.traction[..]),
                    self.friction_coefficient(),
                    taus.as_deref(),
                )?;
                self.anchor = anchor;
            }
        }
        self.normal = Some(normal);
        self.response = Some(response);
        Ok(())
    }

    /// Refuses a response under which the driving spring cannot load the block.
    fn check_spring(&self, response: &TangentialResponse) -> Result<()> {
        if let Drive::Spring { stiffness, .. } = self.scene.drive() {
            let denominator = 1.0 + stiffness * response.offset_per_newton;
            if denominator.is_nan() || denominator <= 0.0 {
                return Err(Error::InvalidParameter {
                    name: "mean shear compliance <u_x>/F (m/N)",
                    value: response.offset_per_newton,
                    reason: "the block's mean displacement per newton must exceed -1/K_S for the \
                             driving spring to load it",
                });
            }
        }
        Ok(())
    }

    /// The anchors' response `g0` at the normal displacements `u_z` (m), counted with
    /// the tangential solves.
    fn solve_anchor(&mut self, u_z: &[f64], anchors: &[f64]) -> Result<AnchorResponse> {
        let clock = std::time::Instant::now();
        let anchor = self
            .solver
            .solve_tangential_anchor(&self.interface, u_z, anchors)?;
        self.stats.tangential_seconds += clock.elapsed().as_secs_f64();
        self.stats.tangential_solves += 1;
        self.stats.tangential_iterations += anchor.report.linear_iterations;
        Ok(anchor)
    }

    /// Anchors the springs of the sites that just attached (`attached_now`) where they
    /// carry no shear at the current load: at their `u_x` in the equilibrium of the other
    /// attached sites at that load (normal displacements `u_z`, m), which inserting them
    /// then leaves as it is. Springs off the attached set lose their anchors.
    fn anchor_new_sites(&mut self, u_z: &[f64], attached_now: &[usize]) -> Result<()> {
        let Some(contact) = &mut self.contact else {
            return Ok(());
        };
        let states = self.interface.states();
        for (a, s) in contact.anchors.iter_mut().zip(states) {
            if *s != SiteState::Attached {
                *a = 0.0;
            }
        }
        if attached_now.is_empty() {
            return Ok(());
        }
        let mut others = self.interface.clone();
        for &i in attached_now {
            others.set_state(i, SiteState::Detached);
            contact.anchors[i] = 0.0;
        }
        let anchors = contact.anchors.clone();
        let u_x: Vec<f64> = if others.attached_count() == 0 {
            // No other site holds the block: the new ones attach where it stood.
            self.shear_displacement.clone()
        } else {
            let clock = std::time::Instant::now();
            let unit = self
                .solver
                .solve_tangential(&others, u_z, &self.unit_load)?;
            let zero = self
                .solver
                .solve_tangential_anchor(&others, u_z, &anchors)?;
            self.stats.tangential_seconds += clock.elapsed().as_secs_f64();
            self.stats.tangential_solves += 2;
            self.stats.tangential_iterations +=
                unit.report.linear_iterations + zero.report.linear_iterations;
            self.check_spring(&unit)?;
            let force = self.drive_force(unit.offset_per_newton, zero.offset);
            unit.displacement
                .iter()
                .zip(&zero.displacement)
                .map(|(u1, u0)| force * u1 + u0)
                .collect()
        };
        if let Some(contact) = &mut self.contact {
            for &i in attached_now {
                contact.anchors[i] = u_x.get(i).copied().unwrap_or(0.0);
            }
        }
        Ok(())
    }

    /// The attached site with the smallest breaking load, and that load (N).
    fn weakest(&self) -> Result<(usize, f64)> {
        self.contact_rule()
            .weakest(self.interface.states(), &self.breaking)
            .ok_or(Error::EmptyContact {
                available: self.interface.attached_count(),
                reason: "no attached site carries shear: the next threshold is undefined",
            })
    }

    /// The rule of the site transitions ([`crate::contact`]): the scene's.
    pub(crate) fn contact_rule(&self) -> &ContactRule {
        self.scene.contact_rule()
    }

    fn normal(&self) -> Result<&NormalEquilibrium> {
        self.normal.as_ref().ok_or(Error::NotSolved {
            what: "the normal equilibrium",
        })
    }

    fn response(&self) -> Result<&TangentialResponse> {
        self.response.as_ref().ok_or(Error::NotSolved {
            what: "the tangential equilibrium",
        })
    }

    /// The shear force `F` (N) in the current state.
    pub fn force(&self) -> f64 {
        match (self.scene.drive(), &self.response) {
            (Drive::Force(_), _) => self.control,
            (Drive::Spring { .. }, Some(r)) => self.drive_force(
                r.offset_per_newton,
                self.anchor.as_ref().map_or(0.0, |a| a.offset),
            ),
            (Drive::Spring { .. }, None) => 0.0,
        }
    }

    /// The shear force (N) of the current control in a state whose block moves by
    /// `per_newton` (m/N) per newton plus `offset` (m, the anchors'):
    /// `K_S (U_S - Û0) / (1 + K_S Û)` under a spring drive, the control under force.
    fn drive_force(&self, per_newton: f64, offset: f64) -> f64 {
        match self.scene.drive() {
            Drive::Force(_) => self.control,
            // `U_S - 0` is `U_S` bit for bit (`-0 - 0` is `-0`): the paper's expression.
            Drive::Spring { stiffness, .. } => {
                stiffness * (self.control - offset) / (1.0 + stiffness * per_newton)
            }
        }
    }

    /// The applied load in the current state.
    pub fn load(&self) -> Load {
        Load {
            force: self.force(),
            drive_displacement: match self.scene.drive() {
                Drive::Spring { .. } => Some(self.control),
                Drive::Force(_) => None,
            },
        }
    }

    /// The backend solving the equilibria (`Dense` or `Spectral`, never `Auto`).
    pub fn backend(&self) -> crate::solver::Backend {
        self.solver.backend()
    }

    /// The threads a solve actually uses ([`EquilibriumSolver::threads`]: 1 on the
    /// dense backend).
    pub fn threads(&self) -> usize {
        self.solver.threads()
    }

    /// Runs the next solves with `parallelism`; the events do not change (the parts of
    /// the grid are fixed by the grid).
    ///
    /// # Errors
    /// As [`EquilibriumSolver::set_parallelism`]: [`Error::InvalidCount`] for
    /// `Parallelism::Threads(0)`, [`Error::DenseThreads`] with an explicit dense backend.
    pub fn set_parallelism(&mut self, parallelism: crate::solver::Parallelism) -> Result<()> {
        self.solver.set_parallelism(parallelism)
    }

    /// The normal load `F_N` (N).
    pub fn normal_load(&self) -> f64 {
        self.scene.normal_load()
    }

    /// The scene this driver runs (its set-up, not the current state: see
    /// [`Driver::interface`] for the site states).
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The block's material (of the scene).
    pub fn material(&self) -> Material {
        self.scene.material()
    }

    /// The local friction coefficient `μ` (dimensionless) of the Coulomb rule, for
    /// instance for [`crate::PlaneStress::profile`]: the material's. With a friction map
    /// ([`crate::SceneBuilder::friction_map`]) each site has its own (the interface's
    /// [`crate::Interface::friction_map`]) and this one stays the reference of the
    /// probes' Coulomb stress.
    pub fn friction_coefficient(&self) -> f64 {
        self.scene.material().friction_coefficient()
    }

    /// The friction limit `μF_N` (N): the largest shear force a stable state can carry
    /// (every attached site holds `|φ_x,i| ≤ μ_i φ_z,i`), and the unit of the loads
    /// `F/(μF_N)` of the run's tables. `μ` is the material's
    /// ([`Driver::friction_coefficient`]), or the largest value of the scene's friction
    /// map ([`crate::SceneBuilder::friction_map`]) where that is larger.
    ///
    /// ```
    /// use precursors::{Drive, Scene, SiteMap};
    /// let base = Scene::builder()
    ///     .block(0.010, 0.004, 0.010)
    ///     .cells(10, 4)
    ///     .normal_load(40.0)                // F_N (N)
    ///     .drive(Drive::top());
    /// assert_eq!(base.clone().build()?.driver()?.friction_limit(), 0.5 * 40.0);
    /// let mu: Vec<f64> = (0..40).map(|i| if i == 7 { 0.8 } else { 0.3 }).collect();
    /// let driver = base.friction_map(SiteMap::Values(mu)).build()?.driver()?;
    /// assert_eq!(driver.friction_limit(), 0.8 * 40.0);              // the largest μ_i
    /// assert_eq!(driver.friction_coefficient(), 0.5);               // the material's
    /// # Ok::<(), precursors::Error>(())
    /// ```
    pub fn friction_limit(&self) -> f64 {
        self.scene.limit_friction_coefficient() * self.normal_load()
    }

    /// Cumulative solver work since this driver was created or resumed (counts and wall
    /// times; not part of a checkpoint).
    pub fn solve_stats(&self) -> SolveStats {
        self.stats
    }

    /// Events returned so far.
    pub fn event_count(&self) -> usize {
        self.events
    }

    /// The digests of the table rows covered by the checkpoint this driver was resumed
    /// from, while it stands at that checkpoint's event; `None` otherwise, or when the
    /// checkpoint holds none (layout version 3, or taken by [`Driver::checkpoint`]).
    pub(crate) fn kept_tables(&self) -> Option<&[TableDigest]> {
        match &self.kept_tables {
            Some((k, tables)) if *k == self.events => Some(tables),
            _ => None,
        }
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        self.scene.grid()
    }
}

impl Iterator for Driver {
    type Item = Result<Event>;

    /// The next event of [`Driver::step`]; `None` after [`Event::GlobalSlip`].
    ///
    /// A failure is yielded once, then the iterator ends (it is fused: `None` for ever):
    /// a loop that goes on after an error must not spin. Once is once per driver: after
    /// the error of a step that failed, or after [`Error::DriverFailed`] from
    /// [`Driver::step`], `next` gives `None` at once; a driver resumed from a failed
    /// driver's checkpoint yields [`Error::DriverFailed`] first. A loop that skips errors
    /// ends at the failure as it ends at global slip: [`Driver::state`] tells them apart.
    fn next(&mut self) -> Option<Self::Item> {
        if self.phase == Phase::Failed && self.failure_returned {
            return None;
        }
        self.step().transpose()
    }
}

impl std::iter::FusedIterator for Driver {}

#[cfg(test)]
impl Driver {
    /// Whether the solver holds a preconditioner (the scene tests' "leave out" check).
    pub(crate) fn solver_holds_preconditioners(&self) -> bool {
        self.solver.holds_preconditioners()
    }
}

//! The parallel layer: how the parts of a solve are spread over threads.
//!
//! A solve is a sequence of *phases*; a phase runs one task per part of the grid's
//! [`Partition`](crate::green::Partition) (fixed by the grid, never by the thread count)
//! and each task returns a few partial values. The calling thread (the leader) publishes
//! a phase, runs tasks itself, waits until every task has finished and reads the partial
//! values in part order, so every reduction is summed in the same order whatever thread
//! ran which part: the results do not depend on the number of threads, bit for bit.
//!
//! Helper threads claim tasks of the current phase as they come. The leader never waits
//! for a helper to *start*: a helper that is late (descheduled, or its pool busy with
//! other work) simply finds no task left, and with no helper at all the leader runs
//! every task. So a pool shared with other work cannot deadlock a solve, and pools can
//! be shared between solvers.
//!
//! Why phases rather than a fork-join per loop: a CG iteration at `N = 1e4` is about
//! 150 µs of work in a handful of phases, and waking a sleeping pool thread for each costs
//! tens of µs; helpers spin briefly between phases (then sleep), so a phase hand-off
//! costs well under a µs on a quiet machine.

use crate::error::{Error, Result};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, OnceLock};
use std::time::{Duration, Instant};

/// How many threads the solvers may use. The results are the same, bit for bit, for
/// every choice (the parts of the grid are fixed by the grid); only the wall time
/// changes.
///
/// ```
/// use precursors::solver::{Backend, Parallelism, SolverOptions};
/// use precursors::{Error, Event, Scene};
/// assert_eq!(Parallelism::default(), Parallelism::Sequential);
/// assert_eq!(Parallelism::Threads(4).threads(), 4);           // the caller and 3 helpers
/// assert!(Parallelism::all_cores().threads() >= 1);
/// // No thread at all is refused; so are threads on the dense backend (one part).
/// let none = SolverOptions::default().with_parallelism(Parallelism::Threads(0));
/// assert!(matches!(none, Err(Error::InvalidCount { .. })));
/// let dense = SolverOptions::default().with_backend(Backend::Dense)?;
/// let refused = dense.with_parallelism(Parallelism::Threads(2));
/// assert!(matches!(refused, Err(Error::DenseThreads { threads: 2, .. })));
/// // The same events, bit for bit, whatever the threads.
/// let scene = Scene::builder()
///     .block(0.010, 0.004, 0.010)       // Lx, Ly, Lz (m)
///     .cells(10, 4)                     // 1 mm cells
///     .normal_load(40.0)                // F_N (N)
///     .solver_options(SolverOptions::default().with_backend(Backend::Spectral)?)
///     .build()?;
/// let one: Vec<Event> = scene.driver()?.collect::<Result<_, _>>()?;
/// let mut driver = scene.driver()?;
/// driver.set_parallelism(Parallelism::Threads(2))?;
/// let two: Vec<Event> = driver.collect::<Result<_, _>>()?;
/// assert_eq!(one, two);
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum Parallelism {
    /// On the calling thread only (the default): no thread is started. The right choice
    /// when several scenes run at once (one per core).
    #[default]
    Sequential,
    /// The calling thread and `n - 1` helpers from a process-wide pool of `n - 1` threads
    /// shared by every solver that asks for `n` (started on first use, kept for the
    /// process). `n >= 1`; `Threads(1)` is [`Parallelism::Sequential`].
    Threads(usize),
    /// The calling thread and the other threads of the rayon pool the call runs in: the
    /// caller's pool inside its `ThreadPool::install`, rayon's global pool otherwise.
    CurrentPool,
}

impl Parallelism {
    /// Every core of the machine (`std::thread::available_parallelism`), or one if that
    /// is unknown.
    pub fn all_cores() -> Self {
        let n = std::thread::available_parallelism().map_or(1, |n| n.get());
        Self::Threads(n)
    }

    /// The parallelism a thread count asks for, as the scene file's `solver.threads`
    /// reads it (Python's `threads=` too): `0` every core ([`Parallelism::all_cores`]),
    /// `1` the calling thread only, `n` the caller and `n - 1` helpers.
    ///
    /// ```
    /// use precursors::solver::Parallelism;
    /// assert_eq!(Parallelism::from_count(1), Parallelism::Sequential);
    /// assert_eq!(Parallelism::from_count(3), Parallelism::Threads(3));
    /// assert_eq!(Parallelism::from_count(0), Parallelism::all_cores());
    /// ```
    pub fn from_count(threads: usize) -> Self {
        match threads {
            0 => Self::all_cores(),
            1 => Self::Sequential,
            n => Self::Threads(n),
        }
    }

    /// Threads a solve uses: the caller plus its helpers.
    pub fn threads(&self) -> usize {
        match self {
            Self::Sequential => 1,
            Self::Threads(n) => *n,
            Self::CurrentPool => rayon::current_num_threads(),
        }
    }

    /// Checks the thread count.
    pub(crate) fn validate(&self) -> Result<()> {
        match self {
            Self::Threads(0) => Err(Error::InvalidCount {
                name: "threads",
                value: 0,
                reason: "a solve needs at least one thread (Parallelism::Threads(n >= 1))",
            }),
            _ => Ok(()),
        }
    }
}

/// Partial values a task returns (a phase combines them over the parts in part order).
pub(crate) const SLOTS: usize = 4;

/// The work of one solve: what a task of a phase does on a part.
pub(crate) trait Tasks: Sync {
    /// What a phase is (the leader publishes it, helpers read it).
    type Phase: Copy + Send + Sync;
    /// Runs `phase` on part `part`.
    fn run(&self, phase: Self::Phase, part: usize) -> [f64; SLOTS];
}

/// The partial values of a phase, in part order.
pub(crate) struct Partials<'a>(&'a [[AtomicU64; SLOTS]]);

impl Partials<'_> {
    /// `Σ_k partial_k[slot]`, added in part order.
    pub(crate) fn sum(&self, slot: usize) -> f64 {
        self.0.iter().fold(0.0, |s, p| {
            s + f64::from_bits(p[slot].load(Ordering::Relaxed))
        })
    }

    /// `max_k partial_k[slot]`.
    pub(crate) fn max(&self, slot: usize) -> f64 {
        self.0.iter().fold(0.0f64, |m, p| {
            m.max(f64::from_bits(p[slot].load(Ordering::Relaxed)))
        })
    }
}

/// How long a helper spins for the next phase before it sleeps. Phases follow each other
/// within µs during a solve; a sleeping helper costs the leader a wake-up call.
const SPIN: Duration = Duration::from_micros(20);

/// The shared state of one solve's phases.
struct Board<P> {
    /// The generation of the current phase.
    generation: AtomicU64,
    /// The current phase (read by a helper before it claims a task of it).
    phase: Mutex<Option<P>>,
    /// Per part: the generation it was last claimed in.
    claims: Vec<AtomicU64>,
    /// Tasks of the current phase finished.
    done: AtomicUsize,
    /// Workers: the leader and its helpers.
    workers: usize,
    partials: Vec<[AtomicU64; SLOTS]>,
    finished: AtomicBool,
    poisoned: AtomicBool,
    sleepers: AtomicUsize,
    lock: Mutex<()>,
    wake: Condvar,
}

impl<P: Copy> Board<P> {
    fn new(parts: usize, workers: usize) -> Self {
        Self {
            generation: AtomicU64::new(0),
            phase: Mutex::new(None),
            claims: (0..parts).map(|_| AtomicU64::new(0)).collect(),
            done: AtomicUsize::new(0),
            workers,
            partials: (0..parts).map(|_| Default::default()).collect(),
            finished: AtomicBool::new(false),
            poisoned: AtomicBool::new(false),
            sleepers: AtomicUsize::new(0),
            lock: Mutex::new(()),
            wake: Condvar::new(),
        }
    }

    fn parts(&self) -> usize {
        self.partials.len()
    }

    /// Runs the tasks of generation `generation` that worker `worker` can claim: its own
    /// block of parts first (each part stays with one thread from phase to phase while
    /// every worker keeps up: its data stays in that core's cache), then, from the far
    /// end, the parts of workers that have not started theirs.
    fn work<T: Tasks<Phase = P>>(&self, tasks: &T, worker: usize, generation: u64, phase: P) {
        let _guard = PoisonOnPanic(&self.poisoned);
        let parts = self.parts();
        let block = |w: usize| w * parts / self.workers..(w + 1) * parts / self.workers;
        let mine = block(worker);
        let others = (0..parts).rev().filter(|k| !mine.contains(k));
        for part in mine.clone().chain(others) {
            let claimed = &self.claims[part];
            let old = claimed.load(Ordering::Acquire);
            if old >= generation
                || claimed
                    .compare_exchange(old, generation, Ordering::AcqRel, Ordering::Acquire)
                    .is_err()
            {
                continue;
            }
            let values = tasks.run(phase, part);
            for (slot, v) in self.partials[part].iter().zip(values) {
                slot.store(v.to_bits(), Ordering::Relaxed);
            }
            self.done.fetch_add(1, Ordering::Release);
        }
    }

    /// Helper `worker`: takes tasks of every phase it sees until the solve is finished.
    fn help<T: Tasks<Phase = P>>(&self, tasks: &T, worker: usize) {
        let mut seen = 0;
        let mut idle = Instant::now();
        let mut spins = 0u32;
        loop {
            if self.finished.load(Ordering::Acquire) || self.poisoned.load(Ordering::Relaxed) {
                return;
            }
            let generation = self.generation.load(Ordering::Acquire);
            if generation != seen {
                // The phase read here belongs to `generation` if a claim of it succeeds
                // (the leader publishes the next phase only once every task is done).
                let phase = *crate::lock::lock(&self.phase);
                if let Some(phase) = phase {
                    self.work(tasks, worker, generation, phase);
                }
                seen = generation;
                idle = Instant::now();
                spins = 0;
                continue;
            }
            spins += 1;
            if spins.is_multiple_of(64) && idle.elapsed() > SPIN {
                let guard = crate::lock::lock(&self.lock);
                self.sleepers.fetch_add(1, Ordering::SeqCst);
                let stale = self.generation.load(Ordering::SeqCst) == seen
                    && !self.finished.load(Ordering::SeqCst);
                if stale {
                    // The timeout only bounds a missed wake-up's cost.
                    drop(crate::lock::wait_timeout(
                        &self.wake,
                        guard,
                        Duration::from_millis(50),
                    ));
                }
                self.sleepers.fetch_sub(1, Ordering::SeqCst);
                idle = Instant::now();
                continue;
            }
            std::hint::spin_loop();
        }
    }

    fn notify(&self) {
        if self.sleepers.load(Ordering::SeqCst) > 0 {
            let _guard = crate::lock::lock(&self.lock);
            self.wake.notify_all();
        }
    }
}

/// Marks the board poisoned if a task unwinds, so that the leader stops waiting.
struct PoisonOnPanic<'a>(&'a AtomicBool);

impl Drop for PoisonOnPanic<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.store(true, Ordering::Relaxed);
        }
    }
}

/// The leader's handle on a solve's phases.
pub(crate) struct Crew<'a, T: Tasks> {
    tasks: &'a T,
    board: &'a Board<T::Phase>,
    generation: std::cell::Cell<u64>,
}

impl<T: Tasks> Crew<'_, T> {
    /// Runs `phase` on every part and returns the partial values in part order.
    pub(crate) fn run(&self, phase: T::Phase) -> Partials<'_> {
        let board = self.board;
        let generation = self.generation.get() + 1;
        self.generation.set(generation);
        *crate::lock::lock(&board.phase) = Some(phase);
        board.done.store(0, Ordering::Relaxed);
        board.generation.store(generation, Ordering::SeqCst);
        board.notify();
        board.work(self.tasks, 0, generation, phase);
        let parts = board.parts();
        let mut spins = 0u32;
        while board.done.load(Ordering::Acquire) < parts {
            assert!(
                !board.poisoned.load(Ordering::Relaxed),
                "a solver thread panicked"
            );
            spins += 1;
            if spins.is_multiple_of(1024) {
                // A helper holding a task was descheduled (more threads than cores): let
                // it run.
                std::thread::yield_now();
            } else {
                std::hint::spin_loop();
            }
        }
        Partials(&board.partials)
    }
}

/// Runs `leader` with a crew of `parallelism`'s threads for `tasks` over `parts` parts.
pub(crate) fn with_crew<T: Tasks, R>(
    parallelism: Parallelism,
    parts: usize,
    tasks: &T,
    leader: impl FnOnce(&Crew<'_, T>) -> R,
) -> Result<R> {
    let helpers = parallelism.threads().min(parts).saturating_sub(1);
    let board = Board::new(parts, helpers + 1);
    if helpers == 0 {
        return Ok(lead(None, &board, tasks, 0, leader));
    }
    Ok(match parallelism {
        Parallelism::Threads(n) => {
            shared_pool(n - 1)?.in_place_scope(|s| lead(Some(s), &board, tasks, helpers, leader))
        }
        _ => rayon::in_place_scope(|s| lead(Some(s), &board, tasks, helpers, leader)),
    })
}

/// Runs `task(k)` for every `k < parts` as one phase on `parallelism`'s threads and
/// returns the results in part order: for work between solves (a preconditioner's upkeep)
/// that would otherwise run on the calling thread alone while the helpers wait. Each
/// result is computed by one task, so it does not depend on the threads.
pub(crate) fn map_parts<R: Send>(
    parallelism: Parallelism,
    parts: usize,
    task: impl Fn(usize) -> R + Sync,
) -> Result<Vec<R>> {
    struct Map<F, R> {
        task: F,
        out: Vec<Mutex<Option<R>>>,
    }
    impl<F: Fn(usize) -> R + Sync, R: Send> Tasks for Map<F, R> {
        type Phase = ();
        fn run(&self, _: (), part: usize) -> [f64; SLOTS] {
            let value = (self.task)(part);
            *crate::lock::lock(&self.out[part]) = Some(value);
            [0.0; SLOTS]
        }
    }
    let map = Map {
        task,
        out: (0..parts).map(|_| Mutex::new(None)).collect(),
    };
    with_crew(parallelism, parts, &map, |crew| {
        crew.run(());
    })?;
    Ok(map
        .out
        .into_iter()
        .map(|slot| crate::lock::into_inner(slot).expect("every part ran"))
        .collect())
}

/// Spawns `helpers` helpers in `scope`, runs the leader, then releases the helpers.
fn lead<'s, T: Tasks, R>(
    scope: Option<&rayon::Scope<'s>>,
    board: &'s Board<T::Phase>,
    tasks: &'s T,
    helpers: usize,
    leader: impl FnOnce(&Crew<'_, T>) -> R,
) -> R {
    if let Some(scope) = scope {
        for worker in 1..=helpers {
            scope.spawn(move |_| board.help(tasks, worker));
        }
    }
    let crew = Crew {
        tasks,
        board,
        generation: std::cell::Cell::new(0),
    };
    let _release = ReleaseHelpers(board);
    leader(&crew)
}

/// Ends the helpers' loop when the leader returns or unwinds: a panic in the leader's own
/// logic must not leave them spinning while the scope waits for them.
struct ReleaseHelpers<'a, P: Copy>(&'a Board<P>);

impl<P: Copy> Drop for ReleaseHelpers<'_, P> {
    fn drop(&mut self) {
        self.0.finished.store(true, Ordering::SeqCst);
        self.0.notify();
    }
}

/// The shared pools, by size.
type Pools = Vec<(usize, Arc<rayon::ThreadPool>)>;

/// The process-wide pool of `size` helper threads ([`Parallelism::Threads`]).
fn shared_pool(size: usize) -> Result<Arc<rayon::ThreadPool>> {
    static POOLS: OnceLock<Mutex<Pools>> = OnceLock::new();
    let pools = POOLS.get_or_init(Default::default);
    let mut pools = crate::lock::lock(pools);
    if let Some((_, pool)) = pools.iter().find(|(n, _)| *n == size) {
        return Ok(pool.clone());
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(size)
        .thread_name(move |i| format!("precursors-{size}-{i}"))
        .build()
        .map_err(|e| Error::ThreadPool {
            threads: size + 1,
            source: Box::new(e),
        })?;
    let pool = Arc::new(pool);
    pools.push((size, pool.clone()));
    Ok(pool)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tasks that record which part ran and return part-dependent values whose sum
    /// depends on the order of addition.
    struct Sums {
        ran: Vec<AtomicUsize>,
    }

    impl Tasks for Sums {
        type Phase = u32;
        fn run(&self, phase: u32, part: usize) -> [f64; SLOTS] {
            self.ran[part].fetch_add(1, Ordering::Relaxed);
            let v = (1.0 + part as f64 * 1e-3).powi(phase as i32 % 7)
                * 10f64.powi(part as i32 % 17 - 8);
            [v, -v, v * v, part as f64]
        }
    }

    /// Every task runs exactly once per phase and the sums are the same bits for 1, 2, 3,
    /// 8 threads and the current pool.
    #[test]
    fn phases_run_every_part_once_in_any_crew() {
        let parts = 13;
        let mut reference: Option<Vec<u64>> = None;
        for par in [
            Parallelism::Sequential,
            Parallelism::Threads(2),
            Parallelism::Threads(3),
            Parallelism::Threads(8),
            Parallelism::CurrentPool,
        ] {
            let tasks = Sums {
                ran: (0..parts).map(|_| AtomicUsize::new(0)).collect(),
            };
            let phases = 500;
            let sums = with_crew(par, parts, &tasks, |crew| {
                (0..phases)
                    .map(|ph| {
                        let p = crew.run(ph);
                        (p.sum(0) + p.sum(1) + p.sum(2) + p.max(3)).to_bits()
                    })
                    .collect::<Vec<u64>>()
            })
            .unwrap();
            for r in &tasks.ran {
                assert_eq!(r.load(Ordering::Relaxed), phases as usize, "{par:?}");
            }
            match &reference {
                None => reference = Some(sums),
                Some(r) => assert_eq!(r, &sums, "{par:?}"),
            }
        }
    }

    /// A leader that panics between phases releases its helpers: the panic reaches the
    /// caller instead of a hang (checked on a thread of its own, so that a hang fails the
    /// test instead of stalling it).
    #[test]
    fn a_panicking_leader_releases_its_helpers() {
        for par in [Parallelism::Threads(2), Parallelism::Threads(3)] {
            let (sender, receiver) = std::sync::mpsc::channel();
            std::thread::spawn(move || {
                let tasks = Sums {
                    ran: (0..4).map(|_| AtomicUsize::new(0)).collect(),
                };
                let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    with_crew(par, 4, &tasks, |crew| {
                        crew.run(1);
                        panic!("the leader's logic failed");
                    })
                }));
                sender.send(outcome.is_err()).unwrap();
            });
            let panicked = receiver.recv_timeout(Duration::from_secs(60));
            assert_eq!(
                panicked,
                Ok(true),
                "{par:?}: the crew hung or did not panic"
            );
        }
    }

    /// `map_parts` runs every part once and returns the results in part order, on any
    /// crew (more parts than threads, fewer, none).
    #[test]
    fn map_parts_returns_every_part_in_order() {
        for par in [
            Parallelism::Sequential,
            Parallelism::Threads(2),
            Parallelism::Threads(3),
        ] {
            for parts in [0, 1, 2, 16] {
                let ran: Vec<AtomicUsize> = (0..parts).map(|_| AtomicUsize::new(0)).collect();
                let out = map_parts(par, parts, |k| {
                    ran[k].fetch_add(1, Ordering::Relaxed);
                    vec![k; k % 3]
                })
                .unwrap();
                let want: Vec<Vec<usize>> = (0..parts).map(|k| vec![k; k % 3]).collect();
                assert_eq!(out, want, "{par:?}, {parts} parts");
                assert!(ran.iter().all(|r| r.load(Ordering::Relaxed) == 1));
            }
        }
    }

    #[test]
    fn zero_threads_is_refused() {
        assert!(Parallelism::Threads(0).validate().is_err());
        assert!(Parallelism::all_cores().validate().is_ok());
    }
}

//! Where a device solve's time goes, by part (docs/gpu.md "Per-phase times"): off unless
//! asked for ([`record_cuda_phase_times`]), because each timed part waits for the stream
//! before and after it, which costs a synchronisation per part. Wall time on the host,
//! so a part's launch overhead counts with it (the GPU's own time per kernel is for a
//! profiler).

use super::seam::Device;
use crate::error::Result;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// The CUDA backend's solve time by part (seconds, wall time of the host, each part
/// between two synchronisations of the stream), summed over the solves since the last
/// [`record_cuda_phase_times`]. Parts do not overlap; what is left of `solve_seconds`
/// is the host's own work (the CG's scalar logic, the set's positions).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[non_exhaustive]
pub struct CudaPhaseTimes {
    /// Set solves timed.
    pub solves: u64,
    /// Their whole time (s).
    pub solve_seconds: f64,
    /// Operator products `A x` and the grid product `C_s f` (FFTs and their kernels) (s).
    pub operator_seconds: f64,
    /// Preconditioner applications (Jacobi, the spectral inverse, FSAI's two stencils,
    /// the coarse correction's restriction, solve and prolongation) (s).
    pub preconditioner_seconds: f64,
    /// The coarse space's upkeep per set solve: `E`'s changed columns, its factor and
    /// inverse (s).
    pub coarse_upkeep_seconds: f64,
    /// FSAI's rows refreshed on the host and copied, and the spectral inverse's table
    /// rebuilt (s).
    pub preconditioner_upkeep_seconds: f64,
    /// Reductions, with the copy of their three scalars to the host (s).
    pub reduction_seconds: f64,
    /// The CG's local vector updates (s).
    pub update_seconds: f64,
    /// The set problem up, the tractions and the grid product down (s).
    pub copy_seconds: f64,
}

/// The parts of [`CudaPhaseTimes`].
#[derive(Debug, Clone, Copy)]
pub(super) enum Part {
    Operator,
    Preconditioner,
    CoarseUpkeep,
    PreconditionerUpkeep,
    Reductions,
    Updates,
    Copies,
}

static RECORDING: AtomicBool = AtomicBool::new(false);
static TIMES: Mutex<CudaPhaseTimes> = Mutex::new(CudaPhaseTimes {
    solves: 0,
    solve_seconds: 0.0,
    operator_seconds: 0.0,
    preconditioner_seconds: 0.0,
    coarse_upkeep_seconds: 0.0,
    preconditioner_upkeep_seconds: 0.0,
    reduction_seconds: 0.0,
    update_seconds: 0.0,
    copy_seconds: 0.0,
});

/// Turns the CUDA backend's per-part timing on or off for the whole process, and returns
/// the times recorded since the last call (then starts again from zero). Off by default:
/// each timed part synchronises the stream twice, which slows small solves (N = 1e4) by
/// a few percent or more, so time the events and iterations with it off.
///
/// ```no_run
/// precursors::solver::record_cuda_phase_times(true);
/// // ... run a scene with backend cuda ...
/// let times = precursors::solver::record_cuda_phase_times(false);
/// println!("{:.3} s of {:.3} s in the operator", times.operator_seconds, times.solve_seconds);
/// ```
pub fn record_cuda_phase_times(on: bool) -> CudaPhaseTimes {
    RECORDING.store(on, Ordering::SeqCst);
    std::mem::take(&mut *crate::lock::lock(&TIMES))
}

fn recording() -> bool {
    RECORDING.load(Ordering::Relaxed)
}

fn add(part: Option<Part>, seconds: f64) {
    let mut t = crate::lock::lock(&TIMES);
    let slot = match part {
        None => {
            t.solves += 1;
            &mut t.solve_seconds
        }
        Some(Part::Operator) => &mut t.operator_seconds,
        Some(Part::Preconditioner) => &mut t.preconditioner_seconds,
        Some(Part::CoarseUpkeep) => &mut t.coarse_upkeep_seconds,
        Some(Part::PreconditionerUpkeep) => &mut t.preconditioner_upkeep_seconds,
        Some(Part::Reductions) => &mut t.reduction_seconds,
        Some(Part::Updates) => &mut t.update_seconds,
        Some(Part::Copies) => &mut t.copy_seconds,
    };
    *slot += seconds;
}

/// Waits for `device` (a timed part's start and end).
pub(super) fn sync<D: Device>(device: &D) -> Result<()> {
    device.synchronize("cuStreamSynchronize (phase timing)")
}

/// Runs `f`, its time added to `part` when recording (the stream drained before and
/// after, so the part's work is all inside). Parts do not nest: each caller times the
/// outermost call of its part only.
pub(super) fn timed<D: Device, T>(
    device: &D,
    part: Part,
    f: impl FnOnce() -> Result<T>,
) -> Result<T> {
    timed_mut(&mut (), |_| sync(device), part, |_| f())
}

/// [`timed`] of `f` on `state`, which `wait` drains (the device is part of the state `f`
/// changes).
pub(super) fn timed_mut<S, T>(
    state: &mut S,
    wait: impl Fn(&S) -> Result<()>,
    part: Part,
    f: impl FnOnce(&mut S) -> Result<T>,
) -> Result<T> {
    if !recording() {
        return f(state);
    }
    wait(state)?;
    let start = Instant::now();
    let out = f(state)?;
    wait(state)?;
    add(Some(part), start.elapsed().as_secs_f64());
    Ok(out)
}

/// Runs a whole set solve `f`, its time and count added when recording.
pub(super) fn timed_solve<T>(f: impl FnOnce() -> Result<T>) -> Result<T> {
    if !recording() {
        return f();
    }
    let start = Instant::now();
    let out = f()?;
    add(None, start.elapsed().as_secs_f64());
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The accumulator (no device: the parts are added directly). One test touches the
    /// process's switch, so no other test sees it on.
    #[test]
    fn times_accumulate_by_part_and_reset_when_read() {
        record_cuda_phase_times(true);
        add(Some(Part::Operator), 1.5);
        add(Some(Part::Operator), 0.25);
        add(Some(Part::Copies), 0.5);
        add(None, 3.0);
        assert!(recording());
        let t = record_cuda_phase_times(false);
        assert!(!recording());
        assert_eq!(
            t,
            CudaPhaseTimes {
                solves: 1,
                solve_seconds: 3.0,
                operator_seconds: 1.75,
                copy_seconds: 0.5,
                ..CudaPhaseTimes::default()
            }
        );
        assert_eq!(record_cuda_phase_times(false), CudaPhaseTimes::default());
        // Off: a timed part runs without touching the stream or the totals.
        assert_eq!(timed_solve(|| Ok(7)).unwrap(), 7);
        assert_eq!(record_cuda_phase_times(false), CudaPhaseTimes::default());
    }
}

//! The projected preconditioned conjugate gradients of every equilibrium solve, generic
//! over the set system (operator and preconditioner, both backends): on an attached set,
//! `A f + U 1 = b`, `1ᵀ f = total`, `A` symmetric positive definite.
//!
//! The iterates stay on the constraint (every search direction has zero sum), and the
//! multiplier `U` is estimated in the preconditioner's metric, `U = -1ᵀM⁻¹r / 1ᵀM⁻¹1`
//! (the constraint preconditioner of Gould, Hribar and Nocedal, 2001). With an exact
//! preconditioner (the dense backend's LDLᵀ factor) one iteration solves the system.
//!
//! The vectors are cut into the system's parts; every step runs as phases of the
//! [`parallel`](super::parallel) layer, and every reduction adds the parts' partial values
//! in part order, so the iterates do not depend on the number of threads.

use super::parallel::{with_crew, Crew, Parallelism, Tasks, SLOTS};
use crate::error::Result;
use std::ops::Range;
use std::sync::Mutex;

/// An operator and a preconditioner restricted to one attached set, applied part by part
/// in stages: a stage must have run on every part before the next one starts on any.
pub(crate) trait SetSystem: Sync {
    /// Number of parts.
    fn parts(&self) -> usize;
    /// The positions in the set (hence in every set vector) that part `k` owns.
    fn range(&self, k: usize) -> Range<usize>;
    /// Stages of the product `y = A x`.
    fn product_stages(&self) -> usize;
    /// Stage `stage` of `y = A x` on part `k` (`x`, `y` the part's slices; `y` is written by
    /// the last stage). `carry` is the sum over the parts, in part order, of what the
    /// previous stage returned (0 for the first stage).
    fn product(&self, stage: usize, k: usize, x: &[f64], y: &mut [f64], carry: f64) -> f64;
    /// Stages of the preconditioner `z = M⁻¹ r`.
    fn precondition_stages(&self) -> usize;
    /// Stage `stage` of `z = M⁻¹ r` on part `k`, as [`SetSystem::product`].
    fn precondition(&self, stage: usize, k: usize, r: &[f64], z: &mut [f64], carry: f64) -> f64;
    /// An upper bound of `‖A‖₂` (m/Pa), the scale of the backward error.
    fn norm_bound(&self) -> f64;
    /// Whether a coarse space corrects the preconditioner (two-level, A-DEF2: the
    /// methods below).
    fn has_coarse(&self) -> bool {
        false
    }
    /// Stage `stage` of `y = A x` on part `k` with buffers of its own (the product of
    /// [`SetSystem::product`] is kept: it is the solution's), as [`SetSystem::product`].
    fn coarse_product(
        &self,
        _stage: usize,
        _k: usize,
        _x: &[f64],
        _y: &mut [f64],
        _carry: f64,
    ) -> f64 {
        0.0
    }
    /// Part `k`'s share of the coarse restriction `Zᵀ (r - a)` (`a` given) or `Zᵀ r`.
    fn restrict(&self, _k: usize, _r: &[f64], _a: Option<&[f64]>) {}
    /// The coarse solve of the restriction, the parts' shares added in part order.
    fn coarse_solve(&self) {}
    /// `x += sign Z y` on part `k`, `y` the last coarse solution.
    fn prolong(&self, _k: usize, _x: &mut [f64], _sign: f64) {}
}

/// What [`projected_pcg`] returns.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PcgOutcome {
    /// The multiplier `U` (units of `b`).
    pub offset: f64,
    /// Iterations spent.
    pub iterations: usize,
    /// Normwise backward error `‖A f + U 1 - b‖∞ / (‖A‖ ‖f‖∞ + ‖b‖∞ + |U|)`.
    pub residual: f64,
    /// Whether `residual ≤ tol`.
    pub converged: bool,
}

/// The limits of one solve: the solver's [`SolverOptions`](super::SolverOptions) as they
/// are, or with a looser tolerance while the active set explores a cold set, or fewer
/// iterations for a stale dense factor (docs/architecture.md, "The solver's settings").
/// Made per set solve by `EquilibriumSolver::solve_set`, stored nowhere.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Effort {
    /// The normwise backward error to reach.
    pub tolerance: f64,
    /// Iterations at most.
    pub max_iterations: usize,
    /// The threads the solve may use (the results do not depend on them).
    pub parallelism: Parallelism,
}

/// The CG's vectors, part by part, kept between solves (no allocation and no zeroing of
/// `O(N)` memory on the calling thread per solve: every vector is written before it is
/// read).
#[derive(Debug, Default)]
pub(crate) struct PcgVectors(Vec<Mutex<Vectors>>);

/// Solves in place with `1ᵀ f = total`: `f` holds the warm start on entry and the
/// solution on exit. The last operator product the system ran is `A f` of the returned `f`
/// (a spectral system keeps `C f` on the grid: the displacements need no product of their
/// own).
pub(crate) fn projected_pcg<S: SetSystem>(
    sys: &S,
    b: &[f64],
    f: &mut [f64],
    total: f64,
    effort: Effort,
    vectors: &mut PcgVectors,
) -> Result<PcgOutcome> {
    let n = f.len();
    debug_assert_eq!(b.len(), n);
    let parts = sys.parts();
    vectors.0.resize_with(parts, Default::default);
    for (k, v) in vectors.0.iter_mut().enumerate() {
        let v = crate::lock::get_mut(v);
        let range = sys.range(k);
        let m = range.len();
        v.f.clear();
        v.f.extend_from_slice(&f[range]);
        for x in [
            &mut v.r,
            &mut v.z,
            &mut v.p,
            &mut v.q,
            &mut v.w,
            &mut v.best,
            &mut v.t,
        ] {
            x.resize(m, 0.0);
        }
    }
    let work = Work {
        sys,
        b,
        vectors: &vectors.0,
    };
    let norm_b = max_abs(b);
    let outcome = with_crew(effort.parallelism, parts, &work, |crew| {
        let phases = HostPhases { crew, sys };
        run_cg(phases, n, norm_b, total, effort)
    })??;
    for (k, v) in work.vectors.iter().enumerate() {
        f[sys.range(k)].copy_from_slice(&lock(v).f);
    }
    Ok(outcome)
}

/// One part's slices of the CG vectors.
#[derive(Debug, Default)]
struct Vectors {
    f: Vec<f64>,
    r: Vec<f64>,
    z: Vec<f64>,
    p: Vec<f64>,
    q: Vec<f64>,
    w: Vec<f64>,
    best: Vec<f64>,
    /// `A z` of the coarse correction.
    t: Vec<f64>,
}

/// Local updates a phase applies on its part before its main work, in this order.
#[derive(Clone, Copy, Default)]
pub(crate) struct Pre {
    /// `best = f`.
    pub(crate) keep_best: bool,
    /// `f = best`.
    pub(crate) restore_best: bool,
    /// `f += shift` (the sum fix).
    pub(crate) shift_f: Option<f64>,
    /// `f += α p`, and `r += α q` when the flag is set.
    pub(crate) step: Option<(f64, bool)>,
    /// `z += u w`, `r += u` (the projection, the multiplier folded into `r`).
    pub(crate) project: Option<f64>,
    /// `w = z`.
    pub(crate) w_from_z: bool,
    /// `p = β p - z` (`None` inside: `p = -z`, a restart).
    pub(crate) direction: Option<Option<f64>>,
    /// `r = 1` (to form `w = M⁻¹ 1`).
    pub(crate) fill_r_one: bool,
    /// `f -= Z y` (the coarse start), after the updates above.
    pub(crate) coarse_f: bool,
    /// `z += Z y` (the coarse correction), after the updates above.
    pub(crate) coarse_z: bool,
}

impl Pre {
    fn apply(&self, v: &mut Vectors) {
        let Vectors {
            f,
            r,
            z,
            p,
            q,
            w,
            best,
            t: _,
        } = v;
        if self.keep_best {
            best.copy_from_slice(f);
        }
        if self.restore_best {
            f.copy_from_slice(best);
        }
        if let Some(shift) = self.shift_f {
            f.iter_mut().for_each(|x| *x += shift);
        }
        if let Some((alpha, update_r)) = self.step {
            f.iter_mut()
                .zip(p.iter())
                .for_each(|(fi, pi)| *fi += alpha * pi);
            if update_r {
                r.iter_mut()
                    .zip(q.iter())
                    .for_each(|(ri, qi)| *ri += alpha * qi);
            }
        }
        if let Some(u) = self.project {
            z.iter_mut()
                .zip(w.iter())
                .for_each(|(zi, wi)| *zi += u * wi);
            r.iter_mut().for_each(|ri| *ri += u);
        }
        if self.w_from_z {
            w.copy_from_slice(z);
        }
        match self.direction {
            Some(Some(beta)) => p
                .iter_mut()
                .zip(z.iter())
                .for_each(|(pi, zi)| *pi = beta * *pi - zi),
            Some(None) => p.iter_mut().zip(z.iter()).for_each(|(pi, zi)| *pi = -zi),
            None => {}
        }
        if self.fill_r_one {
            r.fill(1.0);
        }
    }
}

/// `pre` applied to the vectors `[f, r, z, p, q, w, best]` (the tests' reference for the
/// device's local updates).
#[cfg(all(test, feature = "cuda"))]
pub(crate) fn apply_pre(pre: Pre, vectors: &mut [Vec<f64>]) {
    let [f, r, z, p, q, w, best] = vectors else {
        panic!("seven vectors")
    };
    let mut v = Vectors {
        f: std::mem::take(f),
        r: std::mem::take(r),
        z: std::mem::take(z),
        p: std::mem::take(p),
        q: std::mem::take(q),
        w: std::mem::take(w),
        best: std::mem::take(best),
        t: Vec::new(),
    };
    pre.apply(&mut v);
    (*f, *r, *z, *p, *q, *w, *best) = (v.f, v.r, v.z, v.p, v.q, v.w, v.best);
}

/// The main work of a phase.
#[derive(Clone, Copy)]
pub(crate) enum Main {
    /// Only the local updates.
    Nothing,
    /// `Σ f`.
    SumF,
    /// A stage of `q = A p`; the last returns `pᵀ q`.
    Direction { stage: usize, carry: f64 },
    /// A stage of `r = A f + U - b`.
    Residual {
        stage: usize,
        carry: f64,
        offset: f64,
    },
    /// A stage of `z = M⁻¹ r`; the last returns `Σ z`.
    Precondition { stage: usize, carry: f64 },
    /// `max |r|`, `max |f|`, `rᵀ z`.
    Measure,
    /// A stage of `t = A z` (the coarse buffers); the last restricts `r - t`.
    CoarseProduct { stage: usize, carry: f64 },
    /// Restricts `r`.
    Restrict,
}

/// One phase of the CG: local updates, then its main work.
#[derive(Clone, Copy)]
pub(crate) struct Phase {
    pub(crate) pre: Pre,
    pub(crate) main: Main,
}

struct Work<'a, S> {
    sys: &'a S,
    b: &'a [f64],
    vectors: &'a [Mutex<Vectors>],
}

use crate::lock::lock;

impl<S: SetSystem> Tasks for Work<'_, S> {
    type Phase = Phase;

    /// Slot 0: the system stage's return value (the next stage's carry); slots 1-3: the
    /// CG's partial values.
    fn run(&self, phase: Phase, k: usize) -> [f64; SLOTS] {
        let mut guard = lock(&self.vectors[k]);
        let v = &mut *guard;
        phase.pre.apply(v);
        let sys = self.sys;
        if phase.pre.coarse_f {
            sys.prolong(k, &mut v.f, -1.0);
        }
        if phase.pre.coarse_z {
            sys.prolong(k, &mut v.z, 1.0);
        }
        match phase.main {
            Main::Nothing => [0.0; SLOTS],
            Main::SumF => [0.0, sum(&v.f), 0.0, 0.0],
            Main::Direction { stage, carry } => {
                let out = sys.product(stage, k, &v.p, &mut v.q, carry);
                let last = stage + 1 == sys.product_stages();
                [out, if last { dot(&v.p, &v.q) } else { 0.0 }, 0.0, 0.0]
            }
            Main::Residual {
                stage,
                carry,
                offset,
            } => {
                let out = sys.product(stage, k, &v.f, &mut v.r, carry);
                if stage + 1 == sys.product_stages() {
                    let b = &self.b[sys.range(k)];
                    v.r.iter_mut()
                        .zip(b)
                        .for_each(|(ri, bi)| *ri += offset - bi);
                }
                [out, 0.0, 0.0, 0.0]
            }
            Main::Precondition { stage, carry } => {
                let out = sys.precondition(stage, k, &v.r, &mut v.z, carry);
                let last = stage + 1 == sys.precondition_stages();
                [out, if last { sum(&v.z) } else { 0.0 }, 0.0, 0.0]
            }
            Main::Measure => [0.0, max_abs(&v.r), max_abs(&v.f), dot(&v.r, &v.z)],
            Main::CoarseProduct { stage, carry } => {
                let out = sys.coarse_product(stage, k, &v.z, &mut v.t, carry);
                if stage + 1 == sys.product_stages() {
                    sys.restrict(k, &v.r, Some(&v.t));
                }
                [out, 0.0, 0.0, 0.0]
            }
            Main::Restrict => {
                sys.restrict(k, &v.r, None);
                [0.0; SLOTS]
            }
        }
    }
}

/// What runs the CG's phases: on the host the crew over the system's parts
/// ([`HostPhases`]), on a device its kernels. The CG's scalar logic ([`run_cg`]) is the
/// same for both. A failed phase (a device's launch, copy, FFT or synchronisation) stops
/// the CG with its error; the host's phases do not fail.
pub(crate) trait PhaseRunner {
    /// Runs `phase`; returns slots 1-3 combined over the parts: for [`Main::Measure`]
    /// `[max |r|, max |f|, rᵀz]`, otherwise `[the main work's value, the stage's carry
    /// for the next stage, 0]`.
    fn run(&mut self, phase: Phase) -> Result<[f64; 3]>;
    /// Stages of the product `y = A x`.
    fn product_stages(&self) -> usize;
    /// Stages of the preconditioner `z = M⁻¹ r`.
    fn precondition_stages(&self) -> usize;
    /// An upper bound of `‖A‖₂` (m/Pa), the scale of the backward error.
    fn norm_bound(&self) -> f64;
    /// Whether a coarse space corrects the preconditioner (A-DEF2).
    fn has_coarse(&self) -> bool;
    /// The coarse solve of the last restriction.
    fn coarse_solve(&mut self) -> Result<()>;
}

impl<R: PhaseRunner + ?Sized> PhaseRunner for &mut R {
    fn run(&mut self, phase: Phase) -> Result<[f64; 3]> {
        (**self).run(phase)
    }
    fn product_stages(&self) -> usize {
        (**self).product_stages()
    }
    fn precondition_stages(&self) -> usize {
        (**self).precondition_stages()
    }
    fn norm_bound(&self) -> f64 {
        (**self).norm_bound()
    }
    fn has_coarse(&self) -> bool {
        (**self).has_coarse()
    }
    fn coarse_solve(&mut self) -> Result<()> {
        (**self).coarse_solve()
    }
}

/// The host's phases: the crew runs each on every part of `sys`, the partial values added
/// in part order.
struct HostPhases<'c, 'a, S: SetSystem> {
    crew: &'c Crew<'c, Work<'a, S>>,
    sys: &'a S,
}

impl<S: SetSystem> PhaseRunner for HostPhases<'_, '_, S> {
    fn run(&mut self, phase: Phase) -> Result<[f64; 3]> {
        let p = self.crew.run(phase);
        Ok(match phase.main {
            Main::Measure => [p.max(1), p.max(2), p.sum(3)],
            _ => [p.sum(1), p.sum(0), 0.0],
        })
    }
    fn product_stages(&self) -> usize {
        self.sys.product_stages()
    }
    fn precondition_stages(&self) -> usize {
        self.sys.precondition_stages()
    }
    fn norm_bound(&self) -> f64 {
        self.sys.norm_bound()
    }
    fn has_coarse(&self) -> bool {
        self.sys.has_coarse()
    }
    fn coarse_solve(&mut self) -> Result<()> {
        self.sys.coarse_solve();
        Ok(())
    }
}

/// The projected CG on `runner`'s vectors (`n` values, `‖b‖∞ = norm_b`, `1ᵀ f = total`
/// kept): the one CG of every backend.
///
/// # Errors
/// The first failed phase's error (none on the host): the CG stops there.
pub(crate) fn run_cg<R: PhaseRunner>(
    runner: R,
    n: usize,
    norm_b: f64,
    total: f64,
    effort: Effort,
) -> Result<PcgOutcome> {
    Leader {
        norm_a: runner.norm_bound(),
        runner,
        n: n as f64,
        norm_b,
        total,
        effort,
        pending: Pre::default(),
        s1: 0.0,
        offset: 0.0,
    }
    .solve()
}

/// The CG's scalar logic, on the calling thread.
struct Leader<R: PhaseRunner> {
    runner: R,
    n: f64,
    norm_a: f64,
    norm_b: f64,
    /// `1ᵀ f` to keep.
    total: f64,
    effort: Effort,
    /// Local updates waiting for the next phase.
    pending: Pre,
    /// `1ᵀ M⁻¹ 1`.
    s1: f64,
    offset: f64,
}

impl<R: PhaseRunner> Leader<R> {
    /// Runs `main` with the pending updates; returns slots 1-3 combined (sums, or maxima
    /// for `Measure`'s first two).
    fn phase(&mut self, main: Main) -> Result<[f64; 3]> {
        let pre = std::mem::take(&mut self.pending);
        self.runner.run(Phase { pre, main })
    }

    /// Runs the stages of a product or a preconditioner (`make(stage, carry)`), the
    /// pending updates with the first; returns the last stage's slot 1.
    fn staged(&mut self, stages: usize, make: impl Fn(usize, f64) -> Main) -> Result<f64> {
        let mut carry = 0.0;
        let mut last = 0.0;
        for stage in 0..stages {
            let [value, passed, _] = self.phase(make(stage, carry))?;
            carry = passed;
            last = value;
        }
        Ok(last)
    }

    /// `f += (total - Σf)/n` (applied with the next phase).
    fn fix_sum(&mut self) -> Result<()> {
        let [s, _, _] = self.phase(Main::SumF)?;
        self.pending.shift_f = Some((self.total - s) / self.n);
        Ok(())
    }

    /// `r = A f + U - b`.
    fn residual(&mut self) -> Result<()> {
        let offset = self.offset;
        self.staged(self.runner.product_stages(), |stage, carry| {
            Main::Residual {
                stage,
                carry,
                offset,
            }
        })?;
        Ok(())
    }

    /// `z = P M⁻¹ r`, the multiplier folded into `U` and `r` (applied with the next
    /// phase). Why fold: the constant part of `r` would otherwise swamp `rᵀz` in rounding
    /// (the residual-update strategy of Gould, Hribar and Nocedal).
    ///
    /// With a coarse space, then A-DEF2 (Tang, Nabben, Vuik and Erlangga, 2009):
    /// `z ← z + Z E⁻¹ Zᵀ (r - A z)`, one more operator product. Why not the additive
    /// `z + Q r`: the smooth modes of an order −1 operator are its *large* eigenvalues,
    /// which an additive term enlarges instead of removing (docs/performance.md).
    fn project(&mut self) -> Result<()> {
        let sz = self.precondition()?;
        let u = -sz / self.s1;
        self.pending.project = Some(u);
        self.offset += u;
        if self.runner.has_coarse() {
            self.staged(self.runner.product_stages(), |stage, carry| {
                Main::CoarseProduct { stage, carry }
            })?;
            self.runner.coarse_solve()?;
            self.pending.coarse_z = true;
        }
        Ok(())
    }

    /// The coarse start `f ← f - Z E⁻¹ Zᵀ r` (A-DEF2 needs a residual with `Zᵀ r = 0`).
    fn coarse_start(&mut self) -> Result<()> {
        self.residual()?;
        self.phase(Main::Restrict)?;
        self.runner.coarse_solve()?;
        self.pending.coarse_f = true;
        self.fix_sum()
    }

    /// `z = M⁻¹ r`; returns `Σ z`.
    fn precondition(&mut self) -> Result<f64> {
        self.staged(self.runner.precondition_stages(), |stage, carry| {
            Main::Precondition { stage, carry }
        })
    }

    /// The backward error and `rᵀ z` (after the pending projection).
    fn measure(&mut self) -> Result<(f64, f64)> {
        let [r, f, rz] = self.phase(Main::Measure)?;
        let den = self.norm_a * f + self.norm_b + self.offset.abs();
        Ok((if den > 0.0 { r / den } else { 0.0 }, rz))
    }

    fn outcome(&self, iterations: usize, residual: f64) -> PcgOutcome {
        PcgOutcome {
            offset: self.offset,
            iterations,
            residual,
            converged: residual <= self.effort.tolerance,
        }
    }

    fn solve(mut self) -> Result<PcgOutcome> {
        let tol = self.effort.tolerance;
        self.fix_sum()?;
        if self.runner.has_coarse() {
            self.coarse_start()?;
        }
        // w = M⁻¹ 1.
        self.pending.fill_r_one = true;
        self.s1 = self.precondition()?;
        self.pending.w_from_z = true;
        self.residual()?;
        self.project()?;
        let (mut residual, mut rz) = self.measure()?;
        let mut iterations = 0;
        if residual <= tol {
            return Ok(self.outcome(iterations, residual));
        }
        self.pending.direction = Some(None);
        // The best iterate so far (CG residuals are not monotone).
        self.pending.keep_best = true;
        let mut best = (residual, self.offset);
        let mut confirmed = false;
        while iterations < self.effort.max_iterations {
            iterations += 1;
            let pq = self.staged(self.runner.product_stages(), |stage, carry| {
                Main::Direction { stage, carry }
            })?;
            if !(pq > 0.0 && rz.is_finite()) {
                break; // no curvature left: rounding has taken over
            }
            let alpha = rz / pq;
            if iterations % 64 == 0 {
                // Refresh the recurrence against drift.
                self.pending.step = Some((alpha, false));
                self.fix_sum()?;
                self.residual()?;
            } else {
                self.pending.step = Some((alpha, true));
            }
            self.project()?;
            let (r_now, rz_new) = self.measure()?;
            residual = r_now;
            if residual < best.0 {
                best = (residual, self.offset);
                self.pending.keep_best = true;
            }
            if residual <= tol {
                // Confirm with the true residual; rounding in the recurrence can flatter it.
                self.fix_sum()?;
                self.residual()?;
                self.project()?;
                let (r_true, rz_true) = self.measure()?;
                residual = r_true;
                if residual < best.0 {
                    best = (residual, self.offset);
                    self.pending.keep_best = true;
                }
                if residual <= tol {
                    confirmed = true;
                    break;
                }
                self.pending.direction = Some(None); // restart from the true residual
                rz = rz_true;
                continue;
            }
            self.pending.direction = Some(Some(rz_new / rz));
            rz = rz_new;
        }
        if !confirmed {
            // Report the true residual of the returned iterate, not the recurrence's.
            if best.0 < residual {
                self.pending.restore_best = true;
                self.offset = best.1;
            }
            self.fix_sum()?;
            self.residual()?;
            self.project()?;
            residual = self.measure()?.0;
        }
        // The last phase's updates touched only r, z (or nothing the caller reads).
        if self.pending.shift_f.is_some()
            || self.pending.step.is_some()
            || self.pending.restore_best
        {
            self.phase(Main::Nothing)?;
        }
        Ok(self.outcome(iterations, residual))
    }
}

/// Lanes of the reductions: eight independent partial results, combined pairwise at the
/// end. Why: a single running sum is one dependent chain of additions (latency bound,
/// about 8 µs per 6000 terms here); eight chains vectorise. The order is fixed, so the
/// result is deterministic.
const LANES: usize = 8;

fn combine(mut lanes: [f64; LANES], op: impl Fn(f64, f64) -> f64) -> f64 {
    let mut width = LANES;
    while width > 1 {
        width /= 2;
        for k in 0..width {
            lanes[k] = op(lanes[k], lanes[k + width]);
        }
    }
    lanes[0]
}

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut lanes = [0.0; LANES];
    let (ca, cb) = (a.chunks_exact(LANES), b.chunks_exact(LANES));
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in ca.zip(cb) {
        for k in 0..LANES {
            lanes[k] += x[k] * y[k];
        }
    }
    combine(lanes, |x, y| x + y) + tail
}

pub(crate) fn sum(a: &[f64]) -> f64 {
    let mut lanes = [0.0; LANES];
    let chunks = a.chunks_exact(LANES);
    let tail: f64 = chunks.remainder().iter().sum();
    for x in chunks {
        for k in 0..LANES {
            lanes[k] += x[k];
        }
    }
    combine(lanes, |x, y| x + y) + tail
}

pub(crate) fn max_abs(a: &[f64]) -> f64 {
    let mut lanes = [0.0f64; LANES];
    let chunks = a.chunks_exact(LANES);
    let tail = chunks
        .remainder()
        .iter()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    for x in chunks {
        for k in 0..LANES {
            let v = x[k].abs();
            // Not f64::max: a plain comparison vectorises (NaN never reaches here: a NaN
            // residual makes the curvature test fail first).
            lanes[k] = if v > lanes[k] { v } else { lanes[k] };
        }
    }
    combine(lanes, f64::max).max(tail)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;

    /// A runner whose `fail_at`-th call (phases and coarse solves counted together)
    /// fails, as a device's failed launch or copy does; the others return values a
    /// solve could see. It counts the calls made after the failure.
    struct Failing {
        calls: usize,
        fail_at: usize,
        after: usize,
        coarse: bool,
    }

    impl Failing {
        fn step(&mut self) -> Result<()> {
            self.calls += 1;
            if self.calls > self.fail_at {
                self.after += 1;
            }
            if self.calls == self.fail_at {
                return Err(Error::InvalidParameter {
                    name: "planted failure",
                    value: self.calls as f64,
                    reason: "injected by the test",
                });
            }
            Ok(())
        }
    }

    impl PhaseRunner for Failing {
        fn run(&mut self, phase: Phase) -> Result<[f64; 3]> {
            self.step()?;
            Ok(match phase.main {
                Main::Measure => [1.0, 1.0, 1.0],
                _ => [1.0, 0.0, 0.0],
            })
        }
        fn product_stages(&self) -> usize {
            1
        }
        fn precondition_stages(&self) -> usize {
            1
        }
        fn norm_bound(&self) -> f64 {
            1.0
        }
        fn has_coarse(&self) -> bool {
            self.coarse
        }
        fn coarse_solve(&mut self) -> Result<()> {
            self.step()
        }
    }

    /// Every phase and coarse solve, wherever the CG is, stops it with its own error:
    /// nothing runs after it and no outcome (NaN or other) comes back. Without a
    /// failure the same runner runs to its iteration limit (the reference count).
    #[test]
    fn a_failed_phase_stops_the_cg_with_its_error() {
        let effort = Effort {
            tolerance: 1e-300,
            max_iterations: 5,
            parallelism: Parallelism::Sequential,
        };
        for coarse in [false, true] {
            let mut clean = Failing {
                calls: 0,
                fail_at: usize::MAX,
                after: 0,
                coarse,
            };
            let outcome = run_cg(&mut clean, 4, 1.0, 0.0, effort).unwrap();
            assert_eq!(outcome.iterations, 5);
            let total = clean.calls;
            assert!(total > 20, "{total} calls");
            for fail_at in 1..=total {
                let mut runner = Failing {
                    calls: 0,
                    fail_at,
                    after: 0,
                    coarse,
                };
                let e = run_cg(&mut runner, 4, 1.0, 0.0, effort).unwrap_err();
                assert!(
                    matches!(e, Error::InvalidParameter { value, .. } if value == fail_at as f64),
                    "{e:?}"
                );
                assert_eq!(runner.after, 0, "call {fail_at} of {total}: calls after it");
            }
        }
    }
}

//! The spectral backend's projected CG, split in two fixed halves of the grid.
//!
//! The grid is cut between two rows (at `Ny / 2`) and the attached set with it: part `h`
//! owns the set's sites in its rows and the slices of every set vector on them. One CG
//! iteration is a sequence of phases; in each
//! phase every part works on its own data (reading the other part's grid buffers where
//! the phase needs them), and the phases are separated by barriers:
//!
//! * operator `C_SS x`: scatter `x` on the part's rows and DCT-II the rows; (barrier) the
//!   part's columns of both halves through the y-filter; (barrier) the part's rows back
//!   from both column blocks, DCT-III, gathered on the part's sites;
//! * preconditioner: Jacobi (local), FSAI `GᵀG` (scatter; (barrier) `G r` on the part's
//!   cells; (barrier) `Gᵀ` gathered per cell), or the restricted full-grid inverse (the
//!   operator's phases with another table);
//! * reductions (dot products, sums, maxima): each part publishes its partial value,
//!   (barrier), every part adds the two in the order part 0 + part 1.
//!
//! With one thread both parts run one after the other on the caller's thread (barriers
//! are no-ops); with two, each part runs on a thread of the solver's pool and the
//! barriers spin (then sleep). The arithmetic is the same: the results do not depend on the thread
//! count, bit for bit (tested). Why a split of its own rather than fork-join per loop: a
//! CG iteration at N = 1e4 is about 150 µs of work in some twenty loops, and a rayon
//! join costs a few µs on this machine (measured: 77 s against 83 s for the N = 1e4 run
//! with joins per loop); a spinning barrier costs well under a µs.

use super::fsai::Fsai;
use super::pcg::PcgOutcome;
use crate::green::{Dct2d, InfluencePlan};
use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, RwLock};
use std::time::{Duration, Instant};

/// Preconditioner of a split solve.
#[derive(Clone, Copy)]
pub(crate) enum SplitPrecond<'a> {
    /// `z = r / (diag_c + d)`.
    Jacobi { diag_c: f64 },
    /// `z = Gᵀ G r` with the factor's weight planes and offsets.
    Fsai(&'a Fsai),
    /// The restricted full-grid inverse `(C_s + d̄ I)⁻¹`, given by its filter table.
    Spectral(&'a [f64]),
}

/// The two halves of the grid: rows `0..rows` and `rows..Ny`, columns `0..cols` and
/// `cols..Nx` (the y-filter's blocks).
#[derive(Debug, Clone, Copy)]
struct Layout {
    nx: usize,
    ny: usize,
    rows: usize,
    cols: usize,
}

impl Layout {
    fn new(nx: usize, ny: usize, pairs: bool) -> Self {
        // Halves of rows (an odd half runs its last row alone: about half a pair more, far
        // less than the pair of rows an even split would move); even column blocks on the
        // paired path (the y-transforms pair columns).
        let even = |k: usize| if pairs { (k / 2) & !1 } else { k / 2 };
        Self {
            nx,
            ny,
            rows: ny / 2,
            cols: even(nx),
        }
    }

    /// First cell of part `h` and its cell count.
    fn cells(&self, h: usize) -> (usize, usize) {
        let split = self.rows * self.nx;
        if h == 0 {
            (0, split)
        } else {
            (split, self.nx * self.ny - split)
        }
    }

    /// First column of block `h` and its width.
    fn block(&self, h: usize) -> (usize, usize) {
        if h == 0 {
            (0, self.cols)
        } else {
            (self.cols, self.nx - self.cols)
        }
    }
}

/// A barrier for one or two parties: spins for a while (a phase is tens of µs, a futex
/// wake-up costs about as much), then sleeps on a condition variable, so that an
/// oversubscribed machine (more busy threads than cores: the other part descheduled)
/// does not burn the waiting core; fails loudly if the other party panicked instead of
/// waiting for ever.
struct SpinBarrier {
    parties: usize,
    arrived: AtomicUsize,
    generation: AtomicUsize,
    /// Parties asleep on `wake` (the last arriver notifies only when there are some).
    sleepers: AtomicUsize,
    poisoned: AtomicBool,
    lock: Mutex<()>,
    wake: Condvar,
}

/// How long a party spins before it sleeps. Measured (first 500 ruptures of the N = 1e4
/// run, two such runs at once on the two cores, each on two threads): 15.8 s per run
/// with 50 µs, 10.9 s with 25 µs, 8.3 s with 10 µs, against 3.9 s for one run alone;
/// alone, 10-50 µs are the same within noise.
const SPIN: Duration = Duration::from_micros(10);

impl SpinBarrier {
    fn new(parties: usize) -> Self {
        Self {
            parties,
            arrived: AtomicUsize::new(0),
            generation: AtomicUsize::new(0),
            sleepers: AtomicUsize::new(0),
            poisoned: AtomicBool::new(false),
            lock: Mutex::new(()),
            wake: Condvar::new(),
        }
    }

    fn wait(&self) {
        if self.parties == 1 {
            return;
        }
        // SeqCst on `generation` and `sleepers` on both sides: either the last arriver
        // sees a sleeper and notifies, or the sleeper sees the new generation.
        let generation = self.generation.load(Ordering::SeqCst);
        if self.arrived.fetch_add(1, Ordering::AcqRel) + 1 == self.parties {
            self.arrived.store(0, Ordering::Relaxed);
            self.generation.fetch_add(1, Ordering::SeqCst);
            if self.sleepers.load(Ordering::SeqCst) > 0 {
                let _guard = self.lock.lock().unwrap_or_else(|e| e.into_inner());
                self.wake.notify_all();
            }
            return;
        }
        let passed = || self.generation.load(Ordering::SeqCst) != generation;
        let start = Instant::now();
        let mut spins = 0u32;
        while !passed() {
            self.check_poison();
            spins += 1;
            if spins % 256 == 0 && start.elapsed() > SPIN {
                let mut guard = self.lock.lock().unwrap_or_else(|e| e.into_inner());
                self.sleepers.fetch_add(1, Ordering::SeqCst);
                while !passed() {
                    self.check_poison();
                    // The timeout only re-checks the poison flag.
                    guard = self
                        .wake
                        .wait_timeout(guard, Duration::from_millis(100))
                        .unwrap_or_else(|e| e.into_inner())
                        .0;
                }
                self.sleepers.fetch_sub(1, Ordering::SeqCst);
                return;
            }
            std::hint::spin_loop();
        }
    }

    fn check_poison(&self) {
        assert!(
            !self.poisoned.load(Ordering::Relaxed),
            "the other solver thread panicked"
        );
    }
}

/// Poisons the barrier if its part unwinds, so that the other part stops waiting.
struct PoisonOnPanic<'a>(&'a SpinBarrier);

impl Drop for PoisonOnPanic<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.poisoned.store(true, Ordering::Relaxed);
            let _guard = self.0.lock.lock().unwrap_or_else(|e| e.into_inner());
            self.0.wake.notify_all();
        }
    }
}

/// Partial values of the reductions: `[bank][part][slot]` (banks alternate, so that a
/// part never overwrites values the other has not read yet).
type Slots = [[[AtomicU64; 4]; 2]; 2];

/// Grid buffers one part writes and both read.
#[derive(Debug, Default)]
struct Shared {
    /// The part's rows (row-major, `rows x Nx`).
    rows: [RwLock<Vec<f64>>; 2],
    /// The part's column block after the y-filter (row-major, `Ny x width`).
    blocks: [RwLock<Vec<f64>>; 2],
    /// FSAI: the residual on the halo cells before the part (copied from part 0 by part
    /// 1, zeros before the grid) and on its cells; then `G r` on its cells and the halo
    /// after them (copied from part 1 by part 0, zeros past the grid).
    rf: [RwLock<Vec<f64>>; 2],
    yf: [RwLock<Vec<f64>>; 2],
}

/// One part's slices of the set vectors and its scratch.
#[derive(Debug, Default, Clone)]
struct Part {
    h: usize,
    /// The part's sites (ascending cells) and their compliances and right-hand sides.
    sites: Vec<usize>,
    d: Vec<f64>,
    b: Vec<f64>,
    w: Vec<f64>,
    f: Vec<f64>,
    r: Vec<f64>,
    z: Vec<f64>,
    p: Vec<f64>,
    q: Vec<f64>,
    best: Vec<f64>,
    /// FSAI `Gᵀ y` on the part's cells.
    zf: Vec<f64>,
    work: Vec<f64>,
}

/// Which set vector an operator product reads and writes.
#[derive(Clone, Copy)]
enum Product {
    /// `q = A p`.
    Direction,
    /// `r = A f + U - b`.
    Residual { offset: f64 },
    /// `z = (C_s + d̄ I)⁻¹ r` on the set (the spectral preconditioner).
    Precondition,
}

/// The split solver: scratch kept between solves, the pool of the solver's threads.
#[derive(Debug)]
pub(crate) struct Team {
    layout: Layout,
    pool: Option<Arc<rayon::ThreadPool>>,
    parts: [Part; 2],
    shared: Shared,
    /// The operator's table split in column blocks (row-major `Ny x width`).
    operator: [Vec<f64>; 2],
    /// The last solve's set, solution and `Σ f` while its transform `Ĝ f` is in the row
    /// buffers (the displacements that follow a solve need no product of their own).
    last: Option<(Vec<usize>, Vec<f64>, f64)>,
}

/// What a solve reads: the problem and the constants, shared by both parts.
struct Context<'a> {
    layout: Layout,
    dct: &'a Dct2d,
    operator: &'a [Vec<f64>; 2],
    precond_blocks: Option<[Vec<f64>; 2]>,
    precond: SplitPrecond<'a>,
    scale: f64,
    shift: f64,
    total: f64,
    n: usize,
    norm_a: f64,
    norm_b: f64,
    tol: f64,
    max_iterations: usize,
    shared: &'a Shared,
    barrier: SpinBarrier,
    slots: Slots,
}

/// Splits a row-major `Ny x Nx` table in the layout's column blocks.
fn column_blocks(layout: &Layout, table: &[f64]) -> [Vec<f64>; 2] {
    std::array::from_fn(|h| {
        let (c0, width) = layout.block(h);
        table
            .chunks_exact(layout.nx)
            .flat_map(|row| row[c0..c0 + width].iter().copied())
            .collect()
    })
}

impl Team {
    pub(crate) fn new(plan: &InfluencePlan, pool: Option<Arc<rayon::ThreadPool>>) -> Self {
        let (dct, table) = plan.transforms();
        let grid = plan.grid();
        let layout = Layout::new(grid.nx(), grid.ny(), dct.pairs_rows());
        let operator = column_blocks(&layout, table);
        Self {
            layout,
            pool,
            parts: [0, 1].map(|h| Part {
                h,
                ..Part::default()
            }),
            shared: Shared::default(),
            operator,
            last: None,
        }
    }

    /// Solves `A f + U 1 = b`, `1ᵀ f = total` on `set` (ascending) with `A = C_SS +
    /// diag(d)`, `C_s = scale (Ĝ - shift 11ᵀ)`, like [`super::pcg::projected_pcg`]: `f`
    /// holds the warm start on entry and the solution on exit.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn solve(
        &mut self,
        plan: &InfluencePlan,
        (scale, shift, norm_a): (f64, f64, f64),
        precond: SplitPrecond<'_>,
        set: &[usize],
        d: &[f64],
        b: &[f64],
        total: f64,
        f: &mut [f64],
        tol: f64,
        max_iterations: usize,
    ) -> PcgOutcome {
        let layout = self.layout;
        let (split, _) = layout.cells(1);
        let cut = set.partition_point(|&i| i < split);
        for part in &mut self.parts {
            let range = if part.h == 0 { 0..cut } else { cut..set.len() };
            let m = range.len();
            part.sites.clear();
            part.sites.extend_from_slice(&set[range.clone()]);
            for (v, src) in [(&mut part.d, d), (&mut part.b, b), (&mut part.f, &*f)] {
                v.clear();
                v.extend_from_slice(&src[range.clone()]);
            }
            for v in [
                &mut part.w,
                &mut part.r,
                &mut part.z,
                &mut part.p,
                &mut part.q,
                &mut part.best,
            ] {
                v.clear();
                v.resize(m, 0.0);
            }
        }
        let parties = if self.pool.is_some() { 2 } else { 1 };
        let precond_blocks = match precond {
            SplitPrecond::Spectral(table) => Some(column_blocks(&layout, table)),
            _ => None,
        };
        let context = Context {
            layout,
            dct: plan.transforms().0,
            operator: &self.operator,
            precond_blocks,
            precond,
            scale,
            shift,
            total,
            n: set.len(),
            norm_a,
            norm_b: b.iter().fold(0.0f64, |m, x| m.max(x.abs())),
            tol,
            max_iterations,
            shared: &self.shared,
            barrier: SpinBarrier::new(parties),
            slots: Default::default(),
        };
        self.last = None;
        let keeps_transform = !matches!(precond, SplitPrecond::Spectral(_));
        let (outcome, sum) = match &self.pool {
            None => context.run(&mut self.parts),
            Some(pool) => {
                let (first, second) = self.parts.split_at_mut(1);
                let context = &context;
                let (a, b) =
                    pool.install(|| rayon::join(|| context.run(first), || context.run(second)));
                debug_assert_eq!(a.0.iterations, b.0.iterations);
                debug_assert_eq!(a.0.residual.to_bits(), b.0.residual.to_bits());
                a
            }
        };
        f[..cut].copy_from_slice(&self.parts[0].f);
        f[cut..].copy_from_slice(&self.parts[1].f);
        if keeps_transform {
            self.last = Some((set.to_vec(), f.to_vec(), sum));
        }
        outcome
    }

    /// Drops the last solve's transform (tests compare against the unsplit product).
    #[cfg(test)]
    pub(crate) fn forget_last(&mut self) {
        self.last = None;
    }

    /// `Ĝ x` on every cell and `Σ x` when `(set, x)` is the last solve's solution (its
    /// transform is still in the row buffers), else `None`.
    pub(crate) fn last_transform(&self, set: &[usize], x: &[f64], out: &mut [f64]) -> Option<f64> {
        let (last_set, last_f, sum) = self.last.as_ref()?;
        let same = last_set == set
            && last_f
                .iter()
                .zip(x)
                .all(|(a, b)| a.to_bits() == b.to_bits());
        if !same || last_f.len() != x.len() {
            return None;
        }
        let (split, _) = self.layout.cells(1);
        out[..split].copy_from_slice(&read(&self.shared.rows[0]));
        out[split..].copy_from_slice(&read(&self.shared.rows[1]));
        Some(*sum)
    }
}

/// A part's view of the reductions (each part counts them alike, so banks agree).
struct Reducer {
    count: usize,
}

impl Reducer {
    /// Publishes `local(part)` for every part of this thread, waits, returns the values of
    /// part 0 and part 1.
    fn gather(
        &mut self,
        context: &Context<'_>,
        parts: &[Part],
        local: impl Fn(&Part) -> [f64; 4],
    ) -> [[f64; 4]; 2] {
        let bank = &context.slots[self.count % 2];
        self.count += 1;
        for part in parts {
            for (slot, v) in bank[part.h].iter().zip(local(part)) {
                slot.store(v.to_bits(), Ordering::Relaxed);
            }
        }
        context.barrier.wait();
        std::array::from_fn(|h| {
            std::array::from_fn(|k| f64::from_bits(bank[h][k].load(Ordering::Relaxed)))
        })
    }

    /// `Σ local` over both parts (part 0 + part 1).
    fn sum(&mut self, context: &Context<'_>, parts: &[Part], local: impl Fn(&Part) -> f64) -> f64 {
        let v = self.gather(context, parts, |p| [local(p), 0.0, 0.0, 0.0]);
        v[0][0] + v[1][0]
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

fn dot(a: &[f64], b: &[f64]) -> f64 {
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

fn sum(a: &[f64]) -> f64 {
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

fn max_abs(a: &[f64]) -> f64 {
    let mut lanes = [0.0f64; LANES];
    let chunks = a.chunks_exact(LANES);
    let tail = chunks
        .remainder()
        .iter()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    for x in chunks {
        for k in 0..LANES {
            let v = x[k].abs();
            // Not f64::max: a plain comparison vectorises (NaN never reaches here:
            // a NaN residual makes the curvature test fail first).
            lanes[k] = if v > lanes[k] { v } else { lanes[k] };
        }
    }
    combine(lanes, f64::max).max(tail)
}

/// Cells per block of the FSAI passes (the block's values stay in L1 across the slots).
const BLOCK: usize = 256;

impl Context<'_> {
    /// The whole projected CG for the parts of this thread (one or both).
    /// Also returns `Σ f` of the last operator product, whose transform `Ĝ f` of the
    /// returned `f` is then left in the row buffers (with the Jacobi and FSAI
    /// preconditioners, which run no product after it).
    fn run(&self, parts: &mut [Part]) -> (PcgOutcome, f64) {
        let _guard = PoisonOnPanic(&self.barrier);
        let mut red = Reducer { count: 0 };
        let n = self.n as f64;
        let total = self.total;
        let fix_sum = |red: &mut Reducer, parts: &mut [Part]| {
            let sum = red.sum(self, parts, |p| sum(&p.f));
            let shift = (total - sum) / n;
            for p in parts.iter_mut() {
                p.f.iter_mut().for_each(|x| *x += shift);
            }
        };
        fix_sum(&mut red, parts);
        // w = M⁻¹ 1 (through r and z).
        for p in parts.iter_mut() {
            p.r.fill(1.0);
        }
        self.precondition(&mut red, parts);
        for p in parts.iter_mut() {
            p.w.copy_from_slice(&p.z);
        }
        let s1 = red.sum(self, parts, |p| sum(&p.w));
        let residual_of = |red: &mut Reducer, parts: &mut [Part], offset: f64| {
            self.product(red, parts, Product::Residual { offset })
        };
        // z = P M⁻¹ r and the multiplier folded into U and r (see projected_pcg).
        let project = |red: &mut Reducer, parts: &mut [Part], offset: &mut f64| {
            self.precondition(red, parts);
            let u = -red.sum(self, parts, |p| sum(&p.z)) / s1;
            for p in parts.iter_mut() {
                p.z.iter_mut().zip(&p.w).for_each(|(zi, wi)| *zi += u * wi);
                p.r.iter_mut().for_each(|ri| *ri += u);
            }
            *offset += u;
        };
        // Backward error and rᵀz in one reduction.
        let measure = |red: &mut Reducer, parts: &[Part], u: f64| -> (f64, f64) {
            let v = red.gather(self, parts, |p| {
                [max_abs(&p.r), max_abs(&p.f), dot(&p.r, &p.z), 0.0]
            });
            let num = v[0][0].max(v[1][0]);
            let den = self.norm_a * v[0][1].max(v[1][1]) + self.norm_b + u.abs();
            let residual = if den > 0.0 { num / den } else { 0.0 };
            (residual, v[0][2] + v[1][2])
        };
        let keep_best = |parts: &mut [Part], best: &mut (f64, f64), residual: f64, offset: f64| {
            if residual < best.0 {
                *best = (residual, offset);
                for p in parts.iter_mut() {
                    p.best.copy_from_slice(&p.f);
                }
            }
        };

        let tol = self.tol;
        let outcome = |offset, iterations, residual: f64| PcgOutcome {
            offset,
            iterations,
            residual,
            converged: residual <= tol,
        };
        let mut offset = 0.0;
        let mut last_sum = residual_of(&mut red, parts, offset);
        project(&mut red, parts, &mut offset);
        let (mut residual, mut rz) = measure(&mut red, parts, offset);
        let mut iterations = 0;
        if residual <= self.tol {
            return (outcome(offset, iterations, residual), last_sum);
        }
        for p in parts.iter_mut() {
            p.p.iter_mut().zip(&p.z).for_each(|(pi, zi)| *pi = -zi);
        }
        let mut best = (residual, offset);
        for p in parts.iter_mut() {
            p.best.copy_from_slice(&p.f);
        }
        let mut confirmed = false;
        while iterations < self.max_iterations {
            iterations += 1;
            self.product(&mut red, parts, Product::Direction);
            let pq = red.sum(self, parts, |p| dot(&p.p, &p.q));
            if !(pq > 0.0 && rz.is_finite()) {
                break; // no curvature left: rounding has taken over
            }
            let alpha = rz / pq;
            let refresh = iterations % 64 == 0;
            for p in parts.iter_mut() {
                p.f.iter_mut()
                    .zip(&p.p)
                    .for_each(|(fi, pi)| *fi += alpha * pi);
                if !refresh {
                    p.r.iter_mut()
                        .zip(&p.q)
                        .for_each(|(ri, qi)| *ri += alpha * qi);
                }
            }
            if refresh {
                fix_sum(&mut red, parts);
                last_sum = residual_of(&mut red, parts, offset); // refresh against drift
            }
            project(&mut red, parts, &mut offset);
            let (r_now, rz_new) = measure(&mut red, parts, offset);
            residual = r_now;
            keep_best(parts, &mut best, residual, offset);
            if residual <= self.tol {
                // Confirm with the true residual; rounding in the recurrence can flatter it.
                fix_sum(&mut red, parts);
                last_sum = residual_of(&mut red, parts, offset);
                project(&mut red, parts, &mut offset);
                let (r_true, rz_true) = measure(&mut red, parts, offset);
                residual = r_true;
                keep_best(parts, &mut best, residual, offset);
                if residual <= self.tol {
                    confirmed = true;
                    break;
                }
                // Restart from the true residual.
                for p in parts.iter_mut() {
                    p.p.iter_mut().zip(&p.z).for_each(|(pi, zi)| *pi = -zi);
                }
                rz = rz_true;
                continue;
            }
            let beta = rz_new / rz;
            rz = rz_new;
            for p in parts.iter_mut() {
                p.p.iter_mut()
                    .zip(&p.z)
                    .for_each(|(pi, zi)| *pi = beta * *pi - zi);
            }
        }
        if confirmed {
            return (outcome(offset, iterations, residual), last_sum);
        }
        // Report the true residual of the returned iterate, not the recurrence's.
        if best.0 < residual {
            for p in parts.iter_mut() {
                p.f.copy_from_slice(&p.best);
            }
            offset = best.1;
        }
        fix_sum(&mut red, parts);
        last_sum = residual_of(&mut red, parts, offset);
        project(&mut red, parts, &mut offset);
        residual = measure(&mut red, parts, offset).0;
        (outcome(offset, iterations, residual), last_sum)
    }

    /// `z = M⁻¹ r` on every part.
    fn precondition(&self, red: &mut Reducer, parts: &mut [Part]) {
        match self.precond {
            SplitPrecond::Jacobi { diag_c } => {
                for p in parts.iter_mut() {
                    for (zi, (ri, d)) in p.z.iter_mut().zip(p.r.iter().zip(&p.d)) {
                        *zi = ri / (diag_c + d);
                    }
                }
            }
            SplitPrecond::Spectral(_) => {
                self.product(red, parts, Product::Precondition);
            }
            SplitPrecond::Fsai(fsai) => self.fsai(parts, fsai),
        }
    }

    /// `z = Gᵀ G r`: scatter; `y_i = Σ_k w_k[i] r[i - o_k]` on the part's cells; `z_j =
    /// Σ_k w_k[j + o_k] y[j + o_k]` on the part's cells, gathered on its sites. Each part
    /// copies the halo it needs from the other part (the largest offset), then runs blocks
    /// of cells with all the slots while the block stays in L1 (these passes stream the
    /// weight planes: a pass per slot over the whole half cost 2.5x more).
    fn fsai(&self, parts: &mut [Part], fsai: &Fsai) {
        let (planes, offsets) = fsai.weights();
        let shared = self.shared;
        let layout = self.layout;
        let total = layout.nx * layout.ny;
        let halo = offsets.iter().copied().max().unwrap_or(0);
        // rf[h]: the halo cells before the part (zeros before the grid), then its cells.
        for p in parts.iter() {
            let (base, cells) = layout.cells(p.h);
            let mut rf = write(&shared.rf[p.h]);
            rf.clear();
            rf.resize(halo + cells, 0.0);
            for (&i, &v) in p.sites.iter().zip(&p.r) {
                rf[halo + i - base] = v;
            }
        }
        self.barrier.wait();
        // The slots with the site itself first (offset 0, never clipped): it assigns, the
        // others add, so no buffer needs zeroing.
        let slots = || planes.chunks_exact(total).zip(offsets).rev();
        for p in parts.iter_mut() {
            let (base, cells) = layout.cells(p.h);
            if p.h == 1 {
                // Part 1 copies its halo from part 0 (which only reads its own buffer now:
                // no lock here may be held for writing across the phase).
                let r0 = read(&shared.rf[0]);
                let take = halo.min(r0.len() - halo);
                write(&shared.rf[1])[halo - take..halo].copy_from_slice(&r0[r0.len() - take..]);
            }
            let rf = read(&shared.rf[p.h]);
            // yf[h]: the part's cells, then the halo cells after it (zeros past the grid).
            let mut yf = write(&shared.yf[p.h]);
            yf.resize(cells + halo, 0.0);
            for (b, y) in yf[..cells].chunks_mut(BLOCK).enumerate() {
                let lo = b * BLOCK; // local cell index of the block
                let hi = lo + y.len();
                for (k, (w, &o)) in slots().enumerate() {
                    let terms = w[base + lo..base + hi]
                        .iter()
                        .zip(&rf[halo + lo - o..halo + hi - o]);
                    if k == 0 {
                        y.iter_mut().zip(terms).for_each(|(y, (w, x))| *y = w * x);
                    } else {
                        y.iter_mut().zip(terms).for_each(|(y, (w, x))| *y += w * x);
                    }
                }
            }
        }
        self.barrier.wait();
        for p in parts.iter_mut() {
            let (base, cells) = layout.cells(p.h);
            if p.h == 0 {
                let y1 = read(&shared.yf[1]);
                let take = halo.min(y1.len() - halo);
                write(&shared.yf[0])[cells..cells + take].copy_from_slice(&y1[..take]);
            }
            let yf = read(&shared.yf[p.h]);
            p.zf.resize(cells, 0.0);
            for (b, z) in p.zf.chunks_mut(BLOCK).enumerate() {
                let lo = b * BLOCK;
                for (k, (w, &o)) in slots().enumerate() {
                    // Cells j + o past the grid carry no weight.
                    let hi = (lo + z.len()).min(total.saturating_sub(base + o));
                    if hi <= lo {
                        continue;
                    }
                    let terms = w[base + lo + o..base + hi + o]
                        .iter()
                        .zip(&yf[lo + o..hi + o]);
                    if k == 0 {
                        z.iter_mut().zip(terms).for_each(|(z, (w, y))| *z = w * y);
                    } else {
                        z[..hi - lo]
                            .iter_mut()
                            .zip(terms)
                            .for_each(|(z, (w, y))| *z += w * y);
                    }
                }
            }
            for (za, &i) in p.z.iter_mut().zip(&p.sites) {
                *za = p.zf[i - base];
            }
        }
    }

    /// A product through the 2-D DCT, in three phases (see the module docs).
    /// Returns the input's sum.
    fn product(&self, red: &mut Reducer, parts: &mut [Part], product: Product) -> f64 {
        let layout = self.layout;
        let shared = self.shared;
        let nx = layout.nx;
        // Phase 1: scatter the input on the part's rows, DCT-II of the rows.
        for p in parts.iter_mut() {
            let (base, cells) = layout.cells(p.h);
            let input = match product {
                Product::Direction => &p.p,
                Product::Residual { .. } => &p.f,
                Product::Precondition => &p.r,
            };
            let mut rows = write(&shared.rows[p.h]);
            rows.clear();
            rows.resize(cells, 0.0);
            for (&i, &v) in p.sites.iter().zip(input) {
                rows[i - base] = v;
            }
            self.dct.rows(&mut rows, true, &mut p.work);
        }
        // The input's sum (for the shift) doubles as the phase's barrier.
        let sum = red.sum(self, parts, |p| match product {
            Product::Direction => sum(&p.p),
            Product::Residual { .. } => sum(&p.f),
            Product::Precondition => 0.0,
        });
        // Phase 2: the part's columns of both halves through the y-filter.
        let table = match (&self.precond_blocks, product) {
            (Some(blocks), Product::Precondition) => blocks,
            _ => self.operator,
        };
        let matrices = self.dct.column_matrices();
        for p in parts.iter_mut() {
            let (c0, width) = layout.block(p.h);
            let (r0, r1) = (read(&shared.rows[0]), read(&shared.rows[1]));
            let mut block = write(&shared.blocks[p.h]);
            if let Some(m) = matrices {
                // Matrix products read the rows in place: block = diag ⊙ (D2 X) with the
                // sum over y split at the rows' cut; D3 waits for phase 3. (The first
                // product replaces the block: no zeroing.)
                block.resize(layout.ny * width, 0.0);
                let split = layout.rows;
                let mut out = MatMut::from_row_major_slice_mut(&mut block, layout.ny, width);
                for (accum, (k0, k1), rows) in [
                    (Accum::Replace, (0, split), &r0),
                    (Accum::Add, (split, layout.ny), &r1),
                ] {
                    if k1 > k0 {
                        let x = MatRef::from_row_major_slice(rows, k1 - k0, nx);
                        let x = x.subcols(c0, width);
                        let d2 = m.forward.as_ref().subcols(k0, k1 - k0);
                        matmul(out.as_mut(), accum, d2, x, 1.0, Par::Seq);
                    }
                }
                block.iter_mut().zip(&table[p.h]).for_each(|(b, d)| *b *= d);
            } else {
                block.clear();
                for row in r0.chunks_exact(nx).chain(r1.chunks_exact(nx)) {
                    block.extend_from_slice(&row[c0..c0 + width]);
                }
                self.dct
                    .columns(&mut block, width, &table[p.h], &mut p.work);
            }
        }
        self.barrier.wait();
        // Phase 3: the part's rows back from both blocks, DCT-III, gathered on the set.
        let (s, c) = (self.scale, self.shift * sum);
        for p in parts.iter_mut() {
            let (base, cells) = layout.cells(p.h);
            let first_row = base / nx;
            let (b0, b1) = (read(&shared.blocks[0]), read(&shared.blocks[1]));
            let mut rows = write(&shared.rows[p.h]);
            if let Some(m) = matrices {
                // The part's rows of D3 times both blocks, into the rows in place.
                let lines = cells / nx;
                let d3 = m.inverse.as_ref().subrows(first_row, lines);
                let mut out = MatMut::from_row_major_slice_mut(&mut rows, lines, nx);
                for (g, block) in [(0, &b0), (1, &b1)] {
                    let (c0, width) = layout.block(g);
                    if width > 0 && lines > 0 {
                        let y = MatRef::from_row_major_slice(block, layout.ny, width);
                        let dst = out.as_mut().subcols_mut(c0, width);
                        matmul(dst, Accum::Replace, d3, y, 1.0, Par::Seq);
                    }
                }
            } else {
                let (w0, w1) = (layout.block(0).1, layout.block(1).1);
                for (k, row) in rows.chunks_exact_mut(nx).enumerate() {
                    let y = first_row + k;
                    row[..w0].copy_from_slice(&b0[y * w0..(y + 1) * w0]);
                    row[w0..].copy_from_slice(&b1[y * w1..(y + 1) * w1]);
                }
            }
            self.dct.rows(&mut rows, false, &mut p.work);
            let at = |i: usize| rows[i - base];
            match product {
                Product::Direction => {
                    let Part {
                        sites, d, p: x, q, ..
                    } = p;
                    for (((qa, &i), da), xa) in
                        q.iter_mut().zip(sites.iter()).zip(d.iter()).zip(x.iter())
                    {
                        *qa = s * (at(i) - c) + da * xa;
                    }
                }
                Product::Residual { offset } => {
                    let Part {
                        sites, d, f, r, b, ..
                    } = p;
                    for ((((ra, &i), da), fa), ba) in r
                        .iter_mut()
                        .zip(sites.iter())
                        .zip(d.iter())
                        .zip(f.iter())
                        .zip(b.iter())
                    {
                        let y = s * (at(i) - c) + da * fa;
                        *ra = y + (offset - ba);
                    }
                }
                Product::Precondition => {
                    for (za, &i) in p.z.iter_mut().zip(&p.sites) {
                        *za = at(i);
                    }
                }
            }
        }
        sum
    }
}

fn read<T>(lock: &RwLock<T>) -> std::sync::RwLockReadGuard<'_, T> {
    lock.read().unwrap_or_else(|e| e.into_inner())
}

fn write<T>(lock: &RwLock<T>) -> std::sync::RwLockWriteGuard<'_, T> {
    lock.write().unwrap_or_else(|e| e.into_inner())
}

//! Dense backend: the assembled matrix `C` and an LDLᵀ factor (faer) of
//! `C_SS + diag(1/k_z)` on the attached set, kept across normal solves. When a few sites
//! leave or join, the factor is updated (faer's row/column deletion; an appended row costs
//! one triangular solve) instead of refactorised; the factor then preconditions projected
//! CG, which converges in one or two iterations.
//!
//! The tangential system has no factor: its compliances `1/k_x = exp(u_z/u0)/c_x` change on
//! every site at every normal re-equilibration and dominate `C`'s diagonal, so Jacobi CG
//! from the last response (the spectral backend's path) costs less than keeping a second
//! factor up to date (docs/performance.md, "The cost of one event").

use super::pcg::Effort;
use super::set::{SetProblem, SetSolve};
use super::spectral::SpectralCore;
use super::system::{ExactInverse, Preconditioner};
use crate::error::{Error, Result};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt;
use faer::linalg::triangular_solve::solve_unit_lower_triangular_in_place;
use faer::{Mat, Par};
use std::sync::Mutex;

/// Refactorise instead of updating when more than `n / UPDATE_FRACTION` sites change:
/// an update costs `O(n²)` per site, a factorisation `O(n³/3)`.
const UPDATE_FRACTION: usize = 8;
/// Refactorise when the stale factor needed more PCG iterations than this last time.
const STALE_ITERATIONS: usize = 6;
/// Refactorise when a kept site's compliance changed by more than this fraction.
const DIAG_DRIFT: f64 = 0.05;

/// Everything a [`FactorCache`] holds, for checkpoints.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub(crate) struct FactorState {
    order: Vec<usize>,
    diag: Vec<f64>,
    /// `L` (unit diagonal implied) and `D` on the diagonal, row by row.
    lower: Vec<f64>,
    last_iterations: usize,
    factorisations: usize,
    updates: usize,
}

/// An LDLᵀ factor of `C_SS + diag(d)` for the sites `order` (in factor order).
#[derive(Debug, Clone)]
pub(crate) struct FactorCache {
    order: Vec<usize>,
    diag: Vec<f64>,
    ld: Mat<f64>,
    last_iterations: usize,
    /// Factorisations and updates performed (diagnostics).
    pub(crate) factorisations: usize,
    pub(crate) updates: usize,
}

impl Default for FactorCache {
    fn default() -> Self {
        Self {
            order: Vec::new(),
            diag: Vec::new(),
            ld: Mat::new(),
            last_iterations: 0,
            factorisations: 0,
            updates: 0,
        }
    }
}

impl FactorCache {
    /// Brings the factor to the sites `set` with compliances `diag` (both in `set` order)
    /// and returns the factor's site order (a permutation of `set`).
    fn prepare(&mut self, c: &Mat<f64>, set: &[usize], diag: &[f64]) -> Result<()> {
        let n_sites = c.nrows();
        let mut in_new = vec![usize::MAX; n_sites];
        for (a, &i) in set.iter().enumerate() {
            in_new[i] = a;
        }
        let mut in_old = vec![false; n_sites];
        let mut removed = Vec::new();
        for (pos, &i) in self.order.iter().enumerate() {
            in_old[i] = true;
            if in_new[i] == usize::MAX {
                removed.push(pos);
            }
        }
        let added: Vec<usize> = set.iter().copied().filter(|&i| !in_old[i]).collect();
        let changes = removed.len() + added.len();
        let kept = self.order.len() - removed.len();
        if self.order.is_empty()
            || self.last_iterations > STALE_ITERATIONS
            || changes * UPDATE_FRACTION > set.len()
            || kept == 0
            || self.diag_drift(set, diag, &in_new) > DIAG_DRIFT
        {
            return self.factorise(c, set, diag);
        }
        if !removed.is_empty() {
            let n = self.order.len();
            let mut idx = removed.clone();
            let mut mem = MemBuffer::new(
                ldlt::update::delete_rows_and_cols_clobber_scratch::<f64>(n, idx.len()),
            );
            ldlt::update::delete_rows_and_cols_clobber(
                self.ld.as_mut(),
                &mut idx,
                Par::Seq,
                MemStack::new(&mut mem),
            );
            for &pos in removed.iter().rev() {
                self.order.remove(pos);
                self.diag.remove(pos);
            }
            let m = self.order.len();
            self.ld.truncate(m, m);
            self.updates += removed.len();
        }
        for &i in &added {
            let a = in_new[i];
            if !self.append(c, i, diag[a]) {
                return self.factorise(c, set, diag);
            }
            self.updates += 1;
        }
        // Kept sites keep their old compliance in the factor: it is a preconditioner.
        Ok(())
    }

    /// Appends site `i`: `l = D⁻¹ L⁻¹ a`, `d = α - yᵀ D⁻¹ y` with `y = L⁻¹ a`.
    /// Returns false when the new pivot is not positive (then refactorise).
    fn append(&mut self, c: &Mat<f64>, i: usize, d_i: f64) -> bool {
        let n = self.order.len();
        let col = c.col_as_slice(i);
        let mut y = Mat::<f64>::from_fn(n, 1, |a, _| col[self.order[a]]);
        solve_unit_lower_triangular_in_place(self.ld.as_ref(), y.as_mut(), Par::Seq);
        let mut pivot = c[(i, i)] + d_i;
        for a in 0..n {
            pivot -= y[(a, 0)] * y[(a, 0)] / self.ld[(a, a)];
        }
        if !(pivot > 0.0 && pivot.is_finite()) {
            return false;
        }
        self.ld.resize_with(n + 1, n + 1, |_, _| 0.0);
        for a in 0..n {
            self.ld[(n, a)] = y[(a, 0)] / self.ld[(a, a)];
            self.ld[(a, n)] = 0.0;
        }
        self.ld[(n, n)] = pivot;
        self.order.push(i);
        self.diag.push(d_i);
        true
    }

    /// Whether bringing the factor to `set` would take a full factorisation.
    pub(crate) fn needs_refactor(&self, set: &[usize], n_sites: usize) -> bool {
        if self.order.is_empty() || self.last_iterations > STALE_ITERATIONS {
            return true;
        }
        let mut in_new = vec![false; n_sites];
        set.iter().for_each(|&i| in_new[i] = true);
        let mut in_old = vec![false; n_sites];
        let removed = self
            .order
            .iter()
            .filter(|&&i| {
                in_old[i] = true;
                !in_new[i]
            })
            .count();
        let added = set.iter().filter(|&&i| !in_old[i]).count();
        (removed + added) * UPDATE_FRACTION > set.len()
    }

    /// Largest relative change of a kept site's compliance since the factorisation.
    fn diag_drift(&self, set: &[usize], diag: &[f64], in_new: &[usize]) -> f64 {
        let _ = set;
        self.order
            .iter()
            .zip(&self.diag)
            .filter(|(i, _)| in_new[**i] != usize::MAX)
            .fold(0.0f64, |m, (i, old)| {
                let new = diag[in_new[*i]];
                m.max((new - old).abs() / new.abs().max(old.abs()).max(f64::MIN_POSITIVE))
            })
    }

    /// Factorises `C_SS + diag(d)` (in `set` order).
    fn factorise(&mut self, c: &Mat<f64>, set: &[usize], diag: &[f64]) -> Result<()> {
        let n = set.len();
        self.order = set.to_vec();
        self.diag = diag.to_vec();
        self.ld = Mat::<f64>::zeros(n, n);
        for (b, &j) in set.iter().enumerate() {
            let src = c.col_as_slice(j);
            let dst = self.ld.col_as_slice_mut(b);
            for (d, &i) in dst.iter_mut().zip(set) {
                *d = src[i];
            }
            dst[b] += diag[b];
        }
        let mut mem = MemBuffer::new(ldlt::factor::cholesky_in_place_scratch::<f64>(
            n,
            Par::Seq,
            Default::default(),
        ));
        let result = ldlt::factor::cholesky_in_place(
            self.ld.as_mut(),
            Default::default(),
            Par::Seq,
            MemStack::new(&mut mem),
            Default::default(),
        );
        self.factorisations += 1;
        self.last_iterations = 0;
        let bad_pivot = (0..n).find(|&a| !(self.ld[(a, a)] > 0.0 && self.ld[(a, a)].is_finite()));
        if let Err(e) = result {
            self.order.clear();
            return Err(factorization_failed(n, e));
        }
        if let Some(a) = bad_pivot {
            let pivot = self.ld[(a, a)];
            self.order.clear();
            return Err(Error::Factorization {
                n,
                reason: format!(
                    "pivot {a} is {pivot:e}: the matrix is not numerically positive definite"
                ),
                source: None,
            });
        }
        Ok(())
    }

    /// The factor's full state, the lower triangle packed row by row.
    pub(crate) fn state(&self) -> FactorState {
        let m = self.order.len();
        let mut lower = Vec::with_capacity(m * (m + 1) / 2);
        for a in 0..m {
            lower.extend((0..=a).map(|b| self.ld[(a, b)]));
        }
        FactorState {
            order: self.order.clone(),
            diag: self.diag.clone(),
            lower,
            last_iterations: self.last_iterations,
            factorisations: self.factorisations,
            updates: self.updates,
        }
    }

    /// Restores a state taken by [`FactorCache::state`] on a grid of `n_sites` sites. The
    /// upper triangle is never read (faer's LDLᵀ kernels use the lower one only).
    pub(crate) fn restore(&mut self, state: FactorState, n_sites: usize) -> Result<()> {
        let m = state.order.len();
        let bad = |reason: String| Err(Error::InvalidCheckpoint { reason });
        if state.diag.len() != m || state.lower.len() != m * (m + 1) / 2 {
            return bad(format!(
                "a dense factor of {m} sites needs {m} compliances and {} entries, found {} \
                 and {}",
                m * (m + 1) / 2,
                state.diag.len(),
                state.lower.len()
            ));
        }
        let mut seen = vec![false; n_sites];
        for &i in &state.order {
            if i >= n_sites || std::mem::replace(&mut seen[i], true) {
                return bad(format!(
                    "the dense factor names site {i} twice or beyond the grid's {n_sites}"
                ));
            }
        }
        if !state.lower.iter().chain(&state.diag).all(|x| x.is_finite()) {
            return bad("the dense factor holds a non-finite entry".into());
        }
        let mut ld = Mat::<f64>::zeros(m, m);
        let mut k = 0;
        for a in 0..m {
            for b in 0..=a {
                ld[(a, b)] = state.lower[k];
                k += 1;
            }
        }
        *self = FactorCache {
            order: state.order,
            diag: state.diag,
            ld,
            last_iterations: state.last_iterations,
            factorisations: state.factorisations,
            updates: state.updates,
        };
        Ok(())
    }

    /// Forgets the factor.
    pub(crate) fn clear(&mut self) {
        self.order.clear();
        self.diag.clear();
        self.ld = Mat::new();
    }
}

/// The dense matrix `C_s` (m/Pa) of every site, column-major, and the factor of the
/// normal system.
#[derive(Debug)]
pub(crate) struct DenseCore {
    pub(crate) c: Mat<f64>,
    pub(crate) normal: FactorCache,
    /// The DCT product (one part), and the spectral iteration that explores a cold
    /// attached set before the factor is built.
    pub(crate) spectral: SpectralCore,
}

impl DenseCore {
    pub(crate) fn new(c: Mat<f64>, spectral: SpectralCore) -> Self {
        Self {
            c,
            spectral,
            normal: FactorCache::default(),
        }
    }

    /// Solves the normal `problem` preconditioned by the factor, brought up to date for the
    /// set first. The product goes through the DCT operator (`O(N log N)`, in cache) rather
    /// than the assembled `n x n` submatrix (`O(n²)`, memory bound): the factor is only the
    /// preconditioner. A stale factor gets 50 iterations, then is refactorised.
    pub(crate) fn solve(
        &mut self,
        problem: SetProblem<'_>,
        f: Vec<f64>,
        effort: Effort,
    ) -> Result<SetSolve> {
        let first = Effort {
            max_iterations: effort.max_iterations.min(50),
            ..effort
        };
        let mut solved = self.solve_once(problem, f, first)?;
        if !solved.outcome.converged {
            self.normal.clear();
            let spent = solved.outcome.iterations;
            solved = self.solve_once(problem, solved.f, effort)?;
            solved.outcome.iterations += spent;
        }
        Ok(solved)
    }

    fn solve_once(
        &mut self,
        problem: SetProblem<'_>,
        f: Vec<f64>,
        effort: Effort,
    ) -> Result<SetSolve> {
        let DenseCore {
            c,
            normal: cache,
            spectral,
        } = self;
        cache.prepare(c, problem.set, problem.d)?;
        // Map from the factor order to positions in `set`.
        let mut pos = vec![usize::MAX; c.nrows()];
        for (a, &i) in problem.set.iter().enumerate() {
            pos[i] = a;
        }
        let perm: Vec<usize> = cache.order.iter().map(|&i| pos[i]).collect();
        let factor = FactorSolve {
            cache,
            work: Mutex::new(Mat::zeros(perm.len(), 1)),
            perm,
        };
        let solved = spectral.solve_with(problem, Preconditioner::Factor(&factor), f, effort)?;
        // How many iterations the factor needed (a stale factor is replaced).
        cache.last_iterations = solved.outcome.iterations;
        Ok(solved)
    }
}

/// `z = (L D Lᵀ)⁻¹ r` with the cached factor, in the factor's site order.
struct FactorSolve<'a> {
    cache: &'a FactorCache,
    /// Positions in the set of the factor's sites.
    perm: Vec<usize>,
    work: Mutex<Mat<f64>>,
}

impl ExactInverse for FactorSolve<'_> {
    fn solve(&self, r: &[f64], z: &mut [f64]) {
        let mut work = crate::lock::lock(&self.work);
        for (a, &p) in self.perm.iter().enumerate() {
            work[(a, 0)] = r[p];
        }
        let ld = self.cache.ld.as_ref();
        ldlt::solve::solve_in_place_with_conj(
            ld,
            ld.diagonal(),
            faer::Conj::No,
            work.as_mut(),
            Par::Seq,
            MemStack::new(&mut []),
        );
        for (a, &p) in self.perm.iter().enumerate() {
            z[p] = work[(a, 0)];
        }
    }
}

/// faer's failure of the LDLᵀ factorisation of the `n x n` matrix, said in words (faer's
/// own text is a Rust debug dump, `ZeroPivot { index: 0 }`).
fn factorization_failed(n: usize, e: ldlt::factor::LdltError) -> Error {
    let ldlt::factor::LdltError::ZeroPivot { index } = e;
    Error::Factorization {
        n,
        reason: format!(
            "pivot {index} is zero: the matrix is singular to working precision (look for \
             extreme values among the scene's lengths and spring constants)"
        ),
        source: None,
    }
}

#[cfg(test)]
mod message_tests {
    use super::*;

    /// faer's error text is its Debug dump (`ZeroPivot { index: 0 }`): the message says
    /// it in words, once (no `caused by:` line repeating faer's text).
    #[test]
    fn a_zero_pivot_is_said_in_words() {
        let e = factorization_failed(98, ldlt::factor::LdltError::ZeroPivot { index: 0 });
        let text = &e.to_string();
        // No cause a report would print below it (none, or one its message already ends).
        let cause = std::error::Error::source(&e).map(|c| c.to_string());
        assert!(
            cause.as_ref().is_none_or(|c| text.ends_with(c)),
            "{text}: {cause:?}"
        );
        assert!(
            text.contains("98 x 98") && text.contains("pivot 0 is zero"),
            "{text}"
        );
        assert!(!text.contains("ZeroPivot") && !text.contains('{'), "{text}");
    }
}

//! The Galerkin influence operator of the grid (MODEL.md section 2) and the transfer of
//! bottom tractions to a plane at height `z`.
//!
//! `Ĝ_ij = (1/ΔA²) ∫_cell i ∫_cell j G(x,ξ;y,η;0,0) dA dA'` is diagonal in the 2-D DCT-II
//! basis of the grid. With `θ = p'π/(2Nx)` the aliases of the mode `p'` are the
//! wavenumbers `k = 2|θ + qπ|/Δx`, `q ∈ ℤ`, with cell-averaging weights
//! `S² = sin²θ/(θ + qπ)²` (summing to 1), and
//!
//! `Ĝ_ij = Σ_{p',m'} λ(p',m') cos(p'π(ix_i+½)/Nx) cos(p'π(ix_j+½)/Nx) cos(m'π(iy_i+½)/Ny) cos(m'π(iy_j+½)/Ny)`,
//! `λ(p',m') = (4/(Lx Ly)) Σ_{aliases} w_p w_m S_p² S_m² coth(κ Lz)/κ` (m⁻¹),
//!
//! `κ² = k_p² + k_m²`, `w_0 = ½`, and `Lz/3` in place of `coth(κLz)/κ` at `κ = 0`.
//! The alias sum is truncated to `|q|, |r| ≤ Q` with the leading tail of both strips added
//! in closed form (Euler–Maclaurin on `Σ 1/|θ + qπ|³`); `Q` doubles until two successive
//! sums agree to the tolerance (see `docs/accuracy.md`).

use crate::error::{check_slice, check_tolerance, Error, Result};
use crate::geometry::Grid;
use rustdct::num_complex::Complex;
use rustdct::rustfft::{Fft, FftPlanner};
use rustdct::{DctPlanner, TransformType2And3};
use std::cell::RefCell;
use std::f64::consts::PI;
use std::sync::Arc;

/// Largest alias box half-width `Q` before the alias sum reports [`Error::NotConverged`].
const MAX_ALIAS: usize = 512;

/// Largest grid for which [`InfluencePlan::dense`] assembles a matrix.
pub const DENSE_LIMIT: usize = 20_000;

/// Cell-averaging weights and wavenumbers of the aliases of one 1-D DCT mode.
struct Aliases {
    theta: f64,
    /// `(weight w S², k)` for q = -Q..=Q, skipping zero weights.
    terms: Vec<(f64, f64)>,
    /// Sum of the weights in the box (½ for mode 0, whose only alias has `w_0 = ½`).
    weight: f64,
}

fn aliases(mode: usize, n: usize, cell: f64, q_max: usize) -> Aliases {
    let theta = mode as f64 * PI / (2.0 * n as f64);
    let mut terms = Vec::with_capacity(2 * q_max + 1);
    if mode == 0 {
        // Only the q = 0 alias (p = 0) survives: sinc(qπ) = 0 otherwise; w_0 = ½.
        terms.push((0.5, 0.0));
        return Aliases {
            theta,
            terms,
            weight: 0.5,
        };
    }
    let s2 = theta.sin().powi(2);
    let mut weight = 0.0;
    for q in -(q_max as i64)..=(q_max as i64) {
        let t = theta + q as f64 * PI;
        let w = s2 / (t * t);
        weight += w;
        terms.push((w, 2.0 * t.abs() / cell));
    }
    Aliases {
        theta,
        terms,
        weight,
    }
}

/// `Σ_{|q|>Q} 1/|θ + qπ|³` by the Euler–Maclaurin midpoint rule (error O(Q⁻⁷)).
fn tail_cubed(theta: f64, q: usize) -> f64 {
    let mut total = 0.0;
    for a in [theta / PI, -theta / PI] {
        let b = q as f64 + 0.5 + a;
        total += 1.0 / (2.0 * b * b) + 1.0 / (8.0 * b.powi(4)) - 7.0 / (96.0 * b.powi(6));
    }
    total / PI.powi(3)
}

/// `coth(κ Lz)/κ`, the depth-summed kernel of the bottom face; `Lz/3` at `κ = 0`.
fn depth_kernel(kappa: f64, lz: f64) -> f64 {
    if kappa == 0.0 {
        lz / 3.0
    } else {
        1.0 / (kappa * (kappa * lz).tanh())
    }
}

/// The alias sum of one eigenvalue with box `Q`, tail-corrected.
fn lambda_box(grid: &Grid, p: usize, m: usize, q: usize) -> f64 {
    let b = grid.block();
    let ax = aliases(p, grid.nx(), grid.dx(), q);
    let ay = aliases(m, grid.ny(), grid.dy(), q);
    let lz = b.lz();
    let mut sum = 0.0;
    for &(wx, kx) in &ax.terms {
        for &(wy, ky) in &ay.terms {
            sum += wx * wy * depth_kernel((kx * kx + ky * ky).sqrt(), lz);
        }
    }
    // Strips outside the box: κ ≈ k along the long side, coth = 1 there.
    if p != 0 {
        sum += ay.weight * ax.theta.sin().powi(2) * grid.dx() / 2.0 * tail_cubed(ax.theta, q);
    }
    if m != 0 {
        sum += ax.weight * ay.theta.sin().powi(2) * grid.dy() / 2.0 * tail_cubed(ay.theta, q);
    }
    4.0 / (b.lx() * b.ly()) * sum
}

/// One eigenvalue with its error estimate, `Q` doubled until converged.
fn lambda_adaptive(grid: &Grid, p: usize, m: usize, tol: f64) -> Result<(f64, f64)> {
    if p == 0 && m == 0 {
        let b = grid.block();
        return Ok((b.lz() / (3.0 * b.lx() * b.ly()), 0.0));
    }
    let mut q = 2;
    let mut previous = lambda_box(grid, p, m, 1);
    loop {
        let value = lambda_box(grid, p, m, q);
        // Successive errors shrink ~14x per doubling: |Δ|/4 over-estimates the error.
        let error = (value - previous).abs() / 4.0;
        if error <= tol * value {
            return Ok((value, error));
        }
        if q >= MAX_ALIAS {
            return Err(Error::NotConverged {
                what: "alias sum of the influence operator",
                value,
                error,
                tolerance: tol,
                terms: ((2 * q + 1) * (2 * q + 1)) as u64,
            });
        }
        previous = value;
        q *= 2;
    }
}

/// Builder of an [`InfluencePlan`].
#[derive(Debug, Clone)]
#[must_use]
pub struct InfluencePlanBuilder {
    grid: Grid,
    tolerance: f64,
}

impl InfluencePlanBuilder {
    /// Relative tolerance on every eigenvalue's alias sum (default `1e-6`).
    pub fn tolerance(mut self, tolerance: f64) -> Self {
        self.tolerance = tolerance;
        self
    }

    /// Computes the eigenvalues and plans the DCTs.
    pub fn build(self) -> Result<InfluencePlan> {
        let tol = check_tolerance(self.tolerance)?;
        let grid = self.grid;
        let (nx, ny) = (grid.nx(), grid.ny());
        let mut lambda = vec![0.0; grid.len()];
        let mut max_rel_error: f64 = 0.0;
        // Modes with the same (p', m') appear once: O(N) alias sums.
        for m in 0..ny {
            for p in 0..nx {
                let (value, error) = lambda_adaptive(&grid, p, m, tol)?;
                lambda[m * nx + p] = value;
                max_rel_error = max_rel_error.max(error / value);
            }
        }
        Ok(InfluencePlan::from_eigenvalues(
            grid,
            tol,
            lambda,
            max_rel_error,
        ))
    }
}

/// The Galerkin influence operator `Ĝ` of a grid, planned once and reused.
///
/// `Ĝ` maps cell-constant tractions on the bottom face (Pa) to cell-averaged
/// displacements times `M/ΔA`: the displacement is `u = ⟨u⟩ + (ΔA/M) Ĝ φ`; its entries
/// are in m⁻¹. It is applied matrix-free through the 2-D DCT in `O(N log N)`
/// ([`InfluencePlan::apply`]) or assembled densely for small grids ([`InfluencePlan::dense`]).
#[derive(Clone)]
pub struct InfluencePlan {
    grid: Grid,
    tolerance: f64,
    lambda: Vec<f64>,
    /// λ scaled for unnormalised DCT-III: ×2 for p' = 0 and for m' = 0.
    scaled: Vec<f64>,
    max_rel_error: f64,
    dct: Arc<Dct2d>,
}

impl std::fmt::Debug for InfluencePlan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("InfluencePlan")
            .field("grid", &self.grid)
            .field("tolerance", &self.tolerance)
            .field("max_rel_error", &self.max_rel_error)
            .finish_non_exhaustive()
    }
}

/// Below this many rows the y-axis transforms are done as a small dense product over
/// whole rows (contiguous, vectorised) instead of strided length-`Ny` DCTs.
const DIRECT_COLUMNS: usize = 16;

/// Up to this many rows (above [`DIRECT_COLUMNS`]) the y-axis transforms are dense
/// `Ny x Ny` matrix products over the whole `Ny x Nx` block, through faer's matmul
/// (contiguous rows, SIMD chosen at run time) instead of strided FFTs of the columns.
/// Measured at 200 x 50: the y-passes (DCT-II and DCT-III) took 70.7 µs as paired FFTs,
/// 31.6 µs as two products; the whole filter went from 144 µs to 105 µs.
const MATMUL_COLUMNS: usize = 64;

/// The y-axis DCT-II and DCT-III as dense matrices (rustdct's unnormalised conventions).
pub(crate) struct ColumnMatrices {
    /// `D2[m][j] = cos(π m (2j+1) / (2Ny))`.
    pub(crate) forward: faer::Mat<f64>,
    /// `D3[j][m] = D2[m][j]`, and `1/2` for `m = 0`.
    pub(crate) inverse: faer::Mat<f64>,
}

impl ColumnMatrices {
    fn new(ny: usize) -> Self {
        let t = cosine_table(ny);
        Self {
            forward: faer::Mat::from_fn(ny, ny, |m, j| t[m * ny + j]),
            inverse: faer::Mat::from_fn(ny, ny, |j, m| if m == 0 { 0.5 } else { t[m * ny + j] }),
        }
    }

    /// `block ← D3 (diag ⊙ (D2 block))`, `block` and `diag` row-major `Ny x width`;
    /// `tmp` holds at least `Ny width` values.
    fn filter(&self, block: &mut [f64], width: usize, diag: &[f64], tmp: &mut [f64]) {
        use faer::linalg::matmul::matmul;
        use faer::{Accum, MatMut, MatRef, Par};
        let ny = self.forward.nrows();
        let tmp = &mut tmp[..ny * width];
        matmul(
            MatMut::from_row_major_slice_mut(tmp, ny, width),
            Accum::Replace,
            self.forward.as_ref(),
            MatRef::from_row_major_slice(block, ny, width),
            1.0,
            Par::Seq,
        );
        tmp.iter_mut().zip(diag).for_each(|(t, d)| *t *= d);
        matmul(
            MatMut::from_row_major_slice_mut(block, ny, width),
            Accum::Replace,
            self.inverse.as_ref(),
            MatRef::from_row_major_slice(tmp, ny, width),
            1.0,
            Par::Seq,
        );
    }
}

/// Planned 1-D DCTs of both axes.
pub(crate) struct Dct2d {
    nx: usize,
    ny: usize,
    x: Arc<dyn TransformType2And3<f64>>,
    y: Arc<dyn TransformType2And3<f64>>,
    scratch_len: usize,
    /// `cos(π m (2j+1) / (2Ny))`, row `m`, when `1 < Ny <= DIRECT_COLUMNS`.
    direct: Option<Vec<f64>>,
    /// Both lengths even and no direct y-product: the transforms of both axes run as
    /// batched complex FFTs of half as many lines ([`PairDct`]).
    pairs: Option<(PairDct, PairDct)>,
    /// `DIRECT_COLUMNS < Ny <= MATMUL_COLUMNS`: the y-transforms as matrix products.
    columns_matmul: Option<ColumnMatrices>,
}

/// Complex buffers of [`PairDct`]: the lines' data and the FFT's scratch.
type PairBuffers = (Vec<Complex<f64>>, Vec<Complex<f64>>);

thread_local! {
    /// Complex scratch of [`PairDct`] (one per thread: the plan is shared between clones).
    static PAIR_SCRATCH: RefCell<PairBuffers> =
        const { RefCell::new((Vec::new(), Vec::new())) };
}

/// Unnormalised DCT-II / DCT-III of even length `n` on two real lines at once, through
/// one complex FFT of length `n` (Makhoul's reordering; line `a` in the real part, line
/// `b` in the imaginary part). Why: rustdct runs a full complex FFT per real line, so
/// pairing halves the FFT work, and one batched FFT call over all pairs vectorises
/// better than one call per line (the 2-D DCT is the inner cost of the spectral solver).
struct PairDct {
    n: usize,
    forward: Arc<dyn Fft<f64>>,
    inverse: Arc<dyn Fft<f64>>,
    /// `cos(πk/(2n))/2` and `sin(πk/(2n))/2`: the twiddle `exp(-iπk/(2n))` split into
    /// real factors, so that the pre- and post-processing only forms the real parts it
    /// keeps (a third of the flops of complex products; these passes were 19 % of a run).
    half_cos: Vec<f64>,
    half_sin: Vec<f64>,
}

impl PairDct {
    fn new(planner: &mut FftPlanner<f64>, n: usize) -> Self {
        let angle = |k: usize| PI * k as f64 / (2.0 * n as f64);
        Self {
            n,
            forward: planner.plan_fft_forward(n),
            inverse: planner.plan_fft_inverse(n),
            half_cos: (0..n).map(|k| 0.5 * angle(k).cos()).collect(),
            half_sin: (0..n).map(|k| 0.5 * angle(k).sin()).collect(),
        }
    }

    fn scratch_len(&self) -> usize {
        self.forward
            .get_inplace_scratch_len()
            .max(self.inverse.get_inplace_scratch_len())
    }

    /// Runs `body` on line pair `c` (lines `2c` and `2c+1`, element `j` of line `l` at
    /// `data[l * line + j * step]`) as two contiguous slices: the lines themselves when
    /// `step = 1` (the rows), else copies written back afterwards.
    fn with_lines(
        &self,
        data: &mut [f64],
        line: usize,
        step: usize,
        c: usize,
        copies: &mut Vec<f64>,
        body: impl FnOnce(&mut [f64], &mut [f64]),
    ) {
        let n = self.n;
        if step == 1 {
            let (a, b) = data[2 * c * line..].split_at_mut(line);
            body(&mut a[..n], &mut b[..n]);
            return;
        }
        copies.resize(2 * n, 0.0);
        let (a, b) = copies.split_at_mut(n);
        let (sa, sb) = (2 * c * line, (2 * c + 1) * line);
        for j in 0..n {
            a[j] = data[sa + j * step];
            b[j] = data[sb + j * step];
        }
        body(a, b);
        for j in 0..n {
            data[sa + j * step] = a[j];
            data[sb + j * step] = b[j];
        }
    }

    /// DCT-II of every line (`lines` even) in place.
    fn dct2(
        &self,
        data: &mut [f64],
        lines: usize,
        line: usize,
        step: usize,
        z: &mut Vec<Complex<f64>>,
        scratch: &mut Vec<Complex<f64>>,
    ) {
        let n = self.n;
        z.resize(lines / 2 * n, Complex::new(0.0, 0.0));
        scratch.resize(self.scratch_len(), Complex::new(0.0, 0.0));
        let mut copies = Vec::new();
        for (c, zc) in z.chunks_exact_mut(n).enumerate() {
            // Makhoul's order: z[j] = (a[2j], b[2j]), z[n-1-j] = (a[2j+1], b[2j+1]).
            self.with_lines(data, line, step, c, &mut copies, |a, b| {
                let (lo, hi) = zc.split_at_mut(n / 2);
                let pairs = a.chunks_exact(2).zip(b.chunks_exact(2));
                for ((zl, zh), (pa, pb)) in lo.iter_mut().zip(hi.iter_mut().rev()).zip(pairs) {
                    *zl = Complex::new(pa[0], pb[0]);
                    *zh = Complex::new(pa[1], pb[1]);
                }
            });
        }
        self.forward.process_with_scratch(z, scratch);
        for (c, zc) in z.chunks_exact(n).enumerate() {
            // Z(k) = V_a(k) + i V_b(k) with V_a, V_b Hermitian: with Z(k) = X + iY and
            // Z(n-k) = P + iQ, V_a(k) = (X+P + i(Y-Q))/2 and V_b(k) = (Y+Q - i(X-P))/2;
            // the DCT-II is Re(exp(-iπk/(2n)) V(k)). At k = 0: V_a = X, V_b = Y.
            self.with_lines(data, line, step, c, &mut copies, |a, b| {
                a[0] = zc[0].re;
                b[0] = zc[0].im;
                let twiddles = self.half_cos[1..].iter().zip(&self.half_sin[1..]);
                let outputs = a[1..].iter_mut().zip(b[1..].iter_mut());
                let inputs = zc[1..].iter().zip(zc[1..].iter().rev());
                for (((z, w), (oa, ob)), (hc, hs)) in inputs.zip(outputs).zip(twiddles) {
                    *oa = hc * (z.re + w.re) + hs * (z.im - w.im);
                    *ob = hc * (z.im + w.im) + hs * (w.re - z.re);
                }
            });
        }
    }

    /// DCT-III of every line (`lines` even) in place.
    fn dct3(
        &self,
        data: &mut [f64],
        lines: usize,
        line: usize,
        step: usize,
        z: &mut Vec<Complex<f64>>,
        scratch: &mut Vec<Complex<f64>>,
    ) {
        let n = self.n;
        z.resize(lines / 2 * n, Complex::new(0.0, 0.0));
        scratch.resize(self.scratch_len(), Complex::new(0.0, 0.0));
        let mut copies = Vec::new();
        for (c, zc) in z.chunks_exact_mut(n).enumerate() {
            // W(k) = (X(k) - i X(n-k)) exp(iπk/(2n)) / 2 per line (X(n) = 0); the inverse
            // FFT of W_a + i W_b is v_a + i v_b (both real). In real parts, with A = X_a(k),
            // Ā = X_a(n-k) and B, B̄ alike: Re = c(A + B̄) + s(Ā - B), Im = s(A + B̄) + c(B - Ā).
            self.with_lines(data, line, step, c, &mut copies, |a, b| {
                zc[0] = Complex::new(self.half_cos[0] * a[0], self.half_cos[0] * b[0]);
                let twiddles = self.half_cos[1..].iter().zip(&self.half_sin[1..]);
                let ahead = a[1..].iter().zip(&b[1..]);
                let behind = a[1..].iter().rev().zip(b[1..].iter().rev());
                for ((zk, ((xa, xb), (ya, yb))), (hc, hs)) in
                    zc[1..].iter_mut().zip(ahead.zip(behind)).zip(twiddles)
                {
                    *zk = Complex::new(
                        hc * (xa + yb) + hs * (ya - xb),
                        hs * (xa + yb) + hc * (xb - ya),
                    );
                }
            });
        }
        self.inverse.process_with_scratch(z, scratch);
        for (c, zc) in z.chunks_exact(n).enumerate() {
            self.with_lines(data, line, step, c, &mut copies, |a, b| {
                let (lo, hi) = zc.split_at(n / 2);
                let pairs = a.chunks_exact_mut(2).zip(b.chunks_exact_mut(2));
                for ((zl, zh), (pa, pb)) in lo.iter().zip(hi.iter().rev()).zip(pairs) {
                    pa[0] = zl.re;
                    pb[0] = zl.im;
                    pa[1] = zh.re;
                    pb[1] = zh.im;
                }
            });
        }
    }
}

impl Dct2d {
    pub(crate) fn new(nx: usize, ny: usize) -> Self {
        Self::with_pairs(nx, ny, true)
    }

    /// `pairs = false` forces the rustdct path (tests compare both).
    fn with_pairs(nx: usize, ny: usize, pairs: bool) -> Self {
        Self::with_options(nx, ny, pairs, true)
    }

    /// `matmul = false` forces the FFT y-transforms (tests compare both).
    fn with_options(nx: usize, ny: usize, pairs: bool, matmul: bool) -> Self {
        let mut planner = DctPlanner::new();
        let x = planner.plan_dct2(nx);
        let y = planner.plan_dct2(ny);
        let scratch_len = x.get_scratch_len().max(y.get_scratch_len());
        let direct = (ny > 1 && ny <= DIRECT_COLUMNS).then(|| cosine_table(ny));
        let pairs = (pairs && direct.is_none() && nx % 2 == 0 && ny % 2 == 0 && nx >= 4 && ny >= 4)
            .then(|| {
                let mut fft = FftPlanner::new();
                (PairDct::new(&mut fft, nx), PairDct::new(&mut fft, ny))
            });
        let columns_matmul = (matmul && ny > DIRECT_COLUMNS && ny <= MATMUL_COLUMNS)
            .then(|| ColumnMatrices::new(ny));
        Self {
            nx,
            ny,
            x,
            y,
            scratch_len,
            direct,
            pairs,
            columns_matmul,
        }
    }

    /// In place: forward (unnormalised DCT-II) on both axes, multiply by `diag`, then
    /// unnormalised DCT-III on both axes. `work` is scratch (resized as needed), so that
    /// iterative solvers do not allocate per product.
    pub(crate) fn filter(&self, buf: &mut [f64], diag: &[f64], work: &mut Vec<f64>) {
        self.rows(buf, true, work);
        self.columns(buf, self.nx, diag, work);
        self.rows(buf, false, work);
    }

    /// The y-transforms as matrices, when they run as matrix products.
    pub(crate) fn column_matrices(&self) -> Option<&ColumnMatrices> {
        self.columns_matmul.as_ref()
    }

    /// Whether [`Dct2d::rows`] and [`Dct2d::columns`] pair their lines (the paired FFT
    /// path: both lengths even).
    pub(crate) fn pairs_rows(&self) -> bool {
        self.pairs.is_some()
    }

    /// Unnormalised DCT-II (`forward`) or DCT-III of every row of `rows`, a whole number
    /// of rows of the grid, in place (on the paired path, an odd last row runs alone:
    /// rounding then depends on where a block of rows starts, fixed by the caller).
    pub(crate) fn rows(&self, rows: &mut [f64], forward: bool, work: &mut Vec<f64>) {
        let nx = self.nx;
        let lines = rows.len() / nx;
        if lines == 0 {
            return;
        }
        // Pairs of rows through the paired FFT; an odd last row alone (rustdct).
        let mut single = rows;
        if let Some((px, _)) = &self.pairs {
            let paired = lines & !1;
            let (head, tail) = single.split_at_mut(paired * nx);
            if paired > 0 {
                PAIR_SCRATCH.with_borrow_mut(|(z, scratch)| {
                    if forward {
                        px.dct2(head, paired, nx, 1, z, scratch);
                    } else {
                        px.dct3(head, paired, nx, 1, z, scratch);
                    }
                });
            }
            single = tail;
        }
        if single.is_empty() {
            return;
        }
        if work.len() < self.scratch_len {
            work.resize(self.scratch_len, 0.0);
        }
        let scratch = &mut work[..self.scratch_len];
        for row in single.chunks_exact_mut(nx) {
            if forward {
                self.x.process_dct2_with_scratch(row, scratch);
            } else {
                self.x.process_dct3_with_scratch(row, scratch);
            }
        }
    }

    /// `block ← DCT-III_y (diag ⊙ DCT-II_y block)` on a row-major `Ny x width` block of
    /// columns (`diag` the same block of the table), in place.
    pub(crate) fn columns(
        &self,
        block: &mut [f64],
        width: usize,
        diag: &[f64],
        work: &mut Vec<f64>,
    ) {
        let ny = self.ny;
        let n = ny * width;
        if ny == 1 {
            // A length-1 DCT-II is the identity; DCT-III halves it, compensated in diag.
            block.iter_mut().zip(diag).for_each(|(b, d)| *b *= d);
            return;
        }
        if let Some(columns) = &self.columns_matmul {
            if work.len() < n {
                work.resize(n, 0.0);
            }
            columns.filter(block, width, diag, work);
            return;
        }
        if let Some(table) = &self.direct {
            if work.len() < n {
                work.resize(n, 0.0);
            }
            let tmp = &mut work[..n];
            for forward in [true, false] {
                // DCT-II: out_m = Σ_j cos(π m (2j+1)/2Ny) in_j; DCT-III: out_j = in_0/2 +
                // Σ_{m>0} cos(π m (2j+1)/2Ny) in_m (rustdct's unnormalised conventions).
                tmp.fill(0.0);
                for o in 0..ny {
                    let out = &mut tmp[o * width..(o + 1) * width];
                    for i in 0..ny {
                        let w = if forward {
                            table[o * ny + i]
                        } else if i == 0 {
                            0.5
                        } else {
                            table[i * ny + o]
                        };
                        let src = &block[i * width..(i + 1) * width];
                        for (d, s) in out.iter_mut().zip(src) {
                            *d += w * s;
                        }
                    }
                }
                block.copy_from_slice(tmp);
                if forward {
                    block.iter_mut().zip(diag).for_each(|(b, d)| *b *= d);
                }
            }
            return;
        }
        if let Some((_, py)) = &self.pairs {
            if width % 2 == 0 {
                PAIR_SCRATCH.with_borrow_mut(|(z, scratch)| {
                    py.dct2(block, width, 1, width, z, scratch);
                    block.iter_mut().zip(diag).for_each(|(b, d)| *b *= d);
                    py.dct3(block, width, 1, width, z, scratch);
                });
                return;
            }
        }
        let need = self.scratch_len + ny;
        if work.len() < need {
            work.resize(need, 0.0);
        }
        let (scratch, column) = work[..need].split_at_mut(self.scratch_len);
        for forward in [true, false] {
            for ix in 0..width {
                for (iy, c) in column.iter_mut().enumerate() {
                    *c = block[iy * width + ix];
                }
                if forward {
                    self.y.process_dct2_with_scratch(column, scratch);
                } else {
                    self.y.process_dct3_with_scratch(column, scratch);
                }
                for (iy, c) in column.iter().enumerate() {
                    block[iy * width + ix] = *c;
                }
            }
            if forward {
                block.iter_mut().zip(diag).for_each(|(b, d)| *b *= d);
            }
        }
    }
}

/// Diagonal for [`Dct2d::filter`]: the eigenvalue table times the DCT-III scaling.
fn dct_diagonal(grid: &Grid, values: &[f64]) -> Vec<f64> {
    let (nx, ny) = (grid.nx(), grid.ny());
    let mut out = values.to_vec();
    for m in 0..ny {
        for p in 0..nx {
            let mut s = 1.0;
            if p == 0 {
                s *= 2.0;
            }
            if m == 0 && ny > 1 {
                s *= 2.0;
            }
            out[m * nx + p] *= s;
        }
    }
    out
}

/// `cos(π k (2i+1) / (2n))` for all `k, i < n`, with exact argument reduction.
pub(crate) fn cosine_table(n: usize) -> Vec<f64> {
    let base: Vec<f64> = (0..4 * n)
        .map(|j| (PI * j as f64 / (2.0 * n as f64)).cos())
        .collect();
    let mut t = vec![0.0; n * n];
    for k in 0..n {
        for i in 0..n {
            t[k * n + i] = base[(k * (2 * i + 1)) % (4 * n)];
        }
    }
    t
}

impl InfluencePlan {
    /// A builder for the operator of `grid` with the default tolerance.
    pub fn builder(grid: Grid) -> InfluencePlanBuilder {
        InfluencePlanBuilder {
            grid,
            tolerance: 1e-6,
        }
    }

    fn from_eigenvalues(grid: Grid, tolerance: f64, lambda: Vec<f64>, max_rel_error: f64) -> Self {
        let scaled = dct_diagonal(&grid, &lambda);
        Self {
            dct: Arc::new(Dct2d::new(grid.nx(), grid.ny())),
            grid,
            tolerance,
            lambda,
            scaled,
            max_rel_error,
        }
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The relative tolerance the alias sums were computed to.
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// Largest estimated relative error of an eigenvalue.
    pub fn max_relative_error(&self) -> f64 {
        self.max_rel_error
    }

    /// `λ(p', m')` (m⁻¹), the coefficient of `cos(p'·)cos(p'·)cos(m'·)cos(m'·)` in `Ĝ`
    /// (module docs); `p' < Nx`, `m' < Ny`. `None` outside the grid.
    pub fn lambda(&self, p: usize, m: usize) -> Option<f64> {
        (p < self.grid.nx() && m < self.grid.ny()).then(|| self.lambda[m * self.grid.nx() + p])
    }

    /// Eigenvalue of `Ĝ` (m⁻¹) for the orthonormal DCT-II mode `(p', m')`:
    /// `λ / (α_p'² α_m'²)` with `α_0² = 1/N`, `α_{>0}² = 2/N`.
    pub fn eigenvalue(&self, p: usize, m: usize) -> Option<f64> {
        let (nx, ny) = (self.grid.nx() as f64, self.grid.ny() as f64);
        let ax = if p == 0 { 1.0 / nx } else { 2.0 / nx };
        let ay = if m == 0 { 1.0 / ny } else { 2.0 / ny };
        self.lambda(p, m).map(|l| l / (ax * ay))
    }

    /// `out = Ĝ v` (m⁻¹ times the units of `v`), matrix-free in `O(N log N)`.
    pub fn apply(&self, v: &[f64], out: &mut [f64]) -> Result<()> {
        let n = self.grid.len();
        check_slice("v", v, n)?;
        if out.len() != n {
            return Err(Error::LengthMismatch {
                name: "out",
                expected: n,
                found: out.len(),
            });
        }
        out.copy_from_slice(v);
        self.dct.filter(out, &self.scaled, &mut Vec::new());
        Ok(())
    }

    /// `buf ← Ĝ buf` in place (`work`: scratch).
    pub(crate) fn apply_in_place(&self, buf: &mut [f64], work: &mut Vec<f64>) {
        self.dct.filter(buf, &self.scaled, work);
    }

    /// The planned transforms and the operator's table (the solver's split products).
    pub(crate) fn transforms(&self) -> (&Dct2d, &[f64]) {
        (&self.dct, &self.scaled)
    }

    /// The table for [`InfluencePlan::filter_in_place`] of the operator with the same
    /// eigenvectors as `Ĝ` and eigenvalues `map(p', m', eigenvalue(p', m'))`.
    pub(crate) fn spectral_table(&self, map: impl Fn(usize, usize, f64) -> f64) -> Vec<f64> {
        let (nx, ny) = (self.grid.nx(), self.grid.ny());
        let mut values = vec![0.0; nx * ny];
        for m in 0..ny {
            let ay = if m == 0 { 1.0 } else { 2.0 } / ny as f64;
            for p in 0..nx {
                let ax = if p == 0 { 1.0 } else { 2.0 } / nx as f64;
                let k = m * nx + p;
                let eigen = self.lambda[k] / (ax * ay);
                values[k] = map(p, m, eigen) * (ax * ay);
            }
        }
        dct_diagonal(&self.grid, &values)
    }

    /// The dense matrix `Ĝ` (m⁻¹), row-major `N x N`, assembled from the eigenvalue table
    /// by explicit cosine sums (independent of the DCT path). Refused above
    /// [`DENSE_LIMIT`] cells.
    pub fn dense(&self) -> Result<Vec<f64>> {
        let n = self.grid.len();
        if n > DENSE_LIMIT {
            return Err(Error::TooLargeForDense {
                n,
                limit: DENSE_LIMIT,
            });
        }
        let (nx, ny) = (self.grid.nx(), self.grid.ny());
        let cx = cosine_table(nx);
        let cy = cosine_table(ny);
        // B_m[a][b] = Σ_p λ(p,m) cx[p][a] cx[p][b], then Ĝ = Σ_m cy[m]⊗cy[m] ⊗ B_m.
        let mut g = vec![0.0; n * n];
        let mut bm = vec![0.0; nx * nx];
        for m in 0..ny {
            bm.iter_mut().for_each(|x| *x = 0.0);
            for p in 0..nx {
                let l = self.lambda[m * nx + p];
                let row = &cx[p * nx..(p + 1) * nx];
                for a in 0..nx {
                    let la = l * row[a];
                    for b in 0..nx {
                        bm[a * nx + b] += la * row[b];
                    }
                }
            }
            let crow = &cy[m * ny..(m + 1) * ny];
            for iy in 0..ny {
                for jy in 0..ny {
                    let c = crow[iy] * crow[jy];
                    for a in 0..nx {
                        let dst =
                            &mut g[(iy * nx + a) * n + jy * nx..(iy * nx + a) * n + jy * nx + nx];
                        let src = &bm[a * nx..(a + 1) * nx];
                        for (d, s) in dst.iter_mut().zip(src) {
                            *d += c * s;
                        }
                    }
                }
            }
        }
        Ok(g)
    }

    /// The transfer of bottom tractions to the plane at height `z` (m), with the alias
    /// sums converged to absolute tolerance `tol` (the factors are at most 1).
    pub fn plane_transfer(&self, z: f64, tol: f64) -> Result<PlaneTransfer> {
        PlaneTransfer::new(self, z, tol)
    }
}

/// Cell-averaged stress on the plane `z` due to cell-constant bottom tractions.
///
/// A bottom traction mode `(p, m) ≠ 0` reaches height `z` multiplied by
/// `sinh κ(Lz-z)/sinh κLz`, the mean by `(Lz-z)/Lz` (MODEL.md section 1); averaging over
/// source and target cells makes the map diagonal in the DCT-II basis with factors
/// `Σ_{aliases} (2w_p S_p²)(2w_m S_m²)·transfer(κ)`, which are exactly 1 at `z = 0`.
#[derive(Clone)]
pub struct PlaneTransfer {
    grid: Grid,
    z: f64,
    factors: Vec<f64>,
    scaled: Vec<f64>,
    dct: Arc<Dct2d>,
}

impl std::fmt::Debug for PlaneTransfer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PlaneTransfer")
            .field("grid", &self.grid)
            .field("z", &self.z)
            .finish_non_exhaustive()
    }
}

/// `sinh κ(Lz - z)/sinh κLz` written with decaying exponentials; `(Lz - z)/Lz` at κ = 0.
fn transfer(kappa: f64, z: f64, lz: f64) -> f64 {
    if kappa == 0.0 {
        return (lz - z) / lz;
    }
    ((-kappa * z).exp() - (-kappa * (2.0 * lz - z)).exp()) / (-(-2.0 * kappa * lz).exp_m1())
}

impl PlaneTransfer {
    fn new(plan: &InfluencePlan, z: f64, tol: f64) -> Result<Self> {
        let grid = plan.grid;
        let lz = grid.block().lz();
        let z = grid.block().check_height(z)?;
        let tol = check_tolerance(tol)?;
        let (nx, ny) = (grid.nx(), grid.ny());
        let mut factors = vec![0.0; grid.len()];
        for m in 0..ny {
            for p in 0..nx {
                factors[m * nx + p] = if z == 0.0 {
                    1.0
                } else {
                    Self::factor(&grid, p, m, z, lz, tol)?
                };
            }
        }
        // Coefficient form for the DCT filter: factor × α_p'² α_m'² (inverse of the
        // orthonormal scaling), then the DCT-III scaling.
        let coef: Vec<f64> = (0..grid.len())
            .map(|i| {
                let (p, m) = (i % nx, i / nx);
                let ax = if p == 0 {
                    1.0 / nx as f64
                } else {
                    2.0 / nx as f64
                };
                let ay = if m == 0 {
                    1.0 / ny as f64
                } else {
                    2.0 / ny as f64
                };
                factors[i] * ax * ay
            })
            .collect();
        Ok(Self {
            scaled: dct_diagonal(&grid, &coef),
            dct: plan.dct.clone(),
            grid,
            z,
            factors,
        })
    }

    fn factor(grid: &Grid, p: usize, m: usize, z: f64, lz: f64, tol: f64) -> Result<f64> {
        let mut q = 1;
        loop {
            let ax = aliases(p, grid.nx(), grid.dx(), q);
            let ay = aliases(m, grid.ny(), grid.dy(), q);
            // Weights normalised to sum to 1 over all aliases (2 w S²).
            let (sx, sy) = (
                if p == 0 { 2.0 } else { 1.0 },
                if m == 0 { 2.0 } else { 1.0 },
            );
            let mut sum = 0.0;
            for &(wx, kx) in &ax.terms {
                for &(wy, ky) in &ay.terms {
                    sum += sx * wx * sy * wy * transfer((kx * kx + ky * ky).sqrt(), z, lz);
                }
            }
            // Rigorous tail bound: the transfer decreases with κ and is below its value at
            // the nearest alias outside the box; the weights outside sum to 1 - inside.
            let inside = (sx * ax.weight * sy * ay.weight).min(1.0);
            let out_weight = (1.0 - inside).max(0.0);
            let k_out = 2.0 * (q as f64 + 0.5) * PI / grid.dx().max(grid.dy());
            let bound = out_weight * transfer(k_out, z, lz);
            if bound <= tol {
                return Ok(sum);
            }
            if q >= MAX_ALIAS {
                return Err(Error::NotConverged {
                    what: "alias sum of the plane transfer (z too close to 0?)",
                    value: sum,
                    error: bound,
                    tolerance: tol,
                    terms: ((2 * q + 1) * (2 * q + 1)) as u64,
                });
            }
            q *= 2;
        }
    }

    /// Height of the plane (m).
    pub fn z(&self) -> f64 {
        self.z
    }

    /// Transfer factor of the orthonormal DCT-II mode `(p', m')` (dimensionless, in [0, 1]).
    pub fn factor_of_mode(&self, p: usize, m: usize) -> Option<f64> {
        (p < self.grid.nx() && m < self.grid.ny()).then(|| self.factors[m * self.grid.nx() + p])
    }

    /// Cell-averaged stress on the plane (Pa) due to the bottom tractions `traction` (Pa):
    /// `σ(z) = -T(z) φ`, so that `σ_xz` follows from `φ_x` and `σ_zz` from `φ_z`; at
    /// `z = 0` it is `-φ`. External load terms are not included (see [`crate::green::loads`]).
    pub fn stress(&self, traction: &[f64], out: &mut [f64]) -> Result<()> {
        let n = self.grid.len();
        check_slice("traction", traction, n)?;
        if out.len() != n {
            return Err(Error::LengthMismatch {
                name: "out",
                expected: n,
                found: out.len(),
            });
        }
        out.copy_from_slice(traction);
        self.dct.filter(out, &self.scaled, &mut Vec::new());
        out.iter_mut().for_each(|s| *s = -*s);
        Ok(())
    }
}

#[cfg(test)]
mod pair_tests {
    use super::*;

    /// The paired-FFT transforms equal rustdct's, through the whole filter.
    #[test]
    fn paired_filter_equals_rustdct_filter() {
        for (nx, ny) in [(200, 50), (4, 18), (6, 20), (30, 22)] {
            let paired = Dct2d::with_options(nx, ny, true, false);
            let plain = Dct2d::with_options(nx, ny, false, false);
            assert!(paired.pairs.is_some() && plain.pairs.is_none());
            let n = nx * ny;
            let v: Vec<f64> = (0..n).map(|i| ((i * 7919) % 101) as f64 - 50.0).collect();
            let diag: Vec<f64> = (0..n).map(|i| 1.0 + ((i * 31) % 17) as f64).collect();
            let (mut a, mut b) = (v.clone(), v);
            let mut work = Vec::new();
            paired.filter(&mut a, &diag, &mut work);
            plain.filter(&mut b, &diag, &mut work);
            let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for (x, y) in a.iter().zip(&b) {
                assert!((x - y).abs() <= 1e-14 * scale, "{nx}x{ny}: {x} vs {y}");
            }
        }
    }

    /// The matrix-product y-transforms equal the FFT ones (paired and rustdct paths).
    #[test]
    fn matmul_columns_equal_fft_columns() {
        for (nx, ny) in [(200, 50), (4, 18), (30, 22), (9, 17), (12, 63), (8, 64)] {
            for pairs in [true, false] {
                let fast = Dct2d::with_options(nx, ny, pairs, true);
                let fft = Dct2d::with_options(nx, ny, pairs, false);
                assert!(fast.columns_matmul.is_some() && fft.columns_matmul.is_none());
                let n = nx * ny;
                let v: Vec<f64> = (0..n).map(|i| ((i * 7919) % 101) as f64 - 50.0).collect();
                let diag: Vec<f64> = (0..n).map(|i| 1.0 + ((i * 31) % 17) as f64).collect();
                let (mut a, mut b) = (v.clone(), v);
                let mut work = Vec::new();
                fast.filter(&mut a, &diag, &mut work);
                fft.filter(&mut b, &diag, &mut work);
                let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let worst = a
                    .iter()
                    .zip(&b)
                    .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
                eprintln!("{nx}x{ny} pairs {pairs}: {:e}", worst / scale);
                assert!(worst <= 1e-14 * scale, "{nx}x{ny}: {:e}", worst / scale);
            }
        }
    }
}

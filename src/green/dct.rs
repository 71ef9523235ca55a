//! The 2-D DCT engine of the grid: unnormalised DCT-II / DCT-III along both axes (paired
//! complex FFTs, direct or matrix products for short columns, rustdct otherwise), and the
//! filter `DCT-III (diag ⊙ DCT-II x)` that applies every operator diagonal in the DCT
//! basis. Only [`super::plan`] and [`super::transfer`] use it.

use rustdct::num_complex::Complex;
use rustdct::rustfft::{Fft, FftPlanner};
use rustdct::{DctPlanner, TransformType2And3};
use std::f64::consts::PI;
use std::sync::Arc;

/// Below this many rows the y-axis transforms are done as a small dense product over
/// whole rows (contiguous, vectorised) instead of strided length-`Ny` DCTs.
const DIRECT_COLUMNS: usize = 16;

/// Up to this many rows (above [`DIRECT_COLUMNS`]) the y-axis transforms are dense
/// `Ny x Ny` matrix products over the whole `Ny x Nx` block, through faer's matmul
/// (contiguous rows, SIMD chosen at run time) instead of strided FFTs of the columns.
/// Measured at 200 x 50: the y-passes (DCT-II and DCT-III) took 70.7 µs as paired FFTs,
/// 31.6 µs as two products; the whole filter went from 144 µs to 105 µs.
const MATMUL_COLUMNS: usize = 64;

/// A diagonal in the DCT basis seen through a block of columns: row `y` of the block
/// multiplies `values[y * stride..][..width]` (the block's columns of a row-major table).
#[derive(Clone, Copy)]
pub(crate) struct Diag<'a> {
    pub(crate) values: &'a [f64],
    pub(crate) stride: usize,
}

impl Diag<'_> {
    /// `block ⊙= diag` on a row-major block of `width` columns.
    fn scale(&self, block: &mut [f64], width: usize) {
        if width == 0 {
            return;
        }
        for (y, row) in block.chunks_exact_mut(width).enumerate() {
            let d = &self.values[y * self.stride..y * self.stride + width];
            row.iter_mut().zip(d).for_each(|(b, d)| *b *= d);
        }
    }
}

/// The y-axis DCT-II and DCT-III as dense matrices (rustdct's unnormalised conventions).
struct ColumnMatrices {
    /// `D2[m][j] = cos(π m (2j+1) / (2Ny))`.
    forward: faer::Mat<f64>,
    /// `D3[j][m] = D2[m][j]`, and `1/2` for `m = 0`.
    inverse: faer::Mat<f64>,
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
    fn filter(&self, block: &mut [f64], width: usize, diag: Diag<'_>, tmp: &mut [f64]) {
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
        diag.scale(tmp, width);
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

    fn fft_scratch_len(&self) -> usize {
        self.forward
            .get_inplace_scratch_len()
            .max(self.inverse.get_inplace_scratch_len())
    }

    /// Scratch (f64 values) of [`PairDct::dct2`] and [`PairDct::dct3`] on `lines` lines of
    /// stride `step`: the lines' complex data, the FFT's complex scratch, and copies of a
    /// strided pair.
    fn scratch_len(&self, lines: usize, step: usize) -> usize {
        let copies = if step == 1 { 0 } else { 2 * self.n };
        lines * self.n + 2 * self.fft_scratch_len() + copies
    }

    /// `scratch` cut into the lines' complex data, the FFT's complex scratch and the copies
    /// (the complex parts viewed in place: no allocation per transform).
    fn split<'a>(
        &self,
        scratch: &'a mut [f64],
        lines: usize,
    ) -> (
        &'a mut [Complex<f64>],
        &'a mut [Complex<f64>],
        &'a mut [f64],
    ) {
        let (z, rest) = scratch.split_at_mut(lines * self.n);
        let (fft, copies) = rest.split_at_mut(2 * self.fft_scratch_len());
        (
            bytemuck::cast_slice_mut(z),
            bytemuck::cast_slice_mut(fft),
            copies,
        )
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
        copies: &mut [f64],
        body: impl FnOnce(&mut [f64], &mut [f64]),
    ) {
        let n = self.n;
        if step == 1 {
            let (a, b) = data[2 * c * line..].split_at_mut(line);
            body(&mut a[..n], &mut b[..n]);
            return;
        }
        let (a, b) = copies[..2 * n].split_at_mut(n);
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

    /// DCT-II of every line (`lines` even) in place; `scratch` holds at least
    /// [`PairDct::scratch_len`] values.
    fn dct2(&self, data: &mut [f64], lines: usize, line: usize, step: usize, scratch: &mut [f64]) {
        let n = self.n;
        // Every value of `z` is written before it is read.
        let (z, scratch, copies) = self.split(scratch, lines);
        for (c, zc) in z.chunks_exact_mut(n).enumerate() {
            // Makhoul's order: z[j] = (a[2j], b[2j]), z[n-1-j] = (a[2j+1], b[2j+1]).
            self.with_lines(data, line, step, c, copies, |a, b| {
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
            self.with_lines(data, line, step, c, copies, |a, b| {
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

    /// DCT-III of every line (`lines` even) in place; `scratch` as for [`PairDct::dct2`].
    fn dct3(&self, data: &mut [f64], lines: usize, line: usize, step: usize, scratch: &mut [f64]) {
        let n = self.n;
        // Every value of `z` is written before it is read.
        let (z, scratch, copies) = self.split(scratch, lines);
        for (c, zc) in z.chunks_exact_mut(n).enumerate() {
            // W(k) = (X(k) - i X(n-k)) exp(iπk/(2n)) / 2 per line (X(n) = 0); the inverse
            // FFT of W_a + i W_b is v_a + i v_b (both real). In real parts, with A = X_a(k),
            // Ā = X_a(n-k) and B, B̄ alike: Re = c(A + B̄) + s(Ā - B), Im = s(A + B̄) + c(B - Ā).
            self.with_lines(data, line, step, c, copies, |a, b| {
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
            self.with_lines(data, line, step, c, copies, |a, b| {
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
        let pairs = (pairs
            && direct.is_none()
            && nx.is_multiple_of(2)
            && ny.is_multiple_of(2)
            && nx >= 4
            && ny >= 4)
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

    /// Scratch (f64 values) of [`Dct2d::filter`] on the whole grid.
    pub(crate) fn filter_scratch_len(&self) -> usize {
        self.rows_scratch_len(self.ny)
            .max(self.columns_scratch_len(self.nx))
    }

    /// Scratch (f64 values) of [`Dct2d::rows`] on `lines` rows.
    pub(crate) fn rows_scratch_len(&self, lines: usize) -> usize {
        let paired = match &self.pairs {
            Some((px, _)) if lines >= 2 => px.scratch_len(lines & !1, 1),
            _ => 0,
        };
        let single = match &self.pairs {
            Some(_) if lines.is_multiple_of(2) => 0,
            _ => self.scratch_len,
        };
        paired.max(single)
    }

    /// Scratch (f64 values) of [`Dct2d::columns`] on a block `width` columns wide.
    pub(crate) fn columns_scratch_len(&self, width: usize) -> usize {
        let n = self.ny * width;
        if self.ny == 1 {
            0
        } else if self.columns_matmul.is_some() || self.direct.is_some() {
            n
        } else {
            match &self.pairs {
                Some((_, py)) if width.is_multiple_of(2) => py.scratch_len(width, width),
                _ => self.scratch_len + self.ny,
            }
        }
    }

    /// In place: forward (unnormalised DCT-II) on both axes, multiply by `diag`, then
    /// unnormalised DCT-III on both axes. `scratch` holds at least
    /// [`Dct2d::filter_scratch_len`] values (iterative solvers keep theirs: no allocation
    /// per product).
    pub(crate) fn filter(&self, buf: &mut [f64], diag: &[f64], stride: usize, scratch: &mut [f64]) {
        self.rows(buf, true, scratch);
        self.columns(
            buf,
            self.nx,
            Diag {
                values: diag,
                stride,
            },
            scratch,
        );
        self.rows(buf, false, scratch);
    }

    /// Whether [`Dct2d::rows`] and [`Dct2d::columns`] pair their lines (the paired FFT
    /// path: both lengths even).
    pub(crate) fn pairs_lines(&self) -> bool {
        self.pairs.is_some()
    }

    /// Unnormalised DCT-II (`forward`) or DCT-III of every row of `rows`, a whole number
    /// of rows of the grid, in place (on the paired path, an odd last row runs alone:
    /// rounding then depends on where a block of rows starts, fixed by the caller).
    /// `scratch` holds at least [`Dct2d::rows_scratch_len`] values.
    pub(crate) fn rows(&self, rows: &mut [f64], forward: bool, scratch: &mut [f64]) {
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
                if forward {
                    px.dct2(head, paired, nx, 1, scratch);
                } else {
                    px.dct3(head, paired, nx, 1, scratch);
                }
            }
            single = tail;
        }
        if single.is_empty() {
            return;
        }
        let scratch = &mut scratch[..self.scratch_len];
        for row in single.chunks_exact_mut(nx) {
            if forward {
                self.x.process_dct2_with_scratch(row, scratch);
            } else {
                self.x.process_dct3_with_scratch(row, scratch);
            }
        }
    }

    /// `block ← DCT-III_y (diag ⊙ DCT-II_y block)` on a row-major `Ny x width` block of
    /// columns (`diag` the same block of the table), in place; `scratch` holds at least
    /// [`Dct2d::columns_scratch_len`] values.
    pub(crate) fn columns(
        &self,
        block: &mut [f64],
        width: usize,
        diag: Diag<'_>,
        scratch: &mut [f64],
    ) {
        let ny = self.ny;
        let n = ny * width;
        if ny == 1 {
            // A length-1 DCT-II is the identity; DCT-III halves it, compensated in diag.
            diag.scale(block, width);
            return;
        }
        if let Some(columns) = &self.columns_matmul {
            columns.filter(block, width, diag, scratch);
            return;
        }
        if let Some(table) = &self.direct {
            let tmp = &mut scratch[..n];
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
                    diag.scale(block, width);
                }
            }
            return;
        }
        if let Some((_, py)) = &self.pairs {
            if width.is_multiple_of(2) {
                py.dct2(block, width, 1, width, scratch);
                diag.scale(block, width);
                py.dct3(block, width, 1, width, scratch);
                return;
            }
        }
        let (scratch, column) = scratch[..self.scratch_len + ny].split_at_mut(self.scratch_len);
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
                diag.scale(block, width);
            }
        }
    }
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
            paired.filter(
                &mut a,
                &diag,
                nx,
                &mut vec![0.0; paired.filter_scratch_len()],
            );
            plain.filter(
                &mut b,
                &diag,
                nx,
                &mut vec![0.0; plain.filter_scratch_len()],
            );
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
                fast.filter(&mut a, &diag, nx, &mut vec![0.0; fast.filter_scratch_len()]);
                fft.filter(&mut b, &diag, nx, &mut vec![0.0; fft.filter_scratch_len()]);
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

//! Analytic load terms: what the external loads contribute to the interface
//! displacements and to the stresses at height `z`, per unit force.
//!
//! A load of force `F` (N) spread as a uniform traction `t = F / area` over a face adds
//! `u = (F/M) · influence` to the displacement of the bottom face (docs/model.md section 1,
//! `u = ⟨u⟩ + (1/M) ∮ G t dS`), where `influence = (1/area) ∫_face G dS` (m⁻¹), and adds
//! `F · stress_influence` to the stress `M ∂u/∂z` at height `z`, where
//! `stress_influence = (1/area) ∫_face ∂G/∂z dS` (m⁻²).
//!
//! On the grid the terms enter cell-averaged over x (docs/model.md section 2): every function
//! `*_cells` returns one value per column `ix` (they do not depend on y).

use super::point::{cos_sum_n2, sin_sum_n3, Estimate};
use crate::error::{check_length, check_tolerance, Error, Result};
use crate::geometry::{Block, Grid};
use std::f64::consts::PI;

/// Largest number of series terms a load term may sum.
const MAX_TERMS: u64 = 20_000_000;

/// Top-face load per unit force: `(1/(Lx Ly)) ∫∫_top G(x,ξ;y,η;0,Lz) dξ dη = -Lz/(6 Lx Ly)`
/// (m⁻¹), the same at every point of the bottom face (paper Eq. `G_x_top`).
///
/// A top shear `F_top` adds `F_top/M` times this to `u_x`; the normal load, a traction
/// `-F_N/(Lx Ly)`, adds `-F_N/M` times this to `u_z`.
///
/// ```
/// use precursors::{green::top_influence, Block};
/// let thin = Block::new(0.010, 0.004, 0.005)?;
/// let thick = Block::new(0.010, 0.004, 0.010)?;
/// // Uniform over the bottom, negative, proportional to the height Lz (m⁻¹).
/// assert!(top_influence(&thin) < 0.0);
/// assert!((top_influence(&thick) / top_influence(&thin) - 2.0).abs() < 1e-12);
/// # Ok::<(), precursors::Error>(())
/// ```
pub fn top_influence(block: &Block) -> f64 {
    -block.lz() / (6.0 * block.lx() * block.ly())
}

/// Top-face load per unit force, transferred to height `z` (m):
/// `(1/(Lx Ly)) ∫∫_top ∂G/∂z (x,ξ;y,η;z,Lz) dξ dη = z/(Lz Lx Ly)` (m⁻²), paper Eq.
/// `derivative_G_B` divided by the face area.
///
/// # Errors
/// [`Error::OutsideBlock`] for `z` outside `[0, Lz]`.
///
/// At the top face the stress is the whole load over the face, `1/(Lx Ly)` per newton;
/// at the bottom the top load adds nothing (the bottom tractions carry it):
///
/// ```
/// use precursors::{green::top_stress_influence, Block};
/// let block = Block::new(0.010, 0.004, 0.005)?;
/// let face = 1.0 / (0.010 * 0.004);                          // m⁻²
/// assert!((top_stress_influence(&block, 0.005)? - face).abs() < 1e-9 * face);
/// assert_eq!(top_stress_influence(&block, 0.0)?, 0.0);
/// assert!(top_stress_influence(&block, 0.006).is_err());    // above the block
/// # Ok::<(), precursors::Error>(())
/// ```
pub fn top_stress_influence(block: &Block, z: f64) -> Result<f64> {
    let z = block.check_height(z)?;
    Ok(z / (block.lz() * block.lx() * block.ly()))
}

/// A shear load on the trailing face `x = 0`, uniform over `y ∈ [0, Ly]` and
/// `z ∈ [h - Δh, h + Δh]`: the paper's rod. `h = Δh = Lz/2` is the uniform side load.
///
/// ```
/// use precursors::{green::RodLoad, Block, Error, Grid};
/// let block = Block::new(0.010, 0.004, 0.005)?;             // 10 x 4 x 5 mm
/// let grid = Grid::new(block, 10, 4)?;                       // 1 mm cells
/// // A rod 1 mm wide (Δh = 0.5 mm) at h = 1 mm on the trailing face x = 0.
/// let rod = RodLoad::new(&block, 1e-3, 0.5e-3)?;
/// let cells = rod.influence_cells(&grid, 1e-10)?;            // per newton, per column (m⁻¹)
/// assert_eq!(cells.len(), 10);
/// assert!(cells[0] > cells[1] && cells[1] > cells[9]);      // largest next to the rod
/// // The uniform side load, h = Δh = Lz/2: its column averages only tilt the face (their
/// // sum is 0) and its influence at x = Lx/2 is -Lx/(24 Ly Lz) (m⁻¹).
/// let side = RodLoad::uniform_side(&block);
/// assert_eq!(side, RodLoad::new(&block, 2.5e-3, 2.5e-3)?);
/// let side_cells = side.influence_cells(&grid, 1e-10)?;
/// assert!(side_cells.iter().sum::<f64>().abs() < 1e-8 * side_cells[0]);
/// let middle = side.influence_at(0.005, 1e-10)?;
/// assert!((middle.value + 0.010 / (24.0 * 0.004 * 0.005)).abs() < 1e-9);
/// // A band must lie on the face: [4.3, 5.3] mm leaves Lz = 5 mm.
/// let e = RodLoad::new(&block, 4.8e-3, 0.5e-3).unwrap_err();
/// assert!(matches!(e, Error::RodBandOutsideFace { high, lz, .. } if high > lz));
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RodLoad {
    block: Block,
    h: f64,
    half_width: f64,
}

impl RodLoad {
    /// A rod at height `h` (m) with half-width `half_width = Δh` (m); the band
    /// `[h - Δh, h + Δh]` must lie inside `[0, Lz]` (to 1e-12 relative).
    ///
    /// # Errors
    /// [`Error::InvalidLength`] for a half-width or height that is not finite and `> 0`;
    /// [`Error::RodBandOutsideFace`] when the band leaves `[0, Lz]`.
    pub fn new(block: &Block, h: f64, half_width: f64) -> Result<Self> {
        check_length("rod half-width", half_width)?;
        let lz = block.lz();
        let (low, high) = (h - half_width, h + half_width);
        let slack = 1e-12 * lz;
        if !h.is_finite() || low < -slack || high > lz + slack {
            return Err(Error::RodBandOutsideFace { low, high, lz });
        }
        Ok(Self {
            block: *block,
            h,
            half_width,
        })
    }

    /// The uniform side load: the whole trailing face, `h = Δh = Lz/2`.
    pub fn uniform_side(block: &Block) -> Self {
        Self {
            block: *block,
            h: block.lz() / 2.0,
            half_width: block.lz() / 2.0,
        }
    }

    /// Height of the rod's centre (m).
    pub fn h(&self) -> f64 {
        self.h
    }
    /// Half-width `Δh` of the band (m).
    pub fn half_width(&self) -> f64 {
        self.half_width
    }

    /// Band edges `(c₋, c₊) = (h - Δh, h + Δh)` clamped into `[0, Lz]` against rounding.
    fn edges(&self) -> (f64, f64) {
        let lz = self.block.lz();
        (
            (self.h - self.half_width).clamp(0.0, lz),
            (self.h + self.half_width).clamp(0.0, lz),
        )
    }

    /// `I_n = ∫_band cos(k_n ζ) dζ` (m).
    fn band_moment(&self, k: f64) -> f64 {
        let (lo, hi) = self.edges();
        ((k * hi).sin() - (k * lo).sin()) / k
    }

    /// Polynomial part `Lx (x²/(2Lx²) - x/Lx + 1/3)` integrated over `[xa, xb]`.
    fn polynomial_integral(&self, xa: f64, xb: f64) -> f64 {
        let lx = self.block.lx();
        let prim = |x: f64| x.powi(3) / (6.0 * lx) - x * x / 2.0 + lx * x / 3.0;
        prim(xb) - prim(xa)
    }

    /// Rod load per unit force at the point `x` of the bottom face:
    /// `(1/(2Δh Ly)) ∫_0^Ly dη ∫_band dζ G(x,0;y,η;0,ζ)` (m⁻¹), to absolute tolerance
    /// `tol` (m⁻¹). Closed form (docs/model.md section 1, paper Eq. `G_x_lat` with all its
    /// constants):
    /// `(1/(Ly Lz)) [Lx(x²/2Lx² - x/Lx + 1/3) + (1/Δh) Σ_n (I_n/k_n) cosh k_n(Lx-x)/sinh k_nLx]`.
    ///
    /// # Errors
    /// [`Error::InvalidTolerance`]; [`Error::OutsideBlock`] for `x` outside `[0, Lx]`;
    /// [`Error::SeriesNotConverged`] when the series does not reach `tol`.
    pub fn influence_at(&self, x: f64, tol: f64) -> Result<Estimate> {
        check_tolerance(tol)?;
        let lx = self.block.lx();
        if !(x.is_finite() && (0.0..=lx).contains(&x)) {
            return Err(Error::OutsideBlock {
                name: "x",
                value: x,
                max: lx,
            });
        }
        let pref = 1.0 / (self.block.ly() * self.block.lz());
        let poly = x * x / (2.0 * lx) - x + lx / 3.0;
        let series = self.sum_series(tol / pref * self.half_width, x, |k| {
            let ch = ((-k * x).exp() + (-k * (2.0 * lx - x)).exp()) / (-(-2.0 * k * lx).exp_m1());
            let bound = 2.0 * (-k * x).exp() / (-(-2.0 * k * lx).exp_m1());
            (self.band_moment(k) / k * ch, bound / (k * k) * 2.0)
        })?;
        Ok(Estimate {
            value: pref * (poly + series.value / self.half_width),
            error: pref * series.error / self.half_width,
        })
    }

    /// Rod load per unit force averaged over each column of cells (m⁻¹): `Nx` values,
    /// each within `tol` (m⁻¹) of the exact cell average of [`RodLoad::influence_at`].
    ///
    /// # Errors
    /// [`Error::InvalidTolerance`]; [`Error::InvalidParameter`] for a grid on another
    /// block; [`Error::SeriesNotConverged`] when a series does not reach `tol`.
    pub fn influence_cells(&self, grid: &Grid, tol: f64) -> Result<Vec<f64>> {
        #[cfg(test)]
        super::built::count(|b| b.load_series += 1);
        check_tolerance(tol)?;
        self.check_grid(grid)?;
        let lx = self.block.lx();
        let dx = grid.dx();
        let pref = 1.0 / (self.block.ly() * self.block.lz());
        let lz = self.block.lz();
        let (lo, hi) = self.edges();
        (0..grid.nx())
            .map(|ix| {
                let xa = ix as f64 * dx;
                let xb = xa + dx;
                let poly = self.polynomial_integral(xa, xb) / dx;
                let first = ix == 0;
                // First cell: Σ (I_n/k_n)/(k_nΔx) = (1/Δx)(Lz/π)³ Σ [sin nθ₊ - sin nθ₋]/n³ in
                // closed form; what is left decays like e^{-k Δx}.
                let closed = if first {
                    (lz / PI).powi(3) * (sin_sum_n3(PI * hi / lz) - sin_sum_n3(PI * lo / lz)) / dx
                } else {
                    0.0
                };
                let gap = if first { dx } else { xa };
                let series = self.sum_series(tol / pref * self.half_width, gap, |k| {
                    let avg = cell_average_cosh(k, xa, xb, lx, first);
                    let bound =
                        2.0 * (-k * gap).exp() / (k * dx).max(1.0) / (-(-2.0 * k * lx).exp_m1());
                    (self.band_moment(k) / k * avg, bound * 2.0 / (k * k))
                })?;
                Ok(pref * (poly + (closed + series.value) / self.half_width))
            })
            .collect()
    }

    /// Rod load per unit force transferred to the point `(x, z)`:
    /// `(1/(2Δh Ly)) ∫ dη ∫_band dζ ∂G/∂z (x,0;y,η;z,ζ)
    ///  = -(1/(Δh Ly Lz)) Σ_n sin(k_n z) I_n cosh k_n(Lx-x)/sinh k_nLx` (m⁻²), to absolute
    /// tolerance `tol` (m⁻²). At `x = 0` on an edge of the band the stress is
    /// logarithmically infinite and [`Error::SingularPoint`] is returned.
    ///
    /// # Errors
    /// [`Error::InvalidTolerance`]; [`Error::OutsideBlock`] for `x` or `z` outside the
    /// block; [`Error::SingularPoint`] on an edge of the band at `x = 0`;
    /// [`Error::SeriesNotConverged`].
    pub fn stress_influence_at(&self, x: f64, z: f64, tol: f64) -> Result<Estimate> {
        check_tolerance(tol)?;
        let lx = self.block.lx();
        let lz = self.block.lz();
        if !(x.is_finite() && (0.0..=lx).contains(&x)) {
            return Err(Error::OutsideBlock {
                name: "x",
                value: x,
                max: lx,
            });
        }
        let z = self.block.check_height(z)?;
        let pref = -1.0 / (self.half_width * self.block.ly() * lz);
        // cosh k(L-x)/sinh kL = e^{-kx} + rest; the e^{-kx} part in closed form:
        // Σ cos(nθ) e^{-nβ}/n = -½ ln(1 - 2 e^{-β} cos θ + e^{-2β}).
        let beta = PI * x / lz;
        let log_sum = |theta: f64| -> Result<f64> {
            let q = (-beta).exp();
            let arg = if beta == 0.0 {
                2.0 * (1.0 - theta.cos())
            } else {
                1.0 - 2.0 * q * theta.cos() + q * q
            };
            if arg <= 0.0 {
                // The rod stress does not depend on y; y = 0 labels the face.
                return Err(Error::SingularPoint { x, y: 0.0, z });
            }
            Ok(-0.5 * arg.ln())
        };
        let (lo, hi) = self.edges();
        let phi = PI * z / lz;
        let mut closed = 0.0;
        for (c, sgn) in [(hi, 1.0), (lo, -1.0)] {
            let theta = PI * c / lz;
            // sin(nφ) sin(nθ) = ½[cos n(φ-θ) - cos n(φ+θ)]; I_n carries 1/k_n = Lz/(nπ).
            if c == 0.0 {
                continue;
            }
            closed += sgn * 0.5 * (log_sum((phi - theta).abs())? - log_sum(phi + theta)?) * lz / PI;
        }
        let gap = lx;
        let series = self.sum_series(tol / pref.abs(), gap, |k| {
            let rest = ((-k * x).exp() * (-2.0 * k * lx).exp() + (-k * (2.0 * lx - x)).exp())
                / (-(-2.0 * k * lx).exp_m1());
            let bound = 2.0 * (-k * lx).exp() / (-(-2.0 * k * lx).exp_m1());
            ((k * z).sin() * self.band_moment(k) * rest, 2.0 / k * bound)
        })?;
        Ok(Estimate {
            value: pref * (closed + series.value),
            error: pref.abs() * series.error,
        })
    }

    /// Rod load per unit force transferred to height `z`, averaged over each column of
    /// cells (m⁻²): `Nx` values, each within `tol` (m⁻²) of the exact cell average.
    ///
    /// # Errors
    /// [`Error::InvalidTolerance`]; [`Error::OutsideBlock`] for `z` outside `[0, Lz]`;
    /// [`Error::InvalidParameter`] for a grid on another block; [`Error::SeriesNotConverged`].
    pub fn stress_influence_cells(&self, grid: &Grid, z: f64, tol: f64) -> Result<Vec<f64>> {
        #[cfg(test)]
        super::built::count(|b| b.load_series += 1);
        check_tolerance(tol)?;
        self.check_grid(grid)?;
        let z = self.block.check_height(z)?;
        let lx = self.block.lx();
        let lz = self.block.lz();
        let dx = grid.dx();
        let pref = -1.0 / (self.half_width * self.block.ly() * lz);
        let (lo, hi) = self.edges();
        let phi = PI * z / lz;
        (0..grid.nx())
            .map(|ix| {
                let xa = ix as f64 * dx;
                let xb = xa + dx;
                let first = ix == 0;
                // First cell: (1/Δx) Σ sin(k z) I_n / k_n in closed form through
                // Σ cos(nθ)/n² = π²/6 - πθ/2 + θ²/4.
                let closed = if first {
                    let mut c = 0.0;
                    for (edge, sgn) in [(hi, 1.0), (lo, -1.0)] {
                        let theta = PI * edge / lz;
                        c +=
                            sgn * 0.5 * (cos_sum_n2((phi - theta).abs()) - cos_sum_n2(phi + theta));
                    }
                    c * (lz / PI).powi(2) / dx
                } else {
                    0.0
                };
                let gap = if first { dx } else { xa };
                let series = self.sum_series(tol / pref.abs(), gap, |k| {
                    let avg = cell_average_cosh(k, xa, xb, lx, first);
                    let bound =
                        2.0 * (-k * gap).exp() / (k * dx).max(1.0) / (-(-2.0 * k * lx).exp_m1());
                    ((k * z).sin() * self.band_moment(k) * avg, 2.0 / k * bound)
                })?;
                Ok(pref * (closed + series.value))
            })
            .collect()
    }

    fn check_grid(&self, grid: &Grid) -> Result<()> {
        if grid.block() != &self.block {
            return Err(Error::InvalidParameter {
                name: "grid",
                value: grid.block().lx(),
                reason: "the grid lies on another block than the rod load",
            });
        }
        Ok(())
    }

    /// Sums `Σ_{n≥1} term(k_n)` where `term` returns `(value, bound)` with bounds that
    /// decrease at least geometrically with ratio `e^{-π gap/Lz}` times a decreasing factor;
    /// stops when the tail bound is below `tol`.
    fn sum_series(&self, tol: f64, gap: f64, term: impl Fn(f64) -> (f64, f64)) -> Result<Estimate> {
        let lz = self.block.lz();
        let ratio = (-PI * gap / lz).exp();
        let mut sum = 0.0;
        let mut n = 1u64;
        loop {
            let k = n as f64 * PI / lz;
            let (value, _) = term(k);
            sum += value;
            // Tail after n: geometric when gap > 0, else Σ_{j>n} C/j² ≤ C·n²·(1/n)·(1/n²).
            let next_bound = {
                let k1 = (n + 1) as f64 * PI / lz;
                term(k1).1
            };
            let tail = if ratio < 1.0 - 1e-12 {
                next_bound / (1.0 - ratio)
            } else {
                next_bound * (n + 1) as f64
            };
            if tail <= tol {
                return Ok(Estimate {
                    value: sum,
                    error: tail,
                });
            }
            if n >= MAX_TERMS {
                return Err(Error::SeriesNotConverged {
                    what: "rod load series",
                    value: sum,
                    error: tail,
                    tolerance: tol,
                    terms: n,
                });
            }
            n += 1;
        }
    }
}

/// Average over `[xa, xb]` of `cosh k(L-x)/sinh kL`, minus `1/(kΔx)` on the first cell
/// (`xa = 0`, where that part is summed in closed form).
fn cell_average_cosh(k: f64, xa: f64, xb: f64, l: f64, first: bool) -> f64 {
    let dx = xb - xa;
    let den = k * dx * (-(-2.0 * k * l).exp_m1());
    if first {
        // [e^{-k(2L-Δx)} - e^{-kΔx}] / (kΔx (1 - e^{-2kL}))
        ((-k * (2.0 * l - dx)).exp() - (-k * dx).exp()) / den
    } else {
        let near = (-k * xa).exp() * (-(-k * dx).exp_m1());
        let far = (-k * (2.0 * l - xb)).exp() * (-(-k * dx).exp_m1());
        (near + far) / den
    }
}

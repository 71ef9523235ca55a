//! The transfer of bottom tractions to a plane at height `z` inside the block.

use super::dct::Dct2d;
use super::plan::InfluencePlan;
use super::spectrum::{aliases, MAX_ALIAS};
use crate::error::{check_slice, check_tolerance, Error, Result};
use crate::geometry::Grid;
use std::f64::consts::PI;
use std::sync::Arc;

/// Cell-averaged stress on the plane `z` due to cell-constant bottom tractions.
///
/// A bottom traction mode `(p, m) ≠ 0` reaches height `z` multiplied by
/// `sinh κ(Lz-z)/sinh κLz`, the mean by `(Lz-z)/Lz` (docs/model.md section 1); averaging
/// over source and target cells makes the map diagonal in the DCT-II basis with factors
/// `Σ_{aliases} (2w_p S_p²)(2w_m S_m²)·transfer(κ)`, which are exactly 1 at `z = 0`.
///
/// ```
/// use precursors::{green::InfluencePlan, Block, Grid};
/// let grid = Grid::new(Block::new(0.010, 0.004, 0.005)?, 10, 4)?;    // Lz = 5 mm
/// let plan = InfluencePlan::builder(grid).build()?;
/// let plane = plan.plane_transfer(2e-3, 1e-10)?;          // the plane z = 2 mm
/// // A uniform 1 kPa traction reaches z scaled by (Lz - z)/Lz = 3/5: σ = -600 Pa.
/// let mut sigma = vec![0.0; grid.len()];
/// plane.stress(&vec![1e3; grid.len()], &mut sigma)?;
/// assert!(sigma.iter().all(|s| (s + 600.0).abs() < 1e-6));
/// // Modes that vary along the face fade faster with height.
/// let (mean, first) = (plane.factor_of_mode(0, 0).unwrap(), plane.factor_of_mode(1, 0).unwrap());
/// assert!((mean - 0.6).abs() < 1e-10 && first < mean);
/// // At z = 0 the transfer is the identity: σ = -φ.
/// let mut traction = vec![0.0; grid.len()];
/// traction[7] = 1e3;
/// plan.plane_transfer(0.0, 1e-10)?.stress(&traction, &mut sigma)?;
/// assert!((sigma[7] + 1e3).abs() < 1e-9 && sigma[8].abs() < 1e-9);
/// # Ok::<(), precursors::Error>(())
/// ```
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

/// The lowest plane above the interface (m) whose transfer `grid`'s alias sums reach to
/// absolute tolerance `tol` within their budget ([`MAX_ALIAS`]) for every mode: the tail
/// bound of [`PlaneTransfer`]'s sums is at most `transfer(κ_out, z)` with
/// `κ_out = 2π(MAX_ALIAS + ½)/max(dx, dy)`, and `transfer(κ, z) <= e^{-κz}/(1 - e^{-2κLz})`,
/// so `z >= ln(1/(tol (1 - e^{-2κ_out Lz})))/κ_out` converges. `z = 0` (the interface)
/// needs no sum. About `0.0072 max(dx, dy)` at `tol = 1e-10`.
pub(crate) fn lowest_plane(grid: &Grid, tol: f64) -> f64 {
    let k_out = 2.0 * (MAX_ALIAS as f64 + 0.5) * PI / grid.dx().max(grid.dy());
    let lz = grid.block().lz();
    // 1 + 1e-9: the bound is evaluated in floating point.
    (1.0 + 1e-9) * -(tol * -(-2.0 * k_out * lz).exp_m1()).ln() / k_out
}

/// `sinh κ(Lz - z)/sinh κLz` written with decaying exponentials; `(Lz - z)/Lz` at κ = 0.
fn transfer(kappa: f64, z: f64, lz: f64) -> f64 {
    if kappa == 0.0 {
        return (lz - z) / lz;
    }
    ((-kappa * z).exp() - (-kappa * (2.0 * lz - z)).exp()) / (-(-2.0 * kappa * lz).exp_m1())
}

// Defined here, not in plan.rs: the plan knows nothing of the transfers built on it.
impl InfluencePlan {
    /// The transfer of bottom tractions to the plane at height `z` (m), with the alias
    /// sums converged to absolute tolerance `tol` (the factors are at most 1).
    ///
    /// # Errors
    /// [`Error::InvalidTolerance`],
    /// [`Error::OutsideBlock`] for `z` outside `[0, Lz]`, [`Error::SeriesNotConverged`].
    pub fn plane_transfer(&self, z: f64, tol: f64) -> Result<PlaneTransfer> {
        #[cfg(test)]
        super::built::count(|b| b.transfers += 1);
        PlaneTransfer::new(self, z, tol)
    }
}

impl PlaneTransfer {
    fn new(plan: &InfluencePlan, z: f64, tol: f64) -> Result<Self> {
        let grid = *plan.grid();
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
            scaled: super::plan::dct_diagonal(&grid, &coef),
            dct: plan.dct().clone(),
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
                return Err(Error::SeriesNotConverged {
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
    /// `z = 0` it is `-φ`. External load terms are not included (see [`crate::green::top_stress_influence`] and [`crate::green::RodLoad`]).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when `traction` or `out` does not hold one value per cell;
    /// [`Error::NonFinite`] for a NaN or infinite traction.
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
        let mut scratch = vec![0.0; self.dct.filter_scratch_len()];
        self.dct
            .filter(out, &self.scaled, self.grid.nx(), &mut scratch);
        out.iter_mut().for_each(|s| *s = -*s);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Block;

    /// The documented lowest plane converges on every mode of grids of several shapes and
    /// tolerances (the bound is sufficient; below it a sum may or may not converge).
    #[test]
    fn the_lowest_plane_converges_on_every_mode() {
        for (lx, ly, lz, nx, ny, tol) in [
            (0.014, 0.003, 0.075, 14, 3, 1e-10),
            (0.004, 0.004, 0.002, 4, 4, 1e-15),
            (0.006, 0.002, 0.02, 12, 2, 1e-6),
        ] {
            let grid = Grid::new(Block::new(lx, ly, lz).unwrap(), nx, ny).unwrap();
            let plan = InfluencePlan::builder(grid).build().unwrap();
            let z = lowest_plane(&grid, tol);
            assert!(z > 0.0 && z < 0.02 * grid.dx().max(grid.dy()), "{z}");
            let transfer = plan.plane_transfer(z, tol).unwrap();
            assert!(transfer
                .factors
                .iter()
                .all(|f| (0.0..=1.0 + 1e-12).contains(f)));
        }
    }
}

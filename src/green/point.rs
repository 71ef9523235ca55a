//! Point evaluation of the box's Neumann Green function `G` and of `∂G/∂z`.
//!
//! `G(r, r') = (8/V) Σ_{(p,m,n)≠0} γ_pmn cos(k_p x)cos(k_p ξ) cos(k_m y)cos(k_m η)
//! cos(k_n z)cos(k_n ζ) / (k_p² + k_m² + k_n²)` (paper Eq. `green`), with
//! `-∇²G = δ - 1/V`, `∂G/∂n = 0` on every face and zero volume mean.
//!
//! Two evaluations are offered:
//! * [`GreenFunction::raw_series`], the triple cosine series itself (slow, a reference);
//! * [`GreenFunction::value`] and [`GreenFunction::dz`], the paper's rapidly converging
//!   representation (Appendix "Rapidly converging representation", and for `∂G/∂z` the
//!   functions 𝒢 and 𝒬 of "Calculation of Coulomb stress"): one of the three sums is done in
//!   closed form,
//!   `Σ_n w_n cos(k_n a)cos(k_n α)/(k_n² + κ²) = (L/4κ)[cosh κ(L-|a-α|) + cosh κ(L-a-α)]/sinh κL`,
//!   leaving a double series whose terms decay like `exp(-κ d)`, `d` the distance of the
//!   target to the source and its mirror images along the summed axis. The paper sums along
//!   y (its function 𝓗) and switches to x on the hypersurface `y = η, z = ζ` (its Eq.
//!   `green_3`); here the axis is chosen per point ([`SummationAxis::Auto`]) as the one
//!   that needs the fewest terms, which covers both of the paper's cases and every other.

use crate::error::{check_tolerance, Error, Result};
use crate::geometry::{Block, Point};
use std::f64::consts::PI;

/// A value with an estimate of its truncation error, in the units of the value.
///
/// ```
/// use precursors::{green::RodLoad, Block};
/// let block = Block::new(0.010, 0.004, 0.005)?;              // 10 x 4 x 5 mm
/// // The uniform side load per newton at x = Lx/2 of the bottom face, to 1e-10 m⁻¹.
/// let estimate = RodLoad::uniform_side(&block).influence_at(0.005, 1e-10)?;
/// assert!(estimate.error <= 1e-10);
/// // The exact value is -Lx/(24 Ly Lz) (m⁻¹): within the estimated error (and rounding).
/// let exact = -0.010 / (24.0 * 0.004 * 0.005);
/// assert!((estimate.value - exact).abs() <= estimate.error + 1e-12 * exact.abs());
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// Estimated absolute truncation error (same units as `value`).
    pub error: f64,
}

/// Which coordinate's series the rapid representation sums in closed form.
///
/// Every axis along which the target and the source differ gives the same `G`; `Auto`
/// picks the one needing fewest terms.
///
/// ```
/// use precursors::green::{GreenFunction, SeriesOptions, SummationAxis};
/// use precursors::{Block, Error, Point};
/// let green = GreenFunction::new(Block::new(0.010, 0.004, 0.005)?);   // 10 x 4 x 5 mm
/// let (target, source) = (Point::new(3e-3, 1e-3, 0.0), Point::new(6e-3, 3e-3, 2e-3));
/// let options = SeriesOptions::default().with_tolerance(1e-9)?;       // m⁻¹
/// let g = |axis| green.value_with_options(target, source, &options.with_axis(axis));
/// let auto = g(SummationAxis::Auto)?.value;
/// for axis in [SummationAxis::X, SummationAxis::Y, SummationAxis::Z] {
///     assert!((g(axis)?.value - auto).abs() < 3e-9);
/// }
/// // Along an axis where both points share their coordinate the sum does not converge.
/// let level = Point { z: 0.0, ..source };
/// let forced = options.with_axis(SummationAxis::Z);
/// let e = green.value_with_options(target, level, &forced).unwrap_err();
/// assert!(matches!(e, Error::InvalidChoice { .. }));
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum SummationAxis {
    /// The axis along which the target is farthest from the source and its images
    /// (fewest terms). The default.
    #[default]
    Auto,
    /// Sum the x series in closed form (the paper's Eq. `green_3`).
    X,
    /// Sum the y series in closed form (the paper's function 𝓗).
    Y,
    /// Sum the z series in closed form (the paper's 𝒢 and 𝒬 for `∂G/∂z`).
    Z,
}

/// Options of a point evaluation.
///
/// The fields are private: options are valid by construction (the defaults, then the
/// `with_` modifiers).
///
/// ```
/// use precursors::green::{SeriesOptions, SummationAxis};
/// let opts = SeriesOptions::default().with_tolerance(1e-8)?.with_axis(SummationAxis::Z);
/// assert_eq!((opts.tolerance(), opts.axis()), (1e-8, SummationAxis::Z));
/// assert!(SeriesOptions::default().with_max_terms(0).is_err());
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct SeriesOptions {
    tolerance: f64,
    axis: SummationAxis,
    max_terms: u64,
}

impl Default for SeriesOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            axis: SummationAxis::Auto,
            max_terms: 50_000_000,
        }
    }
}

impl SeriesOptions {
    /// Absolute tolerance on the result, in the units of the result (m⁻¹ for `G`, m⁻² for
    /// `∂G/∂z`). Default `1e-10`.
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// Axis summed in closed form by the rapid representation. Default
    /// [`SummationAxis::Auto`].
    pub fn axis(&self) -> SummationAxis {
        self.axis
    }

    /// Largest number of terms a single evaluation may sum before it reports
    /// [`Error::SeriesNotConverged`]. Default `5e7`.
    pub fn max_terms(&self) -> u64 {
        self.max_terms
    }

    /// The same options with another absolute tolerance (units of the result, finite and
    /// `> 0`).
    ///
    /// # Errors
    /// [`Error::InvalidTolerance`] for a tolerance that is not finite and `> 0`.
    pub fn with_tolerance(self, tolerance: f64) -> Result<Self> {
        check_tolerance(tolerance)?;
        Ok(Self { tolerance, ..self })
    }

    /// The same options with another summation axis.
    #[must_use]
    pub fn with_axis(self, axis: SummationAxis) -> Self {
        Self { axis, ..self }
    }

    /// The same options with another term budget (`≥ 1`).
    ///
    /// # Errors
    /// [`Error::InvalidCount`] for 0.
    pub fn with_max_terms(self, max_terms: u64) -> Result<Self> {
        if max_terms == 0 {
            return Err(Error::InvalidCount {
                name: "max_terms",
                value: 0,
                reason: "a series needs at least one term",
            });
        }
        Ok(Self { max_terms, ..self })
    }
}

/// The Neumann Green function of a block, evaluated at points.
///
/// Units: `G` in m⁻¹, `∂G/∂z` in m⁻²; coordinates in m. The target is `r = (x, y, z)`,
/// the source `r' = (ξ, η, ζ)`; [`GreenFunction::dz`] differentiates with respect to the
/// target's `z`.
///
/// ```
/// use precursors::{green::GreenFunction, Block, Error, Point};
/// let green = GreenFunction::new(Block::new(0.010, 0.004, 0.005)?);   // 10 x 4 x 5 mm
/// let bottom = Point::new(3e-3, 1e-3, 0.0);              // on the bottom face (m)
/// let inside = Point::new(6e-3, 3e-3, 2e-3);             // 2 mm above it
/// let g = green.value(bottom, inside, 1e-8)?;            // G (m⁻¹) to 1e-8 m⁻¹
/// assert!(g.error <= 1e-8);
/// // G is symmetric in target and source...
/// assert!((g.value - green.value(inside, bottom, 1e-8)?.value).abs() < 2e-8);
/// // ...and satisfies the Neumann condition on the faces: ∂G/∂z = 0 at z = 0 (m⁻²).
/// assert!(green.dz(bottom, inside, 1e-6)?.value.abs() < 1e-6);
/// // It is singular where target and source coincide.
/// let e = green.value(inside, inside, 1e-8).unwrap_err();
/// assert!(matches!(e, Error::SingularPoint { .. }));
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GreenFunction {
    block: Block,
}

/// `Σ_{n≥1} cos(n π t / L)/(nπ/L)² = L²/6 - L t/2 + t²/4` for `0 ≤ t ≤ 2L`.
pub(crate) fn cos_sum_k2(l: f64, t: f64) -> f64 {
    l * l / 6.0 - l * t / 2.0 + t * t / 4.0
}

/// `Σ_{n≥1} sin(nθ)/n³ = π²θ/6 - πθ²/4 + θ³/12` for `0 ≤ θ ≤ 2π`.
pub(crate) fn sin_sum_n3(theta: f64) -> f64 {
    PI * PI * theta / 6.0 - PI * theta * theta / 4.0 + theta.powi(3) / 12.0
}

/// `Σ_{n≥1} cos(nθ)/n² = π²/6 - πθ/2 + θ²/4` for `0 ≤ θ ≤ 2π`.
pub(crate) fn cos_sum_n2(theta: f64) -> f64 {
    PI * PI / 6.0 - PI * theta / 2.0 + theta * theta / 4.0
}

/// Distance of `a` to the source `alpha` and to its mirror images across the faces of
/// `[0, l]`: the decay length of the closed-form sum along this axis.
fn image_distance(a: f64, alpha: f64, l: f64) -> f64 {
    let tp = a + alpha;
    (a - alpha).abs().min(tp).min(2.0 * l - tp)
}

impl GreenFunction {
    /// The Green function of `block`.
    pub fn new(block: Block) -> Self {
        Self { block }
    }

    /// The block.
    pub fn block(&self) -> &Block {
        &self.block
    }

    /// `G(r, r')` (m⁻¹) by the rapid representation, to absolute tolerance `tol` (m⁻¹).
    ///
    /// # Errors
    /// [`Error::InvalidTolerance`] for a `tol` that is not finite and `> 0`; otherwise as
    /// [`GreenFunction::value_with_options`].
    pub fn value(&self, target: Point, source: Point, tol: f64) -> Result<Estimate> {
        self.value_with_options(
            target,
            source,
            &SeriesOptions::default().with_tolerance(tol)?,
        )
    }

    /// `G(r, r')` (m⁻¹) by the rapid representation with explicit options.
    ///
    /// # Errors
    /// [`Error::OutsideBlock`] for a point outside the block; [`Error::SingularPoint`] when
    /// target and source coincide; [`Error::InvalidChoice`] for a forced axis along which
    /// they do not differ; [`Error::SeriesNotConverged`] past the term budget.
    pub fn value_with_options(
        &self,
        target: Point,
        source: Point,
        opts: &SeriesOptions,
    ) -> Result<Estimate> {
        self.rapid(target, source, opts, false)
    }

    /// `∂G/∂z (r, r')` (m⁻²), derivative in the target's height, to absolute tolerance `tol`.
    ///
    /// # Errors
    /// As [`GreenFunction::value`].
    pub fn dz(&self, target: Point, source: Point, tol: f64) -> Result<Estimate> {
        self.dz_with_options(
            target,
            source,
            &SeriesOptions::default().with_tolerance(tol)?,
        )
    }

    /// `∂G/∂z (r, r')` (m⁻²) with explicit options.
    ///
    /// # Errors
    /// As [`GreenFunction::value_with_options`].
    pub fn dz_with_options(
        &self,
        target: Point,
        source: Point,
        opts: &SeriesOptions,
    ) -> Result<Estimate> {
        self.rapid(target, source, opts, true)
    }

    fn check_points(&self, target: Point, source: Point) -> Result<()> {
        self.block.check_point(target, ["x", "y", "z"])?;
        self.block.check_point(source, ["xi", "eta", "zeta"])
    }

    fn rapid(
        &self,
        target: Point,
        source: Point,
        opts: &SeriesOptions,
        dz: bool,
    ) -> Result<Estimate> {
        self.check_points(target, source)?;
        let a = target.coords();
        let alpha = source.coords();
        let l = self.block.lengths();
        let d: [f64; 3] = std::array::from_fn(|k| image_distance(a[k], alpha[k], l[k]));
        let axis = match opts.axis {
            SummationAxis::X => 0,
            SummationAxis::Y => 1,
            SummationAxis::Z => 2,
            SummationAxis::Auto => {
                // Terms needed ~ L_u L_v / d_s² = V / (L_s d_s²): maximise L_s d_s².
                let score = |k: usize| l[k] * d[k] * d[k];
                (0..3)
                    .max_by(|&i, &j| score(i).total_cmp(&score(j)))
                    .unwrap_or(2)
            }
        };
        if d[axis] <= 0.0 {
            if d.iter().all(|&x| x <= 0.0) {
                return Err(Error::SingularPoint {
                    x: a[0],
                    y: a[1],
                    z: a[2],
                });
            }
            return Err(Error::InvalidChoice {
                name: "summation axis",
                value: ["x", "y", "z"][axis],
                reason: "the target has the source's coordinate along the summed axis, \
                         where that representation does not converge; use SummationAxis::Auto",
            });
        }
        partial_sum(&self.block, a, alpha, axis, dz, d[axis], opts)
    }

    /// `G(r, r')` (m⁻¹) by the raw triple cosine series (paper Eq. `green`), a reference.
    ///
    /// Box partial sums `p ≤ K Lx/π`, `m ≤ K Ly/π`, `n ≤ K Lz/π` with the wavenumber
    /// cut-off `K` doubled until two successive sums differ by less than `tol` (m⁻¹); that
    /// difference is the error estimate. It converges algebraically, and only where the
    /// target differs from the source in every coordinate; expect
    /// [`Error::SeriesNotConverged`] for tight tolerances.
    ///
    /// # Errors
    /// As [`GreenFunction::value_with_options`]; [`Error::SeriesNotConverged`] is common here.
    pub fn raw_series(
        &self,
        target: Point,
        source: Point,
        opts: &SeriesOptions,
    ) -> Result<Estimate> {
        self.check_points(target, source)?;
        let a = target.coords();
        let alpha = source.coords();
        let l = self.block.lengths();
        let v = self.block.volume();
        let mut k_cut = 8.0 * PI / l.iter().cloned().fold(f64::INFINITY, f64::min);
        let mut previous: Option<f64> = None;
        let mut terms = 0u64;
        loop {
            let counts: [usize; 3] = std::array::from_fn(|k| (k_cut * l[k] / PI).floor() as usize);
            let size = counts.iter().map(|&c| (c + 1) as u64).product::<u64>();
            if terms + size > opts.max_terms {
                let value = previous.unwrap_or(0.0);
                return Err(Error::SeriesNotConverged {
                    what: "raw triple cosine series of G",
                    value,
                    error: f64::INFINITY,
                    tolerance: opts.tolerance,
                    terms,
                });
            }
            // Per-axis tables of w_j cos(k_j a) cos(k_j α) and k_j².
            let tables: Vec<(Vec<f64>, Vec<f64>)> = (0..3)
                .map(|k| {
                    (0..=counts[k])
                        .map(|j| {
                            let kk = j as f64 * PI / l[k];
                            let w = if j == 0 { 0.5 } else { 1.0 };
                            (w * (kk * a[k]).cos() * (kk * alpha[k]).cos(), kk * kk)
                        })
                        .unzip()
                })
                .collect();
            let (cx, kx) = &tables[0];
            let (cy, ky) = &tables[1];
            let (cz, kz) = &tables[2];
            let mut sum = 0.0;
            for p in 0..cx.len() {
                for m in 0..cy.len() {
                    let cpm = cx[p] * cy[m];
                    let kpm = kx[p] + ky[m];
                    let mut inner = 0.0;
                    for n in 0..cz.len() {
                        let k2 = kpm + kz[n];
                        if k2 > 0.0 {
                            inner += cz[n] / k2;
                        }
                    }
                    sum += cpm * inner;
                }
            }
            terms += size;
            let value = 8.0 / v * sum;
            if let Some(prev) = previous {
                let error = (value - prev).abs();
                if error <= opts.tolerance {
                    return Ok(Estimate { value, error });
                }
            }
            previous = Some(value);
            k_cut *= 2.0;
        }
    }
}

/// The rapid representation with axis `s` summed in closed form.
///
/// `G = (8/V) [ ¼·½(f(t₋) + f(t₊)) + Σ_{(i,j)≠0} w_i w_j C_u(i) C_v(j) S(κ_ij) ]` with
/// `S(κ) = (L_s/4κ)[E(t₋) + E(t₊)]`, `E(t) = cosh κ(L_s - t)/sinh κL_s` written with
/// decaying exponentials, `t₋ = |a_s - α_s|`, `t₊ = a_s + α_s`, `f(t) = L²/6 - Lt/2 + t²/4`.
fn partial_sum(
    block: &Block,
    a: [f64; 3],
    alpha: [f64; 3],
    s: usize,
    dz: bool,
    d: f64,
    opts: &SeriesOptions,
) -> Result<Estimate> {
    let l = block.lengths();
    let v = block.volume();
    let (u, w) = match s {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let ls = l[s];
    let tm = (a[s] - alpha[s]).abs();
    let tp = a[s] + alpha[s];
    let sign = (a[s] - alpha[s]).signum();
    // Derivative on the summed axis (s = z) or on one of the cosine axes.
    let deriv_s = dz && s == 2;
    let deriv_u = dz && u == 2;
    let deriv_w = dz && w == 2;

    // Tail estimate: |term| <= (8/V) L_s e^{-κd} κ^{q-1} / (1 - e^{-2κL_s}), lattice
    // density ρ(κ) = A κ + B in the quarter plane of (k_u, k_v).
    let q = if dz { 1 } else { 0 };
    let dens_a = l[u] * l[w] / (2.0 * PI);
    let dens_b = (l[u] + l[w]) / (2.0 * PI);
    let tail = |k: f64| -> f64 {
        let e = (-k * d).exp();
        let c = 1.0 / (-(-2.0 * k * ls).exp_m1());
        let integral = if q == 0 {
            dens_a * e / d + dens_b * e / (k * d)
        } else {
            dens_a * e * (k / d + 1.0 / (d * d)) + dens_b * e / d
        };
        8.0 / v * ls * c * integral
    };
    let kmin = PI / l[u].max(l[w]);
    let mut k_cut = kmin;
    let mut guard = 0;
    while tail(k_cut) > opts.tolerance && guard < 400 {
        k_cut *= 1.1;
        guard += 1;
    }
    let est_terms =
        (l[u] * l[w] * k_cut * k_cut / (4.0 * PI) + k_cut * (l[u] + l[w]) / PI + 1.0) as u64;
    if est_terms > opts.max_terms || guard >= 400 {
        return Err(Error::SeriesNotConverged {
            what: "rapid representation of the Green function (nothing summed)",
            value: 0.0,
            error: tail(k_cut),
            tolerance: opts.tolerance,
            terms: est_terms,
        });
    }

    // (0,0) term: κ = 0, the closed-form n-sum without its n = 0 term.
    let zero_term = if deriv_s {
        0.5 * ((-ls / 2.0 + tm / 2.0) * sign + (-ls / 2.0 + tp / 2.0))
    } else if dz {
        0.0 // the (0,0) term does not depend on z when z is a cosine axis
    } else {
        0.5 * (cos_sum_k2(ls, tm) + cos_sum_k2(ls, tp))
    };
    let mut sum = 0.25 * zero_term;

    let jmax = (k_cut * l[w] / PI).floor() as usize;
    let cw: Vec<(f64, f64)> = (0..=jmax)
        .map(|j| {
            let k = j as f64 * PI / l[w];
            let weight = if j == 0 { 0.5 } else { 1.0 };
            let c = if deriv_w {
                -k * (k * a[w]).sin() * (k * alpha[w]).cos()
            } else {
                (k * a[w]).cos() * (k * alpha[w]).cos()
            };
            (weight * c, k)
        })
        .collect();
    let imax = (k_cut * l[u] / PI).floor() as usize;
    for i in 0..=imax {
        let ku = i as f64 * PI / l[u];
        let weight = if i == 0 { 0.5 } else { 1.0 };
        let cu = weight
            * if deriv_u {
                -ku * (ku * a[u]).sin() * (ku * alpha[u]).cos()
            } else {
                (ku * a[u]).cos() * (ku * alpha[u]).cos()
            };
        if cu == 0.0 {
            continue;
        }
        let kv_max2 = k_cut * k_cut - ku * ku;
        for &(cv, kv) in &cw {
            if kv * kv > kv_max2 {
                break;
            }
            if i == 0 && kv == 0.0 {
                continue;
            }
            let kappa = (ku * ku + kv * kv).sqrt();
            let den = -(-2.0 * kappa * ls).exp_m1();
            let e = |t: f64| (-kappa * t).exp();
            let closed = if deriv_s {
                // d/da_s of (L/4κ)[cosh κ(L-t₋) + cosh κ(L-t₊)]/sinh κL
                -(ls / 4.0) * (sign * (e(tm) - e(2.0 * ls - tm)) + (e(tp) - e(2.0 * ls - tp))) / den
            } else {
                ls / (4.0 * kappa) * (e(tm) + e(2.0 * ls - tm) + e(tp) + e(2.0 * ls - tp)) / den
            };
            sum += cu * cv * closed;
        }
    }
    Ok(Estimate {
        value: 8.0 / v * sum,
        error: tail(k_cut),
    })
}

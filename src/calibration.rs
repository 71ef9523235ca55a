//! Fitting the model's two adjustable constants to measurements (paper Suppl. "Model
//! calibration"):
//!
//! * [`fit_normal_stiffness`]: `c_z` (N/m²) such that the real contact area at zero shear,
//!   averaged over height realizations, equals a target `A_R = α F_N` (a bracketing root
//!   search in `ln c_z`: the area falls monotonically as the springs stiffen);
//! * [`fit_tangential_stiffness`]: `c_x` (N/m³) minimising the squared misfit between the
//!   precursor curve `ℓ(F)` averaged over realizations and target points (a scan of a
//!   logarithmic grid refined by golden sections: `ℓ` is a multiple of `Δx`, so the
//!   misfit is piecewise constant and a derivative-based method would stall).
//!
//! ```
//! use precursors::calibration::{fit_normal_stiffness, normal_contact_area, FitOptions};
//! use precursors::{Scene, SpringLaw};
//! let base = Scene::builder().block(0.020, 0.004, 0.010).normal_load(100.0);
//! let options = FitOptions::default().with_seeds(&[1, 2]);
//! // A target made with c_z = 3e8 N/m² is recovered.
//! let law = SpringLaw::default().with_c_z(3e8)?;
//! let target = normal_contact_area(&base.clone().springs(law), &options)?;
//! let fit = fit_normal_stiffness(&base, target, (1e7, 1e10), &options)?;
//! assert!((fit.value / 3e8 - 1.0).abs() < 1e-6);
//! # Ok::<(), precursors::Error>(())
//! ```

use crate::driver::Event;
use crate::error::{check_tolerance, Error, Result};
use crate::green::Planner;
use crate::scene::SceneBuilder;

/// Options of the fits.
///
/// The fields are private: options are valid by construction (the defaults, then the
/// `with_` modifiers).
///
/// ```
/// use precursors::calibration::FitOptions;
/// let options = FitOptions::default().with_seeds(&[1, 2]).with_tolerance(1e-3)?;
/// assert_eq!((options.seeds(), options.tolerance()), (&[1, 2][..], 1e-3));
/// assert!(FitOptions::default().with_scan_points(2).is_err());
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct FitOptions {
    seeds: Vec<u64>,
    tolerance: f64,
    max_evaluations: usize,
    scan_points: usize,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            seeds: Vec::new(),
            tolerance: 1e-8,
            max_evaluations: 200,
            scan_points: 17,
        }
    }
}

impl FitOptions {
    /// Seeds of the height realizations averaged over (the builder's random heights, paper
    /// Gaussian or a random surface, with each seed; the paper's Gaussian heights when
    /// the builder's are given values); empty: the builder's own heights only (default).
    pub fn seeds(&self) -> &[u64] {
        &self.seeds
    }

    /// Relative accuracy of the fitted constant (dimensionless, default `1e-8`).
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// Largest number of model evaluations (default `200`).
    pub fn max_evaluations(&self) -> usize {
        self.max_evaluations
    }

    /// Points of the logarithmic scan of [`fit_tangential_stiffness`] (default `17`, at
    /// least 3).
    pub fn scan_points(&self) -> usize {
        self.scan_points
    }

    /// The same options with these realizations.
    #[must_use]
    pub fn with_seeds(mut self, seeds: &[u64]) -> Self {
        self.seeds = seeds.to_vec();
        self
    }

    /// The same options with another relative accuracy of the constant (dimensionless,
    /// finite and `> 0`).
    ///
    /// # Errors
    /// [`Error::InvalidTolerance`] for a tolerance that is not finite and `> 0`.
    pub fn with_tolerance(self, tolerance: f64) -> Result<Self> {
        check_tolerance(tolerance)?;
        Ok(Self { tolerance, ..self })
    }

    /// The same options with another evaluation budget (`≥ 1`).
    ///
    /// # Errors
    /// [`Error::InvalidCount`] for 0.
    pub fn with_max_evaluations(self, max_evaluations: usize) -> Result<Self> {
        if max_evaluations == 0 {
            return Err(Error::InvalidCount {
                name: "max_evaluations",
                value: 0,
                reason: "a fit needs at least one model evaluation",
            });
        }
        Ok(Self {
            max_evaluations,
            ..self
        })
    }

    /// The same options with another scan size (`≥ 3`).
    ///
    /// # Errors
    /// [`Error::InvalidCount`] for fewer than 3 points.
    pub fn with_scan_points(self, scan_points: usize) -> Result<Self> {
        if scan_points < 3 {
            return Err(Error::InvalidCount {
                name: "scan_points",
                value: scan_points as u64,
                reason: "the scan needs at least 3 points to bracket a minimum",
            });
        }
        Ok(Self {
            scan_points,
            ..self
        })
    }
}

/// A fitted constant.
///
/// ```
/// use precursors::calibration::{fit_normal_stiffness, FitOptions};
/// use precursors::{Error, Scene};
/// // 10 x 4 mm of the paper's PMMA under 100 N, one realization of the heights.
/// let base = Scene::builder().block(0.010, 0.004, 0.010).normal_load(100.0).seed(3);
/// let options = FitOptions::default().with_tolerance(1e-6)?;
/// // c_z (N/m²) such that A_R = 12 mm² at zero shear (the paper's α F_N).
/// let target = 12e-6;                                            // m²
/// let fit = fit_normal_stiffness(&base, target, (1e6, 1e11), &options)?;
/// assert!(fit.value > 1e6 && fit.value < 1e11);                  // N/m²
/// assert!(fit.misfit.abs() < 1e-6 * target);                     // area - target (m²)
/// assert!(fit.evaluations <= options.max_evaluations());
/// // A bracket whose ends give areas on the same side of the target is refused.
/// let e = fit_normal_stiffness(&base, target, (1e10, 1e11), &options).unwrap_err();
/// assert!(matches!(e, Error::InvalidParameter { .. }));
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Fit {
    /// The constant (N/m² for `c_z`, N/m³ for `c_x`).
    pub value: f64,
    /// The misfit there: area minus target (m²) for `c_z`; mean squared length misfit
    /// (m²) for `c_x`.
    pub misfit: f64,
    /// Model evaluations spent (each over every realization).
    pub evaluations: usize,
}

/// The builders of the realizations.
fn realizations(builder: &SceneBuilder, options: &FitOptions) -> Vec<SceneBuilder> {
    if options.seeds.is_empty() {
        return vec![builder.clone()];
    }
    let source = builder.current_heights();
    options
        .seeds
        .iter()
        // `seed` too: a seed given to the builder would otherwise reseed the source.
        .map(|&seed| builder.clone().heights(source.reseeded(seed)).seed(seed))
        .collect()
}

fn check_bracket(name: &'static str, bracket: (f64, f64)) -> Result<()> {
    let (lo, hi) = bracket;
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
        return Err(Error::InvalidParameter {
            name,
            value: lo,
            reason: "the bracket must be finite with 0 < low < high",
        });
    }
    Ok(())
}

/// The real contact area at zero shear (m²), averaged over the realizations of
/// `options`.
///
/// With no seeds, the builder's own heights: the area its driver reaches at the first
/// stable state.
///
/// ```
/// use precursors::calibration::{normal_contact_area, FitOptions};
/// use precursors::Scene;
/// let builder = Scene::builder().block(0.020, 0.004, 0.010).normal_load(100.0);
/// let area = normal_contact_area(&builder, &FitOptions::default())?;
/// let mut driver = builder.clone().build()?.driver()?;
/// driver.step()?;
/// assert_eq!(area, driver.real_contact_area()?);         // A_R (m²)
/// // Two realizations: the mean of their areas.
/// let two = normal_contact_area(&builder, &FitOptions::default().with_seeds(&[1, 2]))?;
/// assert!(two > 0.0 && two < 0.020 * 0.004);
/// # Ok::<(), precursors::Error>(())
/// ```
///
/// # Errors
/// Those of
/// [`SceneBuilder::build`](crate::SceneBuilder::build) and of the normal solve
/// ([`Error::SolverNotConverged`], [`Error::EmptyContact`], ...).
pub fn normal_contact_area(builder: &SceneBuilder, options: &FitOptions) -> Result<f64> {
    normal_area_with(builder, options, &Planner::new())
}

/// [`normal_contact_area`] with plans from `planner` (a fit plans its geometry once).
fn normal_area_with(
    builder: &SceneBuilder,
    options: &FitOptions,
    planner: &Planner,
) -> Result<f64> {
    let scenes = realizations(builder, options);
    let mut total = 0.0;
    for b in &scenes {
        let scene = b.clone().build_with_planner(planner)?;
        let mut driver = scene.driver()?;
        driver.step()?;
        total += driver.real_contact_area()?;
    }
    Ok(total / scenes.len() as f64)
}

/// `c_z` (N/m²) in `bracket` such that the mean real contact area at zero shear is
/// `target_area` (m², the paper's `α F_N`). Errors: [`Error::InvalidParameter`] when the
/// bracket does not enclose the target (with the areas at its ends in the message's
/// value), [`Error::FitNotConverged`] past `max_evaluations`.
///
/// The module's example recovers a `c_z`; a bracket that does not enclose the target is
/// refused:
///
/// ```
/// use precursors::calibration::{fit_normal_stiffness, FitOptions};
/// use precursors::{Error, Scene};
/// let base = Scene::builder().block(0.020, 0.004, 0.010).normal_load(100.0);
/// // An area larger than the block's face (m²) no stiffness reaches.
/// let e = fit_normal_stiffness(&base, 1.0, (1e7, 1e10), &FitOptions::default());
/// assert!(matches!(e, Err(Error::InvalidParameter { .. })));
/// # Ok::<(), precursors::Error>(())
/// ```
///
/// # Errors
/// [`Error::InvalidParameter`] for a target area that is not finite and `> 0`, a bracket
/// that is not `0 < low < high` or does not enclose the target; [`Error::FitNotConverged`]
/// past `max_evaluations`; those of [`normal_contact_area`]; [`Error::InvalidChoice`]
/// (`maps.c_z`) for a scene with a map of `c_z`, which the scalar fitted would not change.
pub fn fit_normal_stiffness(
    builder: &SceneBuilder,
    target_area: f64,
    bracket: (f64, f64),
    options: &FitOptions,
) -> Result<Fit> {
    check_bracket("c_z bracket (N/m²)", bracket)?;
    refuse_map(builder, 2)?;
    if !(target_area.is_finite() && target_area > 0.0) {
        return Err(Error::InvalidParameter {
            name: "target_area (m²)",
            value: target_area,
            reason: "the target real contact area must be finite and > 0",
        });
    }
    let mut evaluations = 0;
    let planner = Planner::new(); // every evaluation shares the geometry's plan
    let misfit = |ln_cz: f64, evaluations: &mut usize| -> Result<f64> {
        *evaluations += 1;
        let law = builder.current_springs().with_c_z(ln_cz.exp())?;
        Ok(normal_area_with(&builder.clone().springs(law), options, &planner)? - target_area)
    };
    let (mut a, mut b) = (bracket.0.ln(), bracket.1.ln());
    let mut fa = misfit(a, &mut evaluations)?;
    let mut fb = misfit(b, &mut evaluations)?;
    for (x, f) in [(a, fa), (b, fb)] {
        if f == 0.0 {
            return Ok(Fit {
                value: x.exp(),
                misfit: 0.0,
                evaluations,
            });
        }
    }
    if fa.signum() == fb.signum() {
        return Err(Error::InvalidParameter {
            name: "c_z bracket: area misfit at its low end (m²)",
            value: fa,
            reason: "the target area is not between the areas at the bracket's ends",
        });
    }
    // Illinois regula falsi in ln c_z: superlinear on this smooth monotone misfit, never
    // leaves the bracket, and shrinks it from both sides.
    let mut side = 0i8;
    loop {
        let c = (a * fb - b * fa) / (fb - fa);
        let fc = misfit(c, &mut evaluations)?;
        if fc.signum() == fb.signum() {
            b = c;
            fb = fc;
            if side == -1 {
                fa /= 2.0;
            }
            side = -1;
        } else {
            a = c;
            fa = fc;
            if side == 1 {
                fb /= 2.0;
            }
            side = 1;
        }
        if fc == 0.0 || (b - a).abs() <= options.tolerance {
            return Ok(Fit {
                value: c.exp(),
                misfit: fc,
                evaluations,
            });
        }
        if evaluations >= options.max_evaluations {
            return Err(Error::FitNotConverged {
                value: c.exp(),
                width: (b - a).abs(),
                tolerance: options.tolerance,
                evaluations,
            });
        }
    }
}

/// The precursor curve of one scene: `(F, ℓ)` (N, m) at every stable state up to global
/// slip.
///
/// ```
/// use precursors::calibration::{length_at, precursor_curve};
/// use precursors::Scene;
/// let builder = Scene::builder().block(0.020, 0.004, 0.010).normal_load(100.0);
/// let curve = precursor_curve(&builder)?;                 // (F in N, ℓ in m)
/// assert!(curve.windows(2).all(|w| w[0].0 <= w[1].0));   // the load only grows
/// assert!(curve.iter().all(|&(_, l)| (0.0..=0.020).contains(&l)));
/// let (f, l) = curve[curve.len() / 2];
/// assert_eq!(length_at(&curve, f), l);
/// assert_eq!(length_at(&curve, -1.0), 0.0);               // before the first state
/// # Ok::<(), precursors::Error>(())
/// ```
///
/// # Errors
/// Those of [`SceneBuilder::build`](crate::SceneBuilder::build) and of the run
/// ([`Driver::step`](crate::Driver::step)).
pub fn precursor_curve(builder: &SceneBuilder) -> Result<Vec<(f64, f64)>> {
    curve_with(builder, &Planner::new())
}

/// [`precursor_curve`] with the plan from `planner`.
fn curve_with(builder: &SceneBuilder, planner: &Planner) -> Result<Vec<(f64, f64)>> {
    let scene = builder.clone().build_with_planner(planner)?;
    let mut driver = scene.driver()?;
    let mut curve = Vec::new();
    while let Some(event) = driver.step()? {
        if let Event::Stable { load, .. } = event {
            curve.push((load.force, driver.precursor_length()?));
        }
    }
    Ok(curve)
}

/// `ℓ` (m) at force `force` (N) on a curve from [`precursor_curve`]: the value of the last
/// stable state at or below the force (the state holds until the next threshold).
///
/// ```
/// use precursors::calibration::length_at;
/// let curve = [(1.0, 0.0), (2.0, 3e-3), (4.0, 5e-3)];     // (F in N, ℓ in m)
/// assert_eq!(length_at(&curve, 3.0), 3e-3);
/// assert_eq!(length_at(&curve, 0.5), 0.0);
/// ```
pub fn length_at(curve: &[(f64, f64)], force: f64) -> f64 {
    curve
        .iter()
        .take_while(|(f, _)| *f <= force)
        .last()
        .map_or(0.0, |(_, l)| *l)
}

/// Mean squared misfit (m²) of the realization-averaged precursor curve against the
/// target points `(F, ℓ)` (N, m).
///
/// A curve's own points are matched exactly:
///
/// ```
/// use precursors::calibration::{precursor_curve, precursor_misfit, FitOptions};
/// use precursors::Scene;
/// let builder = Scene::builder().block(0.020, 0.004, 0.010).normal_load(100.0);
/// let curve = precursor_curve(&builder)?;
/// assert_eq!(precursor_misfit(&builder, &curve, &FitOptions::default())?, 0.0);
/// let off: Vec<_> = curve.iter().map(|&(f, l)| (f, l + 1e-3)).collect();
/// assert!((precursor_misfit(&builder, &off, &FitOptions::default())? - 1e-6).abs() < 1e-12);
/// # Ok::<(), precursors::Error>(())
/// ```
///
/// # Errors
/// [`Error::EmptyInput`] with no target point; [`Error::NonFinite`] for a target point
/// that is not finite and `>= 0`; those of building and running the scenes.
pub fn precursor_misfit(
    builder: &SceneBuilder,
    targets: &[(f64, f64)],
    options: &FitOptions,
) -> Result<f64> {
    check_targets(targets)?;
    misfit_with(builder, targets, options, &Planner::new())
}

/// At least one target point, each finite and `>= 0`.
fn check_targets(targets: &[(f64, f64)]) -> Result<()> {
    if targets.is_empty() {
        return Err(Error::EmptyInput {
            what: "targets (points (F, ℓ) of a precursor curve)",
            reason: "the misfit is a mean over the target points: give at least one",
        });
    }
    for (i, &(f, l)) in targets.iter().enumerate() {
        if !(f.is_finite() && l.is_finite() && f >= 0.0 && l >= 0.0) {
            return Err(Error::NonFinite {
                name: "targets (F in N, ℓ in m: finite and >= 0)",
                index: i,
                value: if f.is_finite() { l } else { f },
            });
        }
    }
    Ok(())
}

/// [`precursor_misfit`] with plans from `planner`.
fn misfit_with(
    builder: &SceneBuilder,
    targets: &[(f64, f64)],
    options: &FitOptions,
    planner: &Planner,
) -> Result<f64> {
    let scenes = realizations(builder, options);
    let curves = scenes
        .iter()
        .map(|b| curve_with(b, planner))
        .collect::<Result<Vec<_>>>()?;
    let mut sum = 0.0;
    for &(force, ell) in targets {
        let model = curves.iter().map(|c| length_at(c, force)).sum::<f64>() / curves.len() as f64;
        sum += (model - ell).powi(2);
    }
    Ok(sum / targets.len() as f64)
}

/// `c_x` (N/m³) in `bracket` minimising [`precursor_misfit`] against `targets` (points
/// `(F, ℓ)` in N and m, read off a measured precursor curve). A logarithmic scan of
/// `scan_points` values, then golden sections around the best one down to the relative
/// `tolerance` (or `max_evaluations`). Among equally good values (the misfit is piecewise
/// constant) the one found first is kept.
///
/// A curve made with `c_x = 2e11` N/m³ is recovered to the options' tolerance (the misfit
/// is piecewise constant, so the fit returns a value near the target's, not the target):
///
/// ```
/// use precursors::calibration::{fit_tangential_stiffness, precursor_curve, FitOptions};
/// use precursors::{Scene, SpringLaw};
/// let base = Scene::builder().block(0.020, 0.004, 0.010).normal_load(100.0);
/// let law = SpringLaw::default().with_c_x(2e11)?;
/// let targets = precursor_curve(&base.clone().springs(law))?;
/// let options = FitOptions::default().with_tolerance(1e-2)?;
/// let fit = fit_tangential_stiffness(&base, &targets, (1e10, 1e13), &options)?;
/// // Found within the relative tolerance's reach of 2e11, the lengths within a fraction of
/// // a 1 mm cell (misfit in m²).
/// assert!((fit.value / 2e11 - 1.0).abs() < 0.05);
/// assert!(fit.misfit < 0.1 * 1e-3 * 1e-3);
/// # Ok::<(), precursors::Error>(())
/// ```
///
/// # Errors
/// [`Error::InvalidParameter`] for a bracket that is not `0 < low < high`; those of
/// [`precursor_misfit`]; [`Error::InvalidChoice`] (`maps.c_x`) for a scene with a map of
/// `c_x`, which the scalar fitted would not change.
pub fn fit_tangential_stiffness(
    builder: &SceneBuilder,
    targets: &[(f64, f64)],
    bracket: (f64, f64),
    options: &FitOptions,
) -> Result<Fit> {
    check_bracket("c_x bracket (N/m³)", bracket)?;
    refuse_map(builder, 1)?;
    check_targets(targets)?;
    let mut evaluations = 0;
    let planner = Planner::new(); // every evaluation shares the geometry's plan
    let misfit = |ln_cx: f64, evaluations: &mut usize| -> Result<f64> {
        *evaluations += 1;
        let law = builder.current_springs().with_c_x(ln_cx.exp())?;
        misfit_with(&builder.clone().springs(law), targets, options, &planner)
    };
    let (lo, hi) = (bracket.0.ln(), bracket.1.ln());
    let k = options.scan_points;
    let grid: Vec<f64> = (0..k)
        .map(|i| lo + (hi - lo) * i as f64 / (k - 1) as f64)
        .collect();
    let mut values = Vec::with_capacity(k);
    for &x in &grid {
        values.push(misfit(x, &mut evaluations)?);
    }
    let best = (0..k)
        .min_by(|&i, &j| values[i].total_cmp(&values[j]))
        .unwrap_or(0);
    let (mut best_x, mut best_f) = (grid[best], values[best]);
    let (mut a, mut b) = (grid[best.saturating_sub(1)], grid[(best + 1).min(k - 1)]);
    let ratio = 0.5 * (5f64.sqrt() - 1.0);
    // Golden sections: the interior point kept from the last step is reused, so each
    // step evaluates one new point.
    let mut c = b - ratio * (b - a);
    let mut d = a + ratio * (b - a);
    let mut fc = None;
    let mut fd = None;
    while b - a > options.tolerance && best_f > 0.0 {
        if evaluations >= options.max_evaluations {
            break;
        }
        let (vc, vd) = match (fc, fd) {
            (Some(vc), Some(vd)) => (vc, vd),
            (Some(vc), None) => (vc, misfit(d, &mut evaluations)?),
            (None, Some(vd)) => (misfit(c, &mut evaluations)?, vd),
            (None, None) => (misfit(c, &mut evaluations)?, misfit(d, &mut evaluations)?),
        };
        for (x, f) in [(c, vc), (d, vd)] {
            if f < best_f {
                best_x = x;
                best_f = f;
            }
        }
        if vc <= vd {
            // Keep [a, d]: the old c becomes the new d.
            b = d;
            d = c;
            fd = Some(vc);
            c = b - ratio * (b - a);
            fc = None;
        } else {
            // Keep [c, b]: the old d becomes the new c.
            a = c;
            c = d;
            fc = Some(vd);
            d = a + ratio * (b - a);
            fd = None;
        }
    }
    Ok(Fit {
        value: best_x.exp(),
        misfit: best_f,
        evaluations,
    })
}

/// Refuses a fit of the scalar that the builder's map `k` (the order of the scene's
/// `maps`: μ, `c_x`, `c_z`) replaces: every evaluation would give the same scene.
fn refuse_map(builder: &SceneBuilder, k: usize) -> Result<()> {
    if builder.current_maps().0[k].is_some() {
        return Err(Error::InvalidChoice {
            name: ["maps.friction_coefficient", "maps.c_x", "maps.c_z"][k],
            value: "a map",
            reason: match k {
                1 => {
                    "fit_tangential_stiffness fits the scalar c_x, which the scene's map of \
                      c_x replaces: fit on the scene without the map"
                }
                _ => {
                    "fit_normal_stiffness fits the scalar c_z, which the scene's map of c_z \
                      replaces: fit on the scene without the map"
                }
            },
        });
    }
    Ok(())
}

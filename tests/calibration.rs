//! Calibration: the fits recover constants from data the crate generated with known
//! constants (the reference is the generating value), and refuse bad input.

use precursors::calibration::*;
use precursors::*;

fn base() -> SceneBuilder {
    Scene::builder()
        .block(0.040, 0.004, 0.020)
        .cells(40, 4)
        .normal_load(400.0)
        .drive(Drive::Force(ForceLoad::Lateral(Lateral::Rod {
            height: 3e-3,
            half_width: 1e-3,
        })))
}

fn with_law(c_x: f64, c_z: f64) -> SceneBuilder {
    base().springs(SpringLaw::new(c_x, c_z).unwrap())
}

#[test]
fn normal_stiffness_is_recovered_over_realizations() {
    let options = FitOptions::default().with_seeds(&[3, 4, 5]);
    let truth = 4.2e8;
    let target = normal_contact_area(&with_law(1.65e12, truth), &options).unwrap();
    let fit = fit_normal_stiffness(&base(), target, (1e6, 1e11), &options).unwrap();
    assert!((fit.value / truth - 1.0).abs() < 1e-6, "{fit:?}");
    assert!(fit.misfit.abs() < 1e-9 * target);
    eprintln!("c_z fit: {fit:?}");
    // The area falls as the springs stiffen (why the bracketing search is safe).
    let soft = normal_contact_area(&with_law(1.65e12, 1e8), &options).unwrap();
    let stiff = normal_contact_area(&with_law(1.65e12, 1e9), &options).unwrap();
    assert!(soft > target && target > stiff);
}

/// A fit that runs out of evaluations says so in its own variant (not a series' nor a
/// solver's): three evaluations (the bracket's ends and one step) cannot narrow the
/// bracket `[1e6, 1e11]` to a relative `1e-12`.
#[test]
fn a_fit_out_of_evaluations_is_fit_not_converged() {
    let options = FitOptions::default()
        .with_seeds(&[3])
        .with_tolerance(1e-12)
        .unwrap()
        .with_max_evaluations(3)
        .unwrap();
    let target = normal_contact_area(&with_law(1.65e12, 4.2e8), &options).unwrap();
    let e = fit_normal_stiffness(&base(), target, (1e6, 1e11), &options).unwrap_err();
    match e {
        Error::FitNotConverged {
            value,
            width,
            tolerance,
            evaluations,
        } => {
            assert_eq!(evaluations, 3);
            assert_eq!(tolerance, 1e-12);
            assert!((1e6..=1e11).contains(&value), "{value}");
            // The bracket in ln c_z is narrower than at the start, wider than asked.
            assert!(width > 1e-12 && width < (1e11f64 / 1e6).ln(), "{width}");
        }
        other => panic!("expected Error::FitNotConverged, got {other:?}"),
    }
}

#[test]
fn tangential_stiffness_is_recovered_from_a_generated_curve() {
    let options = FitOptions::default()
        .with_seeds(&[1, 2])
        .with_tolerance(1e-3)
        .unwrap();
    let truth = 1.65e12;
    let generating = with_law(truth, 1.65e8);
    // Target points: the generated, realization-averaged curve at a few forces.
    let curves: Vec<_> = [1u64, 2]
        .iter()
        .map(|&s| precursor_curve(&generating.clone().seed(s)).unwrap())
        .collect();
    let mu_fn = 0.5 * 400.0;
    let targets: Vec<(f64, f64)> = [0.3, 0.5, 0.7, 0.85, 0.95]
        .iter()
        .map(|r| {
            let f = r * mu_fn;
            (f, curves.iter().map(|c| length_at(c, f)).sum::<f64>() / 2.0)
        })
        .collect();
    assert!(targets.iter().any(|t| t.1 > 0.0), "{targets:?}");
    let fit = fit_tangential_stiffness(&with_law(1.0e12, 1.65e8), &targets, (1e11, 1e13), &options)
        .unwrap();
    eprintln!("c_x fit: {fit:?}, targets {targets:?}");
    assert_eq!(fit.misfit, 0.0);
    assert!((fit.value / truth).ln().abs() < 0.1, "{fit:?}");
}

#[test]
fn bad_calibration_input_is_refused() {
    let options = FitOptions::default();
    assert!(matches!(
        fit_normal_stiffness(&base(), 1e-6, (1e9, 1e8), &options),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(matches!(
        fit_normal_stiffness(&base(), -1.0, (1e7, 1e9), &options),
        Err(Error::InvalidParameter { .. })
    ));
    // A target no c_z in the bracket reaches.
    assert!(matches!(
        fit_normal_stiffness(&base(), 1.0, (1e7, 1e9), &options),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(matches!(
        fit_tangential_stiffness(&base(), &[], (1e11, 1e13), &options),
        Err(Error::EmptyInput { .. })
    ));
    // A scan of fewer than three points is refused (it was silently raised to three).
    assert!(matches!(
        options.clone().with_scan_points(2),
        Err(Error::InvalidCount {
            name: "scan_points",
            value: 2,
            ..
        })
    ));
    // The misfit of no target point is refused, not NaN (0/0).
    assert!(matches!(
        precursor_misfit(&base(), &[], &options),
        Err(Error::EmptyInput { .. })
    ));
    assert!(matches!(
        precursor_misfit(&base(), &[(1.0, f64::INFINITY)], &options),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        fit_tangential_stiffness(&base(), &[(f64::NAN, 0.0)], (1e11, 1e13), &options),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        options.clone().with_tolerance(0.0),
        Err(Error::InvalidTolerance { .. })
    ));
}

//! Runs to global slip event by event, and the dense and spectral backends compared on
//! them (tests/maps.rs, tests/contact_rules.rs).

use precursors::solver::{Backend, SolverOptions};
use precursors::{Driver, Event, Scene, SceneBuilder};
use proptest::prelude::*;

/// The events of a run to global slip, each with what `look` reads of the state right
/// after it; at most 20 000 events (a run that does not end fails).
pub fn run<T>(scene: &Scene, mut look: impl FnMut(&Event, &Driver) -> T) -> Vec<(Event, T)> {
    let mut driver = scene.driver().unwrap();
    let mut out = Vec::new();
    while let Some(event) = driver.step().unwrap() {
        let seen = look(&event, &driver);
        out.push((event, seen));
        assert!(out.len() < 20_000, "no global slip after 20 000 events");
    }
    assert!(matches!(out.last(), Some((Event::GlobalSlip { .. }, _))));
    out
}

/// An event's kind, its site (for a rupture, an attachment, a detachment) and the load
/// (N) right after it.
type Step = (&'static str, Option<usize>, f64);

/// The events of a run of `builder`'s scene on `backend`: kinds and sites, and the loads.
fn events_on(builder: SceneBuilder, backend: Backend) -> Vec<Step> {
    let options = SolverOptions::default().with_backend(backend).unwrap();
    let scene = builder.solver_options(options).build().unwrap();
    run(&scene, |_, d| d.force())
        .into_iter()
        .map(|(e, force)| {
            let site = match e {
                Event::Rupture { site, .. } | Event::Attach { site } | Event::Detach { site } => {
                    Some(site.index)
                }
                _ => None,
            };
            (e.kind(), site, force)
        })
        .collect()
}

/// `builder`'s scene gives the same events on the dense and the spectral backends, in
/// order, with the same loads to 1e-8 of the larger of the load and `scale` (N, the
/// loads' scale `μ F_N`: the solves agree to their tolerance relative to it, so a load
/// far below it, an early threshold of a few mN, is compared to 1e-8 of it, not of
/// itself).
pub fn backends_agree(builder: SceneBuilder, scale: f64) -> Result<(), TestCaseError> {
    let dense = events_on(builder.clone(), Backend::Dense);
    let spectral = events_on(builder, Backend::Spectral);
    prop_assert_eq!(dense.len(), spectral.len());
    for (d, s) in dense.iter().zip(&spectral) {
        prop_assert_eq!((d.0, d.1), (s.0, s.1));
        prop_assert!(
            (d.2 - s.2).abs() <= 1e-8 * d.2.abs().max(scale),
            "{:?} {:?}",
            d,
            s
        );
    }
    Ok(())
}

/// Force balance in the state right after `event` (`what` names the case in failures):
/// the springs' shear tractions carry the load, `ΔA Σ φ_x = -F` to 1e-9 of the terms'
/// size, and their normal tractions the normal load, `ΔA Σ φ_z = F_N` to 1e-9 (`cell`
/// the cell area ΔA in m², `f_n` in N). The tractions `(φ_x, φ_z)` in Pa are returned for
/// the caller's own checks.
pub fn assert_balanced(
    driver: &Driver,
    event: &Event,
    (cell, f_n): (f64, f64),
    what: &str,
) -> (Vec<f64>, Vec<f64>) {
    let force = driver.force();
    let phi_x = driver.shear_traction().unwrap().to_vec();
    let phi_z = driver.normal_traction().unwrap().to_vec();
    let scale: f64 = cell * phi_x.iter().map(|p| p.abs()).sum::<f64>() + force.abs();
    let carried: f64 = cell * phi_x.iter().sum::<f64>();
    assert!(
        (carried + force).abs() <= 1e-9 * scale + 1e-12,
        "{what}: {event:?}: ΔA Σφ_x = {carried:e}, F = {force:e}"
    );
    let normal: f64 = cell * phi_z.iter().sum::<f64>();
    assert!((normal - f_n).abs() <= 1e-9 * f_n, "{what}: {normal} N");
    (phi_x, phi_z)
}

//! Times the two calibration fits on a 70 x 7 x 75 mm block (1 mm cells, 1.7 kN, rod at
//! 6 mm): `c_z` from the zero-shear contact area over three height realizations, and
//! `c_x` from five points of a precursor curve over two, both generated with known
//! constants (the paper's), so the fits also show they recover them; then `c_x` from the
//! same points perturbed (ℓ x 1.05 + 0.5 mm, as a measured curve the model cannot match
//! exactly: the golden sections then run down to the tolerance).
//!
//! Run: `cargo run --release --example calibration_fit` (docs/performance.md).

use precursors::calibration::{
    fit_normal_stiffness, fit_tangential_stiffness, length_at, normal_contact_area,
    precursor_curve, FitOptions,
};
use precursors::{Scene, SceneBuilder, SpringLaw};
use std::time::Instant;

fn base(law: SpringLaw) -> SceneBuilder {
    Scene::builder()
        .block(0.070, 0.007, 0.075)
        .cell_size(1e-3, 1e-3)
        .normal_load(1750.0)
        .springs(law)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let truth = SpringLaw::default();
    let options = FitOptions::default().with_seeds(&[1, 2, 3]);
    let target = normal_contact_area(&base(truth), &options)?;
    let start_law = truth.with_c_z(1e7)?;
    let clock = Instant::now();
    let fit = fit_normal_stiffness(&base(start_law), target, (1e7, 1e10), &options)?;
    println!(
        "c_z fit: {:.6e} N/m² (truth {:.6e}), {} evaluations, {:.2} s",
        fit.value,
        truth.c_z(),
        fit.evaluations,
        clock.elapsed().as_secs_f64()
    );
    let options = FitOptions::default()
        .with_seeds(&[1, 2])
        .with_tolerance(1e-3)?;
    let curves = [1u64, 2]
        .iter()
        .map(|&s| precursor_curve(&base(truth).seed(s)))
        .collect::<Result<Vec<_>, _>>()?;
    let mu_fn = 0.5 * 1750.0;
    let targets: Vec<(f64, f64)> = [0.3, 0.5, 0.7, 0.85, 0.95]
        .iter()
        .map(|r| {
            let f = r * mu_fn;
            (f, curves.iter().map(|c| length_at(c, f)).sum::<f64>() / 2.0)
        })
        .collect();
    let clock = Instant::now();
    let fit = fit_tangential_stiffness(&base(truth), &targets, (1e11, 1e13), &options)?;
    println!(
        "c_x fit: {:.4e} N/m³ (truth {:.4e}), misfit {:.2e} m², {} evaluations, {:.2} s",
        fit.value,
        truth.c_x(),
        fit.misfit,
        fit.evaluations,
        clock.elapsed().as_secs_f64()
    );
    let perturbed: Vec<(f64, f64)> = targets.iter().map(|&(f, l)| (f, 1.05 * l + 5e-4)).collect();
    let clock = Instant::now();
    let fit = fit_tangential_stiffness(&base(truth), &perturbed, (1e11, 1e13), &options)?;
    println!(
        "c_x fit to perturbed points: {:.4e} N/m³, misfit {:.2e} m², {} evaluations, {:.2} s",
        fit.value,
        fit.misfit,
        fit.evaluations,
        clock.elapsed().as_secs_f64()
    );
    Ok(())
}

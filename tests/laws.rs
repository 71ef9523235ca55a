//! Archard's law and Amontons' second law at zero shear (paper Fig. 2a and its text):
//! the total real contact area grows linearly with the normal load and does not depend
//! on the nominal area. Run with `--nocapture` to see the measured deviations quoted in
//! `docs/validation-solvers.md`.

use precursors::green::InfluencePlan;
use precursors::solver::EquilibriumSolver;
use precursors::*;

/// Total real contact area (m²) at zero shear, averaged over `seeds` realizations.
fn real_area(lx: f64, ly: f64, lz: f64, loads: &[f64], seeds: u64) -> Vec<f64> {
    let grid = Grid::from_cell_size(Block::new(lx, ly, lz).unwrap(), 1e-3, 1e-3).unwrap();
    let plan = InfluencePlan::builder(grid).build().unwrap();
    let mut solver = EquilibriumSolver::builder(plan).build().unwrap();
    let mut out = vec![0.0; loads.len()];
    for seed in 0..seeds {
        let heights =
            Heights::truncated_gaussian(&grid, HeightDistribution::default(), seed).unwrap();
        let mut iface = Interface::new(grid, heights, SpringLaw::default()).unwrap();
        for (k, &load) in loads.iter().enumerate() {
            let eq = solver.solve_normal(&iface, load).unwrap();
            iface.set_states(&eq.states).unwrap();
            let area: f64 = iface
                .cell_contact_area(&eq.displacement)
                .unwrap()
                .iter()
                .sum();
            out[k] += area / seeds as f64;
        }
    }
    out
}

#[test]
fn archard_real_area_is_linear_in_the_normal_load() {
    // 30 x 6 mm face, Lz = 150 mm, 250 N to 4 kN (paper Fig. 2a).
    let loads: Vec<f64> = (0..16).map(|k| 250.0 * (k + 1) as f64).collect();
    let area = real_area(0.03, 0.006, 0.15, &loads, 4);
    for (f, y) in loads.iter().zip(&area) {
        println!(
            "  F_N = {f:6.0} N  A_R = {y:.4e} m²  A_R/F_N = {:.4e} m²/N",
            y / f
        );
    }
    // Linearity: the secant A_R/F_N is constant and the log-log slope is 1.
    let ratio: Vec<f64> = loads.iter().zip(&area).map(|(f, y)| y / f).collect();
    let (lo, hi) = ratio
        .iter()
        .fold((f64::MAX, 0.0f64), |(l, h), r| (l.min(*r), h.max(*r)));
    let beta = (area[15] / area[0]).ln() / (loads[15] / loads[0]).ln();
    println!(
        "Archard: A_R/F_N varies by {:.2} % from 250 N to 4 kN; d ln A_R / d ln F_N = {beta:.4}",
        100.0 * (hi / lo - 1.0)
    );
    assert!(area.windows(2).all(|w| w[1] > w[0]));
    assert!(hi / lo - 1.0 < 0.08, "A_R/F_N not constant: {lo:e}..{hi:e}");
    assert!((beta - 1.0).abs() < 0.03, "exponent {beta}");
}

#[test]
fn amontons_real_area_does_not_depend_on_nominal_area() {
    let load = [2000.0];
    let faces = [(0.03, 0.006), (0.06, 0.006), (0.03, 0.012), (0.06, 0.012)];
    let areas: Vec<f64> = faces
        .iter()
        .map(|(lx, ly)| real_area(*lx, *ly, 0.15, &load, 4)[0])
        .collect();
    let mean = areas.iter().sum::<f64>() / areas.len() as f64;
    for ((lx, ly), a) in faces.iter().zip(&areas) {
        println!(
            "Amontons: {:.0} x {:.0} mm face: A_R = {a:.4e} m² ({:+.2} % from the mean)",
            lx * 1e3,
            ly * 1e3,
            100.0 * (a / mean - 1.0)
        );
        assert!((a / mean - 1.0).abs() < 0.05);
    }
}

//! Equilibrium solvers: optimality (KKT) checked with the plan's dense matrix and a
//! full-pivoting LU, uniqueness against a test-side single-flip active-set method in
//! random orders. Random scenes, ruptures and both backends against an independently
//! assembled operator: `properties.rs`.

use crate::common::{bordered_solve, compliance_matrix, max_rel_diff, scene};
use precursors::green::RodLoad;
use precursors::solver::{Backend, EquilibriumSolver, NormalEquilibrium, SolverOptions};
use precursors::*;

fn solver(plan: &green::InfluencePlan, backend: Backend) -> EquilibriumSolver {
    EquilibriumSolver::builder(plan.clone())
        .solver_options(SolverOptions::default().with_backend(backend).unwrap())
        .build()
        .unwrap()
}

/// The optimality conditions of the normal problem, checked with the dense `C`:
/// attached sites obey the spring law, detached ones sit above their height, f ≥ 0.
fn assert_kkt(c: &[f64], iface: &Interface, eq: &NormalEquilibrium, tol: f64) {
    let n = iface.grid().len();
    let u0 = iface.heights();
    let law = iface.law();
    let u: Vec<f64> = (0..n)
        .map(|i| eq.offset + (0..n).map(|j| c[i * n + j] * eq.traction[j]).sum::<f64>())
        .collect();
    let u_scale = u.iter().chain(u0).fold(0.0f64, |m, x| m.max(x.abs()));
    let f_scale = eq.traction.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for i in 0..n {
        assert!(
            (u[i] - eq.displacement[i]).abs() <= tol * u_scale,
            "site {i}: u"
        );
        match iface.states()[i] {
            SiteState::Attached => {
                let spring = law.c_z() / u0[i] * (u0[i] - u[i]);
                assert!(
                    (spring - eq.traction[i]).abs() <= tol * f_scale,
                    "site {i}: spring law"
                );
                assert!(eq.traction[i] >= -tol * f_scale, "site {i}: pulls");
            }
            _ => {
                assert_eq!(eq.traction[i], 0.0);
                assert!(
                    u[i] >= u0[i] - tol * u_scale,
                    "site {i}: detached below its height"
                );
            }
        }
    }
    let total: f64 = eq.traction.iter().sum::<f64>() * iface.grid().cell_area();
    assert!((total - eq.normal_load).abs() <= 1e-12 * eq.normal_load);
}

#[test]
fn normal_equilibrium_satisfies_kkt_for_both_backends() {
    for (nx, ny, lz) in [(14, 5, 0.01), (30, 6, 0.15), (9, 1, 0.005)] {
        let s = scene(nx, ny, 1e-3, lz, 3);
        let c = compliance_matrix(&s.plan, Material::default().modulus());
        for backend in [Backend::Dense, Backend::Spectral] {
            let mut iface = s.interface.clone();
            let mut sol = solver(&s.plan, backend);
            let load = 3.5 * (nx * ny) as f64; // 3.5 MPa, the calibration scene's pressure
            let eq = sol.solve_normal(&iface, load).unwrap();
            iface.set_states(&eq.states).unwrap();
            assert_eq!(eq.report.backend, backend);
            assert!(iface.attached_count() > 0 && iface.attached_count() < nx * ny);
            assert_kkt(&c, &iface, &eq, 1e-9);
        }
    }
}

/// A test-side reference: one site flips at a time (the first violator in a shuffled
/// order, Murty's least-index rule), each step a full-pivoting LU solve.
fn single_flip_reference(c: &[f64], iface: &Interface, load: f64, order: &[usize]) -> Vec<bool> {
    let n = iface.grid().len();
    let u0 = iface.heights();
    let d = iface.normal_compliance();
    let total = load / iface.grid().cell_area();
    let mut in_set = vec![true; n];
    for _ in 0..10 * n {
        let set: Vec<usize> = (0..n).filter(|&i| in_set[i]).collect();
        let dd: Vec<f64> = set.iter().map(|&i| d[i]).collect();
        let b: Vec<f64> = set.iter().map(|&i| u0[i]).collect();
        let (f, offset) = bordered_solve(c, n, &set, &dd, &b, total);
        let mut full = vec![0.0; n];
        set.iter().zip(&f).for_each(|(&i, &v)| full[i] = v);
        let u: Vec<f64> = (0..n)
            .map(|i| offset + (0..n).map(|j| c[i * n + j] * full[j]).sum::<f64>())
            .collect();
        let scale = u0.iter().fold(0.0f64, |m, x| m.max(*x));
        let violator = order.iter().copied().find(|&i| {
            (in_set[i] && full[i] < 0.0) || (!in_set[i] && u0[i] - u[i] > 1e-12 * scale)
        });
        match violator {
            Some(i) => in_set[i] = !in_set[i],
            None => return in_set,
        }
    }
    panic!("single-flip reference did not converge");
}

#[test]
fn normal_equilibrium_does_not_depend_on_flip_order() {
    let s = scene(8, 6, 1e-3, 0.02, 11);
    let n = s.grid.len();
    let c = compliance_matrix(&s.plan, Material::default().modulus());
    let load = 150.0; // ~3 MPa: about half the sites attach
    let mut iface = s.interface.clone();
    let mut sol = solver(&s.plan, Backend::Dense);
    let eq = sol.solve_normal(&iface, load).unwrap();
    iface.set_states(&eq.states).unwrap();
    let attached: Vec<bool> = iface
        .states()
        .iter()
        .map(|s| *s == SiteState::Attached)
        .collect();
    let mut seed = 1u64;
    for _ in 0..3 {
        let mut order: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            order.swap(i, (seed >> 33) as usize % (i + 1));
        }
        assert_eq!(
            single_flip_reference(&c, &s.interface, load, &order),
            attached
        );
    }
    // Warm starts from other states reach the same equilibrium: from a lighter and a
    // heavier load, on both backends.
    for backend in [Backend::Dense, Backend::Spectral] {
        let cold = {
            let i2 = s.interface.clone();
            solver(&s.plan, backend).solve_normal(&i2, load).unwrap()
        };
        for prior in [5.0, 2000.0] {
            let mut i2 = s.interface.clone();
            let mut sol = solver(&s.plan, backend);
            let first = sol.solve_normal(&i2, prior).unwrap();
            i2.set_states(&first.states).unwrap();
            let warm = sol.solve_normal(&i2, load).unwrap();
            i2.set_states(&warm.states).unwrap();
            assert!(warm.report.flips > 0);
            let now: Vec<bool> = i2
                .states()
                .iter()
                .map(|s| *s == SiteState::Attached)
                .collect();
            assert_eq!(now, attached);
            assert!(max_rel_diff(&cold.traction, &warm.traction) < 1e-10);
        }
    }
}

#[test]
fn tangential_response_matches_bordered_lu() {
    let s = scene(20, 4, 1e-3, 0.03, 5);
    let n = s.grid.len();
    let m = Material::default();
    let c = compliance_matrix(&s.plan, m.modulus());
    let rod = RodLoad::new(s.grid.block(), 0.006, 0.002).unwrap();
    let per_column = rod.influence_cells(&s.grid, 1e-10).unwrap();
    let e: Vec<f64> = (0..n).map(|i| per_column[i % 20] / m.modulus()).collect();
    for backend in [Backend::Dense, Backend::Spectral] {
        let mut iface = s.interface.clone();
        let mut sol = solver(&s.plan, backend);
        let eq = sol.solve_normal(&iface, 400.0).unwrap();
        iface.set_states(&eq.states).unwrap();
        let t = sol.solve_tangential(&iface, &eq.displacement, &e).unwrap();
        let set: Vec<usize> = (0..n)
            .filter(|&i| iface.states()[i] == SiteState::Attached)
            .collect();
        let d: Vec<f64> = set
            .iter()
            .map(|&i| (eq.displacement[i] / iface.heights()[i]).exp() / iface.law().c_x())
            .collect();
        let b: Vec<f64> = set.iter().map(|&i| -e[i]).collect();
        let (phi, _) = bordered_solve(&c, n, &set, &d, &b, -1.0 / s.grid.cell_area());
        let mut reference = vec![0.0; n];
        set.iter().zip(&phi).for_each(|(&i, &v)| reference[i] = v);
        assert!(max_rel_diff(&reference, &t.traction) < 1e-9, "{backend:?}");
        // The springs hold: φ_x = -k_x u_x on attached sites.
        let kx = iface.tangential_stiffness(&eq.displacement).unwrap();
        for &i in &set {
            assert!(
                (t.traction[i] + kx[i] * t.displacement[i]).abs()
                    < 1e-9 * t.traction[i].abs().max(1e-3)
            );
        }
        let loads = iface
            .breaking_loads(&eq.traction, &t.traction, m.friction_coefficient())
            .unwrap();
        for ((load, g), f) in loads.iter().zip(&t.traction).zip(&eq.traction) {
            if *g != 0.0 {
                // At its breaking load a site sits on the Coulomb threshold |φ_x| = μ φ_z.
                assert!((load * g.abs() - 0.5 * f).abs() <= 1e-12 * f);
            } else {
                assert_eq!(*load, f64::INFINITY);
            }
        }
    }
}

#[test]
fn solver_errors_are_typed() {
    let s = scene(4, 2, 1e-3, 0.01, 1);
    let mut sol = solver(&s.plan, Backend::Dense);
    let mut iface = s.interface.clone();
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            sol.solve_normal(&iface, bad),
            Err(Error::InvalidParameter { .. })
        ));
    }
    for i in 0..8 {
        iface.break_site(i).unwrap();
    }
    assert!(matches!(
        sol.solve_normal(&iface, 10.0),
        Err(Error::EmptyContact { .. })
    ));
    assert!(matches!(
        sol.solve_tangential(&iface, &[0.0; 8], &[0.0; 8]),
        Err(Error::EmptyContact { .. })
    ));
    let mut fresh = s.interface.clone();
    let eq = sol.solve_normal(&fresh, 10.0).unwrap();
    fresh.set_states(&eq.states).unwrap();
    assert!(matches!(
        sol.solve_tangential(&fresh, &eq.displacement, &[0.0; 7]),
        Err(Error::LengthMismatch { .. })
    ));
    let other = scene(5, 2, 1e-3, 0.01, 1);
    let wrong = other.interface.clone();
    assert!(matches!(
        sol.solve_normal(&wrong, 10.0),
        Err(Error::LengthMismatch { .. })
    ));
    let big = scene(150, 150, 1e-4, 0.01, 1);
    assert!(matches!(
        EquilibriumSolver::builder(big.plan)
            .solver_options(
                SolverOptions::default()
                    .with_backend(Backend::Dense)
                    .unwrap()
            )
            .build(),
        Err(Error::TooLargeForDense { .. })
    ));
    // A negative tolerance cannot reach a solver: the options refuse it.
    assert!(matches!(
        SolverOptions::default().with_tolerance(-1.0),
        Err(Error::InvalidTolerance { .. })
    ));
}

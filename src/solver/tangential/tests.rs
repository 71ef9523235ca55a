//! The anchors' tangential solve: zero anchors give zero; the superposition `F g1 + g0`
//! is the direct solve of `b = a - F e` and holds the springs and the load; the dense and
//! spectral backends agree; its warm start survives a solver state's round trip.

use super::*;
use crate::geometry::{Block, Grid};
use crate::green::InfluencePlan;
use crate::interface::{Heights, Material, SpringLaw};
#[cfg(feature = "serde")]
use crate::solver::SolverState;
use crate::solver::{Backend, SolverOptions};

/// A solver of `backend` on a 12 x 4 grid of 1 mm cells and the interface in its normal
/// equilibrium under 40 N (some sites detached), with two sites broken; `u_z` (m).
fn setup(backend: Backend) -> (EquilibriumSolver, Interface, Vec<f64>) {
    let grid = Grid::new(Block::new(0.012, 0.004, 0.010).unwrap(), 12, 4).unwrap();
    let heights: Vec<f64> = (0..grid.len())
        .map(|i| 1e-6 * (1.0 + 0.8 * (i as f64 * 1.3).sin()))
        .collect();
    let heights = Heights::from_values(&grid, heights).unwrap();
    let mut interface = Interface::new(grid, heights, SpringLaw::default()).unwrap();
    interface.break_site(5).unwrap();
    interface.break_site(30).unwrap();
    let options = SolverOptions::default().with_backend(backend).unwrap();
    let mut solver = EquilibriumSolver::builder(InfluencePlan::builder(grid).build().unwrap())
        .material(Material::default())
        .solver_options(options)
        .build()
        .unwrap();
    let normal = solver.solve_normal(&interface, 40.0).unwrap();
    interface.set_states(&normal.states).unwrap();
    let detached = normal.states.iter().filter(|s| **s == SiteState::Detached);
    assert!(detached.count() > 0, "the test wants detached sites");
    (solver, interface, normal.displacement)
}

/// Anchors (m) and a unit-load displacement (m/N) of rod-like size.
fn inputs(n: usize) -> (Vec<f64>, Vec<f64>) {
    let anchors = (0..n).map(|i| 1e-7 * (i as f64 * 0.91).sin()).collect();
    let e = (0..n)
        .map(|i| 1e-9 * (1.0 + (i as f64 * 0.37).cos()))
        .collect();
    (anchors, e)
}

fn max_abs(v: impl Iterator<Item = f64>) -> f64 {
    v.fold(0.0, |m, x| m.max(x.abs()))
}

/// Zero anchors, or anchors only where no spring is attached: exactly zero.
#[test]
fn zero_anchors_give_zero() {
    let (mut solver, interface, u_z) = setup(Backend::Spectral);
    let n = u_z.len();
    let off: Vec<f64> = (0..n)
        .map(|i| match interface.states()[i] {
            SiteState::Attached => 0.0,
            _ => 1e-6,
        })
        .collect();
    for anchors in [vec![0.0; n], off] {
        let r = solver
            .solve_tangential_anchor(&interface, &u_z, &anchors)
            .unwrap();
        assert!(r.traction.iter().chain(&r.displacement).all(|x| *x == 0.0));
        assert_eq!(r.offset, 0.0);
    }
    assert!(matches!(
        solver.solve_tangential_anchor(&interface, &u_z, &[0.0; 3]),
        Err(Error::LengthMismatch {
            name: "anchors",
            ..
        })
    ));
}

/// `F g1 + g0` against the direct solve of `b = a - F e`, `ΔA Σ φ = -F` (the same set
/// system), and against the physics it solves: on attached sites the springs hold,
/// `u + φ/k_x = a`; elsewhere no traction; the tractions carry `F`.
#[test]
fn superposition_equals_the_direct_solve_of_the_anchored_springs() {
    for backend in [Backend::Dense, Backend::Spectral] {
        let (mut solver, interface, u_z) = setup(backend);
        let n = u_z.len();
        let (anchors, e) = inputs(n);
        let force = 2.5; // N
        let g1 = solver.solve_tangential(&interface, &u_z, &e).unwrap();
        let g0 = solver
            .solve_tangential_anchor(&interface, &u_z, &anchors)
            .unwrap();
        let phi: Vec<f64> = (0..n)
            .map(|i| force * g1.traction[i] + g0.traction[i])
            .collect();
        let u: Vec<f64> = (0..n)
            .map(|i| force * g1.displacement[i] + g0.displacement[i])
            .collect();
        // The direct solve, cold.
        let set: Vec<usize> = (0..n)
            .filter(|&i| interface.states()[i] == SiteState::Attached)
            .collect();
        let d: Vec<f64> = set
            .iter()
            .map(|&i| interface.tangential_compliance_at(i, u_z[i]).unwrap())
            .collect();
        let b: Vec<f64> = set.iter().map(|&i| anchors[i] - force * e[i]).collect();
        let cell = solver.grid.cell_area();
        let problem = SetProblem {
            set: &set,
            d: &d,
            b: &b,
            total: -force / cell,
        };
        let kind = SolveKind {
            explore: false,
            tangential: true,
            cold: false,
        };
        let direct = solver
            .solve_set(kind, problem, vec![0.0; set.len()])
            .unwrap();
        let scale = max_abs(direct.f.iter().copied());
        let off = max_abs(set.iter().enumerate().map(|(a, &i)| phi[i] - direct.f[a]));
        assert!(
            off <= 1e-8 * scale,
            "{backend}: off by {off:e} Pa of {scale:e}"
        );
        // The physics.
        let spring = max_abs(
            set.iter()
                .enumerate()
                .map(|(a, &i)| u[i] + d[a] * phi[i] - anchors[i]),
        );
        let size = max_abs(u.iter().chain(&anchors).copied());
        assert!(
            spring <= 1e-8 * size,
            "{backend}: springs off by {spring:e} m"
        );
        assert!((0..n).all(|i| set.contains(&i) || phi[i] == 0.0));
        let carried = cell * phi.iter().sum::<f64>();
        assert!(
            (carried + force).abs() <= 1e-9 * force,
            "{backend}: {carried} N"
        );
        // The anchors alone carry no net force.
        assert!(
            g0.report.force_balance_error <= 1e-9,
            "{:e}",
            g0.report.force_balance_error
        );
    }
}

/// The dense and spectral backends give the same anchor response.
#[test]
fn dense_and_spectral_anchor_responses_agree() {
    let (mut dense, interface, u_z) = setup(Backend::Dense);
    let (mut spectral, _, u_z_spectral) = setup(Backend::Spectral);
    let (anchors, _) = inputs(u_z.len());
    let a = dense
        .solve_tangential_anchor(&interface, &u_z, &anchors)
        .unwrap();
    let b = spectral
        .solve_tangential_anchor(&interface, &u_z_spectral, &anchors)
        .unwrap();
    let scale = max_abs(a.traction.iter().copied());
    let off = max_abs(a.traction.iter().zip(&b.traction).map(|(x, y)| x - y));
    assert!(
        scale > 0.0 && off <= 1e-7 * scale,
        "off by {off:e} Pa of {scale:e}"
    );
    let size = max_abs(a.displacement.iter().copied());
    let off = max_abs(
        a.displacement
            .iter()
            .zip(&b.displacement)
            .map(|(x, y)| x - y),
    );
    assert!(off <= 1e-7 * size, "off by {off:e} m of {size:e}");
}

/// The anchor warm start is part of the solver's state: a solver restored from it
/// repeats the next anchor solve bit for bit; without anchors the state (and so a
/// checkpoint's JSON) has no anchor key, and a state without one reads as empty.
#[test]
fn the_anchor_warm_start_round_trips_through_the_solver_state() {
    let (mut solver, interface, u_z) = setup(Backend::Spectral);
    let n = u_z.len();
    let (anchors, e) = inputs(n);
    // A solver that has solved holds both other warm starts (as a driver's does).
    solver.solve_tangential(&interface, &u_z, &e).unwrap();
    #[cfg(feature = "serde")]
    {
        let json = serde_json::to_string(&solver.state()).unwrap();
        assert!(!json.contains("warm_anchor"), "{json}");
    }
    solver
        .solve_tangential_anchor(&interface, &u_z, &anchors)
        .unwrap();
    let state = solver.state();
    assert_eq!(state.warm_anchor.len(), n);
    #[cfg(feature = "serde")]
    let state = {
        let json = serde_json::to_string(&state).unwrap();
        assert!(json.contains("warm_anchor"));
        serde_json::from_str::<SolverState>(&json).unwrap()
    };
    let (mut restored, _, _) = setup(Backend::Spectral);
    restored.restore(state, true).unwrap();
    assert_eq!(restored.state(), solver.state());
    let moved: Vec<f64> = anchors.iter().map(|a| 1.1 * a + 1e-9).collect();
    let x = solver
        .solve_tangential_anchor(&interface, &u_z, &moved)
        .unwrap();
    let y = restored
        .solve_tangential_anchor(&interface, &u_z, &moved)
        .unwrap();
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&x.traction), bits(&y.traction));
    // A warm start of another length is refused.
    let mut bad = solver.state();
    bad.warm_anchor.pop();
    assert!(matches!(
        restored.restore(bad, true),
        Err(Error::InvalidCheckpoint { .. })
    ));
}

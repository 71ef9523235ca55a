//! Property tests (proptest: random blocks, grids, heights, loads, drives and ruptures)
//! whose references are computed by other code paths than the code under test:
//!
//! * [`reference_operator`]: the Galerkin operator `Ĝ` summed as the raw double cosine
//!   series of the bottom face with exact cell averages of every cosine (no alias folding,
//!   no DCT, no tail correction; Richardson extrapolation in the cut-off instead), and
//!   4-D Gauss–Legendre quadrature of the point function `G` over two cells: the symmetry
//!   and the entries of `InfluencePlan::dense` and `InfluencePlan::apply`;
//! * closed forms: the flux of the loads through a plane (plane probes), the face means of
//!   `G` (the spring force `K_S (U_S - ⟨u_x⟩)` from the displacements);
//! * the equilibrium equations (KKT conditions of the normal problem, the tangential
//!   spring equations) recomputed with the reference `Ĝ`, for the solvers (both backends,
//!   after random ruptures) and the driver's states.
//!
//! Each test was seen to fail once with the code under test broken by hand (the commit
//! messages list the breakages).

use crate::common::rule;
use precursors::green::{GreenFunction, InfluencePlan, RodLoad};
use precursors::solver::{Backend, EquilibriumSolver, SolverOptions};
use precursors::*;
use precursors::{ProbeInput, ProbeSpec, StressProbe};
use proptest::prelude::*;
use std::f64::consts::PI;

/// splitmix64: the tests' random vectors and picks (seeded by proptest).
fn next(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Uniform in [0, 1).
fn uniform(state: &mut u64) -> f64 {
    (next(state) >> 11) as f64 / (1u64 << 53) as f64
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Random blocks and grids: up to `max_nx x max_ny` cells of 0.5 to 2 mm with an aspect
/// ratio between 1/2 and 2, heights `Lz` from 0.5 mm to 0.1 m (log-uniform).
fn grids(max_nx: usize, max_ny: usize) -> impl Strategy<Value = Grid> {
    (
        1..=max_nx,
        1..=max_ny,
        0.5e-3f64..2e-3,
        0.5f64..2.0,
        (0.5e-3f64).ln()..(0.1f64).ln(),
    )
        .prop_map(|(nx, ny, dx, aspect, ln_lz)| {
            let block = Block::new(nx as f64 * dx, ny as f64 * dx * aspect, ln_lz.exp()).unwrap();
            Grid::new(block, nx, ny).unwrap()
        })
}

/// Cell averages of `cos(k_p x)` over the `n` cells of `[0, l]`, for `p = 0..=p_max`:
/// `A[p][a] = (sin(k_p x_{a+1}) - sin(k_p x_a)) / (k_p Δ)`, `A[0][a] = 1`.
fn cell_cosines(l: f64, n: usize, p_max: usize) -> Vec<Vec<f64>> {
    let d = l / n as f64;
    (0..=p_max)
        .map(|p| {
            if p == 0 {
                return vec![1.0; n];
            }
            let k = p as f64 * PI / l;
            (0..n)
                .map(|a| ((k * (a + 1) as f64 * d).sin() - (k * a as f64 * d).sin()) / (k * d))
                .collect()
        })
        .collect()
}

/// The raw series of `Ĝ` with the cut-off `p ≤ 2 Nx q`, `m ≤ 2 Ny q` (row-major `N x N`):
/// `Ĝ_ij = (4/(Lx Ly)) Σ_{p,m} w_p w_m s(κ) A_p(ix_i) A_p(ix_j) A_m(iy_i) A_m(iy_j)`,
/// `s(κ) = coth(κ Lz)/κ`, `s(0) = Lz/3` (MODEL.md section 1, bottom-face form of `G`,
/// averaged over source and target cells).
fn raw_operator(grid: &precursors::Grid, q: usize) -> Vec<f64> {
    let b = grid.block();
    let (nx, ny) = (grid.nx(), grid.ny());
    let (pmax, mmax) = (2 * nx * q, 2 * ny * q);
    let ax = cell_cosines(b.lx(), nx, pmax);
    let ay = cell_cosines(b.ly(), ny, mmax);
    let n = nx * ny;
    let mut g = vec![0.0; n * n];
    let mut bm = vec![0.0; nx * nx];
    for (m, rowy) in ay.iter().enumerate() {
        let km = m as f64 * PI / b.ly();
        let wm = if m == 0 { 0.5 } else { 1.0 };
        bm.iter_mut().for_each(|x| *x = 0.0);
        for (p, row) in ax.iter().enumerate() {
            let kp = p as f64 * PI / b.lx();
            let wp = if p == 0 { 0.5 } else { 1.0 };
            let kappa = (kp * kp + km * km).sqrt();
            let s = if kappa == 0.0 {
                b.lz() / 3.0
            } else {
                1.0 / (kappa * (kappa * b.lz()).tanh())
            };
            let c = wp * s;
            for a in 0..nx {
                let ca = c * row[a];
                for (bb, r) in row.iter().enumerate() {
                    bm[a * nx + bb] += ca * r;
                }
            }
        }
        for iy in 0..ny {
            for jy in 0..ny {
                let c = 4.0 / (b.lx() * b.ly()) * wm * rowy[iy] * rowy[jy];
                for a in 0..nx {
                    for bb in 0..nx {
                        g[(iy * nx + a) * n + jy * nx + bb] += c * bm[a * nx + bb];
                    }
                }
            }
        }
    }
    g
}

/// The reference operator `Ĝ` (m⁻¹) and an a-posteriori bound on the error of each
/// entry: [`raw_operator`] at the cut-offs `q = 8, 16, 32, 64`, Richardson extrapolated
/// twice. The truncation error is `c₂/q² + c₃/q³ + O(q⁻⁴)` (the strips `p > 2 Nx q` carry
/// `Σ S_p² s(κ) ~ Σ 1/p³` over whole alias periods, whose Euler–Maclaurin expansion is
/// `1/(2Q²) - 1/(2Q³) + …`), so the extrapolation from `(16, 32, 64)` is ~16 times more
/// accurate than the one from `(8, 16, 32)`, and their difference bounds its error
/// (measured: below 1e-9 of the largest entry on 12 x 6 grids).
fn reference_operator(grid: &Grid) -> (Vec<f64>, Vec<f64>) {
    let s: Vec<Vec<f64>> = [8, 16, 32, 64]
        .iter()
        .map(|&q| raw_operator(grid, q))
        .collect();
    let extrapolate = |a: &[f64], b: &[f64], c: &[f64], k: usize| {
        let r1 = (4.0 * b[k] - a[k]) / 3.0;
        let r2 = (4.0 * c[k] - b[k]) / 3.0;
        (8.0 * r2 - r1) / 7.0
    };
    let n2 = s[0].len();
    let fine: Vec<f64> = (0..n2)
        .map(|k| extrapolate(&s[1], &s[2], &s[3], k))
        .collect();
    let error = (0..n2)
        .map(|k| (fine[k] - extrapolate(&s[0], &s[1], &s[2], k)).abs())
        .collect();
    (fine, error)
}

/// Relative tolerance of the plans' eigenvalues in these tests: `‖δĜ‖₂ ≤ PLAN_TOL ‖Ĝ‖₂`.
const PLAN_TOL: f64 = 1e-9;

/// `‖A‖∞ = max_i Σ_j |A_ij|` of a row-major square matrix.
fn norm_inf(a: &[f64], n: usize) -> f64 {
    (0..n)
        .map(|i| a[i * n..(i + 1) * n].iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0f64, f64::max)
}

fn matvec(c: &[f64], v: &[f64]) -> Vec<f64> {
    let n = v.len();
    (0..n)
        .map(|i| {
            c[i * n..(i + 1) * n]
                .iter()
                .zip(v)
                .map(|(a, b)| a * b)
                .sum()
        })
        .collect()
}

/// `(1/ΔA²) ∫_i ∫_j G(x,ξ;y,η;0,0)` by 4-D Gauss–Legendre (6 points per axis) with `G`
/// from the point representation (target in cell `i`, source in cell `j`).
fn quadrature_entry(
    gf: &GreenFunction,
    grid: &Grid,
    i: (usize, usize),
    j: (usize, usize),
    tol: f64,
) -> f64 {
    let (dx, dy) = (grid.dx(), grid.dy());
    let q = |c: usize, d: f64| rule(c as f64 * d, (c + 1) as f64 * d, 1, 6);
    let (qx, qy, qxi, qeta) = (q(i.0, dx), q(i.1, dy), q(j.0, dx), q(j.1, dy));
    let mut sum = 0.0;
    for &(x, wx) in &qx {
        for &(y, wy) in &qy {
            for &(xi, wxi) in &qxi {
                for &(eta, weta) in &qeta {
                    let g = gf
                        .value(Point::new(x, y, 0.0), Point::new(xi, eta, 0.0), tol)
                        .unwrap()
                        .value;
                    sum += wx * wy * wxi * weta * g;
                }
            }
        }
    }
    sum / (dx * dy).powi(2)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    /// Symmetry and values of the Galerkin operator on random blocks and grids.
    /// References: (a) every entry of `InfluencePlan::dense` and the matrix-free
    /// `InfluencePlan::apply` against [`reference_operator`] (raw double series with exact
    /// cell averages: no alias folding, no DCT, no tail correction); (b) for a random pair
    /// of cells at least two cells apart, 4-D quadrature of the point function `G` with the
    /// target in `i` and the source in `j`, against both `Ĝ_ij` and `Ĝ_ji` (the symmetry of
    /// `Ĝ` is the reciprocity of `G` through its cell averages).
    #[test]
    fn galerkin_operator_equals_independent_assemblies(grid in grids(12, 6), seed in any::<u64>()) {
        let plan = InfluencePlan::builder(grid).plan_tolerance(PLAN_TOL).build().unwrap();
        let n = grid.len();
        let dense = plan.dense().unwrap();
        let (reference, error) = reference_operator(&grid);
        // The plan's eigenvalues are within PLAN_TOL relative, so |δĜ_ij| ≤ ‖δĜ‖₂ ≤
        // PLAN_TOL ‖Ĝ‖₂ ≤ PLAN_TOL ‖Ĝ‖∞; the reference's entries within `error`.
        let plan_error = PLAN_TOL * norm_inf(&reference, n);
        for i in 0..n {
            for j in 0..n {
                let k = i * n + j;
                let (d, r) = (dense[k], reference[k]);
                prop_assert!((d - r).abs() <= plan_error + error[k],
                    "entry ({}, {}): plan {} vs reference {} (bound {:e})", i, j, d, r, plan_error + error[k]);
            }
        }
        let mut rng = seed;
        let v: Vec<f64> = (0..n).map(|_| uniform(&mut rng) - 0.5).collect();
        let mut out = vec![0.0; n];
        plan.apply(&v, &mut out).unwrap();
        let expected = matvec(&reference, &v);
        let v_max = max_abs(&v);
        for i in 0..n {
            let row_error: f64 = error[i * n..(i + 1) * n].iter().sum();
            let bound = (plan_error * (n as f64).sqrt() + row_error) * v_max;
            prop_assert!((out[i] - expected[i]).abs() <= bound, "apply row {}: {} vs {}", i, out[i], expected[i]);
        }
        // (b) A pair of cells with at least two cells between them (6-point rules then
        // integrate the 1/r kernel to ~1e-9, see the tolerance below).
        let far: Vec<((usize, usize), (usize, usize))> = (0..n)
            .flat_map(|a| (0..n).map(move |b| (a, b)))
            .map(|(a, b)| ((a % grid.nx(), a / grid.nx()), (b % grid.nx(), b / grid.nx())))
            .filter(|&((ix, iy), (jx, jy))| ix.abs_diff(jx).max(iy.abs_diff(jy)) >= 3)
            .collect();
        if !far.is_empty() {
            let (ci, cj) = far[(next(&mut rng) % far.len() as u64) as usize];
            let gap = ((ci.0.abs_diff(cj.0).saturating_sub(1)) as f64 * grid.dx())
                .hypot((ci.1.abs_diff(cj.1).saturating_sub(1)) as f64 * grid.dy());
            // The kernel's scale at the pair's distance: 1/(2π r) on the face.
            let kernel = 1.0 / (2.0 * PI * gap);
            let gf = GreenFunction::new(*grid.block());
            let quad = quadrature_entry(&gf, &grid, ci, cj, 1e-12 * kernel);
            let (i, j) = (
                grid.index(ci.0, ci.1).unwrap(),
                grid.index(cj.0, cj.1).unwrap(),
            );
            for (name, entry) in [("G_ij", dense[i * n + j]), ("G_ji", dense[j * n + i])] {
                prop_assert!((entry - quad).abs() <= 1e-7 * kernel,
                    "{} of {:?}-{:?}: {} vs quadrature {}", name, ci, cj, entry, quad);
            }
        }
    }
}

/// Random cell tractions (Pa) with the total `ΔA Σ φ = total` (N): the mean plus a
/// zero-sum perturbation of the same size.
fn tractions(grid: &Grid, total: f64, rng: &mut u64) -> Vec<f64> {
    let n = grid.len();
    let mean = total / (grid.block().lx() * grid.block().ly());
    let mut noise: Vec<f64> = (0..n).map(|_| uniform(rng) - 0.5).collect();
    let avg = noise.iter().sum::<f64>() / n as f64;
    noise.iter_mut().for_each(|x| *x -= avg);
    let amplitude = 2.0 * mean.abs().max(1.0);
    noise.iter().map(|x| mean + amplitude * x).collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Force balance through random planes: for random blocks, grids, rod bands (or the
    /// uniform side load), loads and tractions that balance them, the integrals of the
    /// plane probes' stresses equal the flux of the loads above the plane (closed form):
    /// `∫ τ dA = F_top + F_lat · (part of the band above z)`, `∫ σ dA = -F_N`.
    #[test]
    fn plane_probes_carry_the_loads_above_them(
        grid in grids(12, 6),
        band in (0.0f64..1.0, 0.0f64..1.0),
        side in any::<bool>(),
        (f_top, f_lat, f_n) in (0.0f64..50.0, 0.0f64..50.0, 1.0f64..500.0),
        planes in proptest::collection::vec(0.0f64..=1.0, 1..4),
        seed in any::<u64>(),
    ) {
        let block = *grid.block();
        let lz = block.lz();
        let (lo, hi) = if side {
            (0.0, lz)
        } else {
            let (a, b) = (band.0.min(band.1), band.0.max(band.1));
            (a * lz, (b * lz).max(a * lz + 1e-3 * lz).min(lz))
        };
        let rod = if side {
            RodLoad::uniform_side(&block)
        } else {
            RodLoad::new(&block, 0.5 * (lo + hi), 0.5 * (hi - lo)).unwrap()
        };
        let plan = InfluencePlan::builder(grid).build().unwrap();
        // Planes from z_min = Δ/20 to Lz: the transfer's alias sums need `z ≳ Δ/100` to
        // converge (`e^{-2π q z/Δ}`, q ≤ 512); z = 0 copies the tractions, balanced here
        // by construction.
        let z_min = (0.05 * grid.dx().max(grid.dy())).min(lz);
        let heights: Vec<f64> = planes.iter().map(|t| z_min + t * (lz - z_min)).collect();
        let spec = heights.iter().fold(ProbeSpec::default(), |s, z| s.with_plane(*z));
        let probe = StressProbe::new(&plan, &spec, Some(&rod)).unwrap();
        let mut rng = seed;
        let phi_x = tractions(&grid, -(f_top + f_lat), &mut rng);
        let phi_z = tractions(&grid, f_n, &mut rng);
        let out = probe
            .evaluate(&ProbeInput::new(&phi_x, &phi_z).with_loads(f_top, f_lat, f_n).unwrap())
            .unwrap();
        let area = grid.cell_area();
        // Probe accuracy (ProbeSpec::tolerance = 1e-10): transfer factors to 1e-10 times
        // the largest traction over the face, the lateral term to 1e-10/(Ly Lz) per
        // newton per cell, i.e. 1e-10 F_lat Lx/Lz over the face; 10x margin.
        let face = block.lx() * block.ly();
        let tol = 1e-9 * (face * (max_abs(&phi_x) + max_abs(&phi_z)) + f_lat * (1.0 + block.lx() / lz) + f_top + f_n);
        for (plane, z) in out.planes.iter().zip(&heights) {
            let above = ((hi - z) / (hi - lo)).clamp(0.0, 1.0);
            let shear: f64 = plane.shear().iter().sum::<f64>() * area;
            let normal: f64 = plane.normal().iter().sum::<f64>() * area;
            let expected = f_top + f_lat * above;
            prop_assert!((shear - expected).abs() <= tol, "z = {}: ∫τ = {} vs {}", z, shear, expected);
            prop_assert!((normal + f_n).abs() <= tol, "z = {}: ∫σ = {} vs {}", z, normal, -f_n);
        }
    }
}

/// The reference `C = (ΔA/M) Ĝ` (m/Pa) of a grid.
struct Compliance {
    c: Vec<f64>,
    /// `‖C‖∞` (m/Pa).
    norm: f64,
    /// Bound on each row's error `Σ_j |δC_ij|` (m/Pa).
    row_error: Vec<f64>,
}

fn reference_compliance(grid: &Grid, modulus: f64) -> Compliance {
    let n = grid.len();
    let scale = grid.cell_area() / modulus;
    let (g, err) = reference_operator(grid);
    let c: Vec<f64> = g.into_iter().map(|g| g * scale).collect();
    let rows = (0..n)
        .map(|i| err[i * n..(i + 1) * n].iter().sum::<f64>() * scale)
        .collect();
    let norm = norm_inf(&c, n);
    Compliance {
        c,
        norm,
        row_error: rows,
    }
}

/// Normal equilibrium (MODEL.md section 4) checked with the reference `C`: with
/// `u = U + C f` recomputed, attached sites satisfy `(C f)_i + f_i/k_z,i + U = u0_i`
/// (`1/k_z = u0/c_z`) and `f_i ≥ 0`, the others carry nothing and detached ones sit at or
/// above their height. Residuals are compared with `tol` times the scale of rounding in
/// these equations plus the reference's row error times `max |f|`.
fn check_normal(
    c: &Compliance,
    iface: &Interface,
    traction: &[f64],
    displacement: &[f64],
    offset: f64,
    tol: f64,
) -> std::result::Result<(), TestCaseError> {
    let u0 = iface.heights();
    let c_z = iface.law().c_z();
    let fmax = max_abs(traction);
    let u: Vec<f64> = matvec(&c.c, traction).iter().map(|x| x + offset).collect();
    let compliance_max = u0.iter().fold(0.0f64, |m, h| m.max(h / c_z));
    // The scale of rounding in `A f + U 1 - b` (the solver's backward error).
    let scale = (c.norm + compliance_max) * fmax + max_abs(u0) + offset.abs();
    for (i, state) in iface.states().iter().enumerate() {
        let bound = tol * scale + c.row_error[i] * fmax;
        prop_assert!(
            (u[i] - displacement[i]).abs() <= bound,
            "site {}: u_z = {} vs recomputed {} (bound {:e})",
            i,
            displacement[i],
            u[i],
            bound
        );
        match state {
            SiteState::Attached => {
                let residual = u[i] + traction[i] * u0[i] / c_z - u0[i];
                prop_assert!(
                    residual.abs() <= bound,
                    "site {}: spring law residual {:e} (bound {:e})",
                    i,
                    residual,
                    bound
                );
                prop_assert!(
                    traction[i] >= -tol * fmax,
                    "site {}: pulls, {}",
                    i,
                    traction[i]
                );
            }
            SiteState::Detached => {
                prop_assert_eq!(traction[i], 0.0);
                prop_assert!(
                    u[i] >= u0[i] - bound,
                    "site {}: detached below its height: {} < {}",
                    i,
                    u[i],
                    u0[i]
                );
            }
            _ => prop_assert_eq!(traction[i], 0.0), // broken
        }
    }
    Ok(())
}

/// A tangential state: `u_z` (m), the load's displacement `e` (m), the shear traction
/// (Pa), the shear displacement (m) and the offset `U` (m), all for the same load.
struct Shear<'a> {
    u_z: &'a [f64],
    e: &'a [f64],
    traction: &'a [f64],
    displacement: &'a [f64],
    offset: f64,
}

/// Tangential equilibrium at the attached set, checked with the reference `C`: with
/// `u_x = U + e + C φ` recomputed and `k_x = c_x exp(-u_z/u0)` (MODEL.md section 3),
/// attached sites satisfy `φ_i = -k_x,i u_x,i`, i.e. `(C φ)_i + φ_i/k_x,i + U + e_i = 0`;
/// the others carry nothing.
fn check_tangential(
    c: &Compliance,
    iface: &Interface,
    s: &Shear<'_>,
    tol: f64,
) -> std::result::Result<(), TestCaseError> {
    let u0 = iface.heights();
    let c_x = iface.law().c_x();
    let states = iface.states();
    let compliance: Vec<f64> = (0..u0.len())
        .map(|i| {
            if states[i] == SiteState::Attached {
                (s.u_z[i] / u0[i]).exp() / c_x
            } else {
                0.0
            }
        })
        .collect();
    let gmax = max_abs(s.traction);
    let u: Vec<f64> = matvec(&c.c, s.traction)
        .iter()
        .zip(s.e)
        .map(|(x, e)| x + e + s.offset)
        .collect();
    let scale = (c.norm + max_abs(&compliance)) * gmax + max_abs(s.e) + s.offset.abs();
    for (i, state) in states.iter().enumerate() {
        let bound = tol * scale + c.row_error[i] * gmax;
        prop_assert!(
            (u[i] - s.displacement[i]).abs() <= bound,
            "site {}: u_x = {} vs recomputed {} (bound {:e})",
            i,
            s.displacement[i],
            u[i],
            bound
        );
        if *state == SiteState::Attached {
            let residual = u[i] + s.traction[i] * compliance[i];
            prop_assert!(
                residual.abs() <= bound,
                "site {}: φ_x + k_x u_x: residual {:e} (bound {:e})",
                i,
                residual,
                bound
            );
        } else {
            prop_assert_eq!(s.traction[i], 0.0);
        }
    }
    Ok(())
}

/// Tolerance of the equilibrium checks relative to their scale: the solvers stop at a
/// normwise backward error of 1e-13 (10x margin), and they solve with the plan's `C`,
/// whose error `‖δC‖₂ ≤ PLAN_TOL ‖C‖₂` changes a row of `C f` by at most
/// `PLAN_TOL √N ‖C‖∞ ‖f‖∞`.
fn equilibrium_tolerance(n: usize) -> f64 {
    1e-12 + PLAN_TOL * (n as f64).sqrt()
}

/// Cell-averaged displacement per newton of a lateral load (m/N): the load input of the
/// tangential solve (the rod's table is tested against quadrature in `loads.rs`).
fn unit_load(grid: &Grid, rod: &RodLoad, modulus: f64) -> Vec<f64> {
    let b = grid.block();
    let columns = rod
        .influence_cells(grid, 1e-13 * b.lx() / (b.ly() * b.lz()))
        .unwrap();
    (0..grid.len())
        .map(|i| columns[i % grid.nx()] / modulus)
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    /// Normal and tangential equilibria on random blocks, grids, heights, loads and rod
    /// bands, cold and after random ruptures (warm starts, factor updates), for both
    /// backends: the optimality (KKT) conditions of the normal problem and the tangential
    /// equations, recomputed with the independently assembled reference `C`
    /// ([`check_normal`], [`check_tangential`]); both backends find the same attached set
    /// (the QP's solution is unique).
    #[test]
    fn equilibria_satisfy_their_equations_with_an_independent_operator(
        grid in grids(12, 6),
        seed in 0u64..100_000,
        ln_pressure in (1e5f64).ln()..(1e8f64).ln(),
        band in (0.05f64..0.95, 0.01f64..0.5),
        breaks in proptest::collection::vec(any::<u64>(), 0..5),
    ) {
        check_equilibria(grid, seed, ln_pressure.exp(), band, &breaks)?;
    }
}

/// The body of [`equilibria_satisfy_their_equations_with_an_independent_operator`]:
/// `pressure` in Pa, the rod band `(h/Lz, Δh/Lz scale)`, `breaks` the sites broken (mod N)
/// one after the other, each followed by a normal and a tangential solve.
fn check_equilibria(
    grid: Grid,
    seed: u64,
    pressure: f64,
    band: (f64, f64),
    breaks: &[u64],
) -> std::result::Result<(), TestCaseError> {
    let n = grid.len();
    let material = Material::default();
    let heights = Heights::truncated_gaussian(&grid, HeightDistribution::default(), seed).unwrap();
    let fresh = Interface::new(grid, heights, SpringLaw::default()).unwrap();
    let plan = InfluencePlan::builder(grid)
        .plan_tolerance(PLAN_TOL)
        .build()
        .unwrap();
    let c = reference_compliance(&grid, material.modulus());
    let block = *grid.block();
    let lz = block.lz();
    let half = band.1 * lz * band.0.min(1.0 - band.0) / 0.5;
    let rod = RodLoad::new(&block, band.0 * lz, half.max(1e-3 * lz)).unwrap();
    let e = unit_load(&grid, &rod, material.modulus());
    let load = pressure * block.lx() * block.ly();
    let tol = equilibrium_tolerance(n);
    let mut sets = Vec::new();
    for backend in [Backend::Dense, Backend::Spectral] {
        let mut iface = fresh.clone();
        let mut solver = EquilibriumSolver::builder(plan.clone())
            .material(material)
            .solver_options(SolverOptions::default().with_backend(backend).unwrap())
            .build()
            .unwrap();
        let mut history = Vec::new();
        for step in 0..=breaks.len() {
            if step > 0 {
                if iface.broken_count() + 1 >= n {
                    break;
                }
                iface
                    .break_site((breaks[step - 1] % n as u64) as usize)
                    .unwrap();
            }
            let eq = solver.solve_normal(&iface, load).unwrap();
            iface.set_states(&eq.states).unwrap();
            check_normal(&c, &iface, &eq.traction, &eq.displacement, eq.offset, tol)?;
            let t = solver
                .solve_tangential(&iface, &eq.displacement, &e)
                .unwrap();
            let shear = Shear {
                u_z: &eq.displacement,
                e: &e,
                traction: &t.traction,
                displacement: &t.displacement,
                offset: t.offset_per_newton,
            };
            check_tangential(&c, &iface, &shear, tol)?;
            history.push(iface.states().to_vec());
        }
        sets.push(history);
    }
    prop_assert_eq!(&sets[0], &sets[1]);
    Ok(())
}

/// The two cases proptest once shrank `solver.rs`'s former backend-agreement property
/// to (`proptest-regressions/solver.txt`), kept as fixed cases: a thin stiff block at
/// 71 MPa, and a tall one at 92 MPa after three ruptures.
#[test]
fn former_solver_regressions_satisfy_the_equilibria() {
    let grid = |nx: usize, ny: usize, lz: f64| {
        Grid::new(
            Block::new(nx as f64 * 1e-3, ny as f64 * 1e-3, lz).unwrap(),
            nx,
            ny,
        )
        .unwrap()
    };
    check_equilibria(grid(7, 4, 0.002), 10, 71439245.63076183, (0.5, 0.25), &[0]).unwrap();
    check_equilibria(
        grid(14, 5, 0.09538563110074855),
        308,
        91994294.41505116,
        (0.3, 0.1),
        &[786, 815, 34],
    )
    .unwrap();
}

/// `(1/(Lx Ly)) ∫_face G(x,y,0; 0,η,ζ) dx dy = (2/V) (Lz²/6 - Lz ζ/2 + ζ²/4)` (only the
/// `p = m = 0` terms survive, then `Σ_n cos(k_n ζ)/k_n²` in closed form), averaged over
/// the band `[lo, hi]`: the bottom-face mean of a lateral load's displacement per newton
/// times `M` (m⁻¹).
fn face_mean_of_lateral_influence(block: &Block, lo: f64, hi: f64) -> f64 {
    let lz = block.lz();
    let primitive = |t: f64| lz * lz * t / 6.0 - lz * t * t / 4.0 + t.powi(3) / 12.0;
    2.0 / block.volume() * (primitive(hi) - primitive(lo)) / (hi - lo)
}

#[derive(Debug, Clone, Copy)]
enum TestDrive {
    Spring { stiffness: f64 },
    Mixed { ratio: f64 },
    Top,
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    /// The driver's states on random scenes and drives (a driving spring, mixed or top
    /// force control), through ruptures up to global slip (or 60 events): the shear
    /// tractions and displacements satisfy the tangential equations with the reference
    /// `C`, and under displacement control the spring force is `K_S (U_S - ⟨u_x⟩)` with
    /// `⟨u_x⟩` recomputed from the displacements: the face mean of `u_x` minus the face
    /// means of the lateral load (closed form) and of the traction term (`Σ_j Ĝ_ij ΔA =
    /// Lz/3`, closed form). Under a spring the offset of the tangential check is
    /// `U_S - F/K_S`, not the driver's.
    #[test]
    fn driver_states_satisfy_the_equilibria_and_the_spring_law(
        (nx, ny) in (2usize..=10, 1usize..=4),
        lz in 2e-3f64..0.05,
        seed in 0u64..100_000,
        pressure in 1e6f64..1e7,
        band in (0.1f64..0.9, 0.05f64..0.5),
        side in any::<bool>(),
        drive in prop_oneof![
            ((1e5f64).ln()..(1e8f64).ln()).prop_map(|k| TestDrive::Spring { stiffness: k.exp() }),
            (0.0f64..3.0).prop_map(|ratio| TestDrive::Mixed { ratio }),
            Just(TestDrive::Top),
        ],
    ) {
        let (dx, dy) = (1e-3, 1e-3);
        let (lx, ly) = (nx as f64 * dx, ny as f64 * dy);
        let half = (band.1 * lz * band.0.min(1.0 - band.0) / 0.5).max(1e-3 * lz);
        let lateral = if side {
            Lateral::Side
        } else {
            Lateral::Rod { height: band.0 * lz, half_width: half }
        };
        let scene_drive = match drive {
            TestDrive::Spring { stiffness } => Drive::Spring { stiffness, lateral },
            TestDrive::Mixed { ratio } => Drive::Force(ForceLoad::Mixed { ratio, lateral }),
            TestDrive::Top => Drive::Force(ForceLoad::Top),
        };
        let scene = Scene::builder()
            .block(lx, ly, lz)
            .cells(nx, ny)
            .normal_load(pressure * lx * ly)
            .drive(scene_drive)
            .seed(seed)
            .plan_tolerance(PLAN_TOL)
            .build()
            .unwrap();
        let grid = *scene.grid();
        let n = grid.len();
        let block = *grid.block();
        let modulus = scene.material().modulus();
        let c = reference_compliance(&grid, modulus);
        let rod = match lateral {
            Lateral::Side => RodLoad::uniform_side(&block),
            _ => RodLoad::new(&block, band.0 * lz, half).unwrap(),
        };
        let (lo, hi) = (rod.h() - rod.half_width(), rod.h() + rod.half_width());
        // Lateral part of the driven force F, and the displacement per newton of F.
        let lateral_share = match drive {
            TestDrive::Spring { .. } => 1.0,
            TestDrive::Mixed { ratio } => 1.0 / (1.0 + ratio),
            TestDrive::Top => 0.0,
        };
        let e: Vec<f64> = unit_load(&grid, &rod, modulus).iter().map(|v| v * lateral_share).collect();
        let e_mean = lateral_share * face_mean_of_lateral_influence(&block, lo, hi) / modulus;
        let tol = equilibrium_tolerance(n);
        let mut driver = scene.driver().unwrap();
        let mut checked = 0;
        for _ in 0..60 {
            let Some(event) = driver.step().unwrap() else { break };
            if matches!(event, Event::GlobalSlip { .. }) {
                break;
            }
            // Equilibrium states only: the last rupture leaves the broken state unsolved.
            if !matches!(event, Event::Stable { .. } | Event::LoadRaised { .. }) {
                continue;
            }
            let force = driver.force();
            let phi = driver.shear_traction().unwrap();
            let u_x = driver.shear_displacement().unwrap();
            let u_z = driver.normal_displacement().unwrap().to_vec();
            let e_f: Vec<f64> = e.iter().map(|v| force * v).collect();
            let offset = match (drive, driver.load().drive_displacement) {
                (TestDrive::Spring { stiffness }, Some(u_s)) => {
                    // ⟨u_x⟩ from the displacements: face mean of u_x minus the load's and
                    // the tractions' face means (closed forms).
                    let face_mean = u_x.iter().sum::<f64>() / n as f64;
                    let traction_mean = block.lz() / (3.0 * modulus * n as f64) * phi.iter().sum::<f64>();
                    let mean = face_mean - force * e_mean - traction_mean;
                    let spring = stiffness * (u_s - mean);
                    let scale = max_abs(u_x) + force * max_abs(&e) + mean.abs();
                    prop_assert!((spring - force).abs() <= stiffness * 1e-11 * scale,
                        "K_S (U_S - <u_x>) = {} vs F = {}", spring, force);
                    u_s - force / stiffness
                }
                (TestDrive::Spring { .. }, None) => {
                    return Err(TestCaseError::fail("a spring drive without U_S"));
                }
                _ => driver.mean_shear_displacement().unwrap(),
            };
            if force > 0.0 {
                let shear = Shear { u_z: &u_z, e: &e_f, traction: phi, displacement: u_x, offset };
                check_tangential(&c, driver.interface(), &shear, tol)?;
                checked += 1;
            }
        }
        prop_assert!(checked > 0);
    }
}

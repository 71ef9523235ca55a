//! The Galerkin grid operator: DCT path against the naive dense path, SPD, entries against
//! 4-D quadrature of the point Green function, and the transfer to a plane.

use crate::common::{rel, rule};
use faer::{Mat, Side};
use precursors::green::{GreenFunction, InfluencePlan};
use precursors::{Block, Grid, Point};

fn lcg(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*seed >> 11) as f64) / (1u64 << 53) as f64 - 0.5
}

fn grids() -> Vec<Grid> {
    let b = Block::new(0.014, 0.005, 0.01).unwrap();
    vec![
        Grid::new(b, 14, 5).unwrap(),
        Grid::new(b, 7, 1).unwrap(),
        Grid::new(b, 1, 4).unwrap(),
        Grid::new(b, 1, 1).unwrap(),
        Grid::new(Block::new(0.14, 0.007, 0.075).unwrap(), 140, 7).unwrap(),
        // Either side of the switch from direct y-products to rustdct columns (Ny = 16).
        Grid::new(Block::new(0.02, 0.016, 0.01).unwrap(), 20, 16).unwrap(),
        Grid::new(Block::new(0.02, 0.017, 0.01).unwrap(), 20, 17).unwrap(),
        // Both sides even, Ny > 16: the paired-FFT transforms.
        Grid::new(Block::new(0.02, 0.018, 0.01).unwrap(), 20, 18).unwrap(),
    ]
}

#[test]
fn matrix_free_apply_equals_dense_matvec() {
    for grid in grids() {
        let plan = InfluencePlan::builder(grid).build().unwrap();
        let n = grid.len();
        let dense = plan.dense().unwrap();
        let mut seed = 7u64;
        let v: Vec<f64> = (0..n).map(|_| lcg(&mut seed)).collect();
        let mut fast = vec![0.0; n];
        plan.apply(&v, &mut fast).unwrap();
        let scale = dense.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for i in 0..n {
            let slow: f64 = (0..n).map(|j| dense[i * n + j] * v[j]).sum();
            assert!(
                (fast[i] - slow).abs() <= 1e-12 * scale * n as f64,
                "{grid:?} row {i}: {} vs {slow}",
                fast[i]
            );
        }
    }
}

#[test]
fn dense_operator_is_symmetric_positive_definite() {
    for grid in grids().into_iter().take(4) {
        let plan = InfluencePlan::builder(grid).build().unwrap();
        let n = grid.len();
        let d = plan.dense().unwrap();
        for i in 0..n {
            for j in 0..i {
                assert!((d[i * n + j] - d[j * n + i]).abs() <= 1e-13 * d[i * n + i]);
            }
        }
        let m = Mat::from_fn(n, n, |i, j| d[i * n + j]);
        assert!(m.llt(Side::Lower).is_ok(), "{grid:?}: Cholesky failed");
        let eig = m.self_adjoint_eigenvalues(Side::Lower).unwrap();
        assert!(eig[0] > 0.0, "smallest eigenvalue {}", eig[0]);
        // The spectrum is the eigenvalue table.
        let mut table: Vec<f64> = (0..grid.ny())
            .flat_map(|mm| (0..grid.nx()).map(move |p| (p, mm)))
            .map(|(p, mm)| plan.eigenvalue(p, mm).unwrap())
            .collect();
        table.sort_by(f64::total_cmp);
        for (a, b) in eig.iter().zip(&table) {
            assert!(rel(*a, *b, 1e-300) < 1e-10, "{a} vs {b}");
        }
    }
}

#[test]
fn entries_equal_cell_quadrature_of_the_point_function() {
    // Reference: (1/ΔA²) ∫_i ∫_j G(x,ξ;y,η;0,0) by 4-D Gauss–Legendre over two cells that
    // do not touch, with G from the rapid point representation.
    let block = Block::new(0.016, 0.006, 0.01).unwrap();
    let grid = Grid::new(block, 16, 6).unwrap();
    let plan = InfluencePlan::builder(grid)
        .plan_tolerance(1e-9)
        .build()
        .unwrap();
    let n = grid.len();
    let dense = plan.dense().unwrap();
    let gf = GreenFunction::new(block);
    let (dx, dy) = (grid.dx(), grid.dy());
    let pairs = [
        ((0, 0), (3, 2)),
        ((5, 1), (12, 4)),
        ((7, 3), (7, 5)),
        ((2, 5), (15, 0)),
        ((9, 2), (11, 2)),
    ];
    for ((ix, iy), (jx, jy)) in pairs {
        let quad = |c: usize, d: f64| rule(c as f64 * d, (c + 1) as f64 * d, 1, 6);
        let (qx, qy, qxi, qeta) = (quad(ix, dx), quad(iy, dy), quad(jx, dx), quad(jy, dy));
        let mut sum = 0.0;
        for &(x, wx) in &qx {
            for &(y, wy) in &qy {
                for &(xi, wxi) in &qxi {
                    for &(eta, weta) in &qeta {
                        let v = gf
                            .value(Point::new(x, y, 0.0), Point::new(xi, eta, 0.0), 1e-11)
                            .unwrap()
                            .value;
                        sum += wx * wy * wxi * weta * v;
                    }
                }
            }
        }
        let reference = sum / (dx * dy).powi(2);
        let entry = dense[grid.index(ix, iy).unwrap() * n + grid.index(jx, jy).unwrap()];
        assert!(
            rel(entry, reference, 1e-300) < 2e-7,
            "({ix},{iy})-({jx},{jy}): {entry} vs {reference}"
        );
        // Point value at the centres: within O(Δ²/r²) of the Galerkin entry.
        let (cx, cy) = grid.centre(ix, iy).unwrap();
        let (sx, sy) = grid.centre(jx, jy).unwrap();
        let r2 = (cx - sx).powi(2) + (cy - sy).powi(2);
        let point = gf
            .value(Point::new(cx, cy, 0.0), Point::new(sx, sy, 0.0), 1e-11)
            .unwrap()
            .value;
        // Averaging over two cells changes a smooth kernel by (Δ²/24)·(second derivatives):
        // O(Δ²/r²) relative to the 1/(2πr) face kernel, plus O(Δ²/V) from the smooth,
        // zero-mean part of the Neumann function (∇²G = 1/V), large for this small block.
        let r = r2.sqrt();
        let bound =
            dx * dx * (1.0 / (2.0 * std::f64::consts::PI * r.powi(3)) + 1.0 / block.volume());
        assert!(
            (entry - point).abs() < bound,
            "point {point} vs entry {entry}, bound {bound}"
        );
    }
}

#[test]
fn the_point_value_error_shrinks_like_delta_squared_over_r_squared() {
    // The paper's block, where the smooth O(Δ²/V) part is small.
    let block = Block::new(0.14, 0.007, 0.075).unwrap();
    let grid = Grid::new(block, 140, 7).unwrap();
    let plan = InfluencePlan::builder(grid)
        .plan_tolerance(1e-8)
        .build()
        .unwrap();
    let n = grid.len();
    let dense = plan.dense().unwrap();
    let gf = GreenFunction::new(block);
    let ratio = |jx: usize| {
        let (cx, cy) = grid.centre(60, 3).unwrap();
        let (sx, sy) = grid.centre(jx, 3).unwrap();
        let point = gf
            .value(Point::new(cx, cy, 0.0), Point::new(sx, sy, 0.0), 1e-12)
            .unwrap()
            .value;
        let entry = dense[grid.index(60, 3).unwrap() * n + grid.index(jx, 3).unwrap()];
        let r = (cx - sx).abs();
        (entry - point).abs() * 4.0 * std::f64::consts::PI * r.powi(3) / grid.dx().powi(2)
    };
    // |Ĝ - G|·4πr³/Δ² stays bounded as r grows from 2Δ to 8Δ: the error is O(Δ²/r²)
    // relative to the 1/(4πr) scale of the kernel.
    for jx in [62, 64, 68] {
        let c = ratio(jx);
        assert!(c < 0.5, "r = {}Δ: |Ĝ - G|·4πr³/Δ² = {c}", jx - 60);
    }
}

/// The eigenvalue by its definition (docs/model.md section 2, crate::green::plan): the
/// alias sum `(4/(Lx Ly)) Σ_{|q|,|r| ≤ Q} S_q² S_r² coth(κ Lz)/κ` summed term by term, with
/// the leading tails of the two strips outside the box in closed form (`coth = 1` there,
/// `Σ_{|q|>Q} 1/|θ + qπ|³` by Euler–Maclaurin). An independent algorithm: the crate
/// integrates a Gaussian representation instead; at Q = 2048 this sum is good to about
/// 1e-12 on square cells.
fn eigenvalue_by_alias_box(grid: &Grid, p: usize, m: usize, q_max: i64) -> f64 {
    use std::f64::consts::PI;
    let b = grid.block();
    if p == 0 && m == 0 {
        return b.lz() / (3.0 * b.lx() * b.ly());
    }
    let axis = |mode: usize, n: usize, cell: f64| -> (f64, Vec<(f64, f64)>) {
        let theta = mode as f64 * PI / (2.0 * n as f64);
        if mode == 0 {
            return (theta, vec![(0.5, 0.0)]);
        }
        let s2 = theta.sin().powi(2);
        let terms = (-q_max..=q_max)
            .map(|q| {
                let t = theta + q as f64 * PI;
                (s2 / (t * t), 2.0 * t.abs() / cell)
            })
            .collect();
        (theta, terms)
    };
    let tail = |theta: f64| -> f64 {
        [theta / PI, -theta / PI]
            .iter()
            .map(|a| {
                let c = q_max as f64 + 0.5 + a;
                1.0 / (2.0 * c * c) + 1.0 / (8.0 * c.powi(4)) - 7.0 / (96.0 * c.powi(6))
            })
            .sum::<f64>()
            / PI.powi(3)
    };
    let (tx, ax) = axis(p, grid.nx(), grid.dx());
    let (ty, ay) = axis(m, grid.ny(), grid.dy());
    let lz = b.lz();
    // Compensated (Neumaier) summation: 1.7e7 positive terms summed naively lose about
    // 3e-11.
    let (mut sum, mut carry) = (0.0f64, 0.0f64);
    for &(wx, kx) in &ax {
        for &(wy, ky) in &ay {
            let k = kx.hypot(ky);
            let term = wx * wy / (k * (k * lz).tanh());
            let t = sum + term;
            carry += if sum.abs() >= term.abs() {
                (sum - t) + term
            } else {
                (term - t) + sum
            };
            sum = t;
        }
    }
    let mut sum = sum + carry;
    let weight = |a: &[(f64, f64)]| a.iter().map(|t| t.0).sum::<f64>();
    if p != 0 {
        sum += weight(&ay) * tx.sin().powi(2) * grid.dx() / 2.0 * tail(tx);
    }
    if m != 0 {
        sum += weight(&ax) * ty.sin().powi(2) * grid.dy() / 2.0 * tail(ty);
    }
    4.0 / (b.lx() * b.ly()) * sum
}

/// The plan's eigenvalues against their definition summed term by term
/// ([`eigenvalue_by_alias_box`]), on square cells (deep and thinner than a cell), long
/// thin and anisotropic grids, low, high and mixed modes; and their error estimates.
#[test]
fn eigenvalues_match_the_alias_sum_and_their_estimates_are_small() {
    let cases = [
        (Block::new(0.2, 0.05, 0.075).unwrap(), 200, 50),
        (Block::new(0.14, 0.007, 0.075).unwrap(), 140, 7),
        (Block::new(0.05, 0.05, 0.0001).unwrap(), 50, 50),
        (Block::new(0.064, 0.128, 0.02).unwrap(), 64, 32),
        (Block::new(0.1, 0.001, 0.01).unwrap(), 100, 1),
    ];
    for (block, nx, ny) in cases {
        let grid = Grid::new(block, nx, ny).unwrap();
        let plan = InfluencePlan::builder(grid)
            .plan_tolerance(1e-12)
            .build()
            .unwrap();
        assert!(plan.max_relative_error() <= 1e-12);
        let modes = [
            (1, 0),
            (0, 1),
            (1, 1),
            (nx / 2, ny / 2),
            (nx - 1, ny - 1),
            (nx - 1, 0),
            (0, ny - 1),
            (3, ny / 3),
        ];
        // Anisotropic cells: the box sum converges more slowly.
        let (q, tol) = if grid.dx() == grid.dy() {
            (2048, 2e-12)
        } else {
            (4096, 5e-12)
        };
        for (p, m) in modes.into_iter().filter(|&(p, m)| p < nx && m < ny) {
            let reference = eigenvalue_by_alias_box(&grid, p, m, q);
            // λ = eigenvalue · α_p'² α_m'² (α_0² = 1/N, α_{>0}² = 2/N): the orthonormal
            // basis's eigenvalue in the module docs' normalisation.
            let alpha = |k: usize, n: usize| {
                if k == 0 {
                    1.0 / n as f64
                } else {
                    2.0 / n as f64
                }
            };
            let value = plan.eigenvalue(p, m).unwrap() * alpha(p, nx) * alpha(m, ny);
            assert!(
                rel(value, reference, 1e-300) <= tol,
                "{nx} x {ny}, Lz = {}: mode ({p},{m}): {value} vs {reference}",
                block.lz()
            );
        }
    }
    // A tolerance the estimates cannot certify is refused, not met silently.
    let grid = Grid::new(Block::new(0.2, 0.05, 0.075).unwrap(), 200, 50).unwrap();
    let e = InfluencePlan::builder(grid)
        .plan_tolerance(1e-15)
        .build()
        .unwrap_err();
    assert!(
        matches!(e, precursors::Error::SeriesNotConverged { .. }),
        "{e:?}"
    );
    assert!(e.to_string().contains("about 1e-13 at best"), "{e}");
}

#[test]
fn row_sums_match_the_face_integral_of_g() {
    // ∫_face G(x,ξ;y,η;0,0) dξdη = Lz/3 (only the n-series of the mean survives:
    // (2/Lz) Σ_n (Lz/nπ)² = Lz/3), so Σ_j Ĝ_ij ΔA = Lz/3 for every cell i.
    let block = Block::new(0.014, 0.005, 0.01).unwrap();
    let grid = Grid::new(block, 14, 5).unwrap();
    let plan = InfluencePlan::builder(grid).build().unwrap();
    let n = grid.len();
    let d = plan.dense().unwrap();
    for i in 0..n {
        let s: f64 = d[i * n..(i + 1) * n].iter().sum::<f64>() * grid.cell_area();
        assert!(rel(s, block.lz() / 3.0, 1e-300) < 1e-12);
    }
}

#[test]
fn plane_transfer_is_identity_at_the_bottom_and_exact_for_the_mean() {
    let block = Block::new(0.014, 0.005, 0.01).unwrap();
    let grid = Grid::new(block, 14, 5).unwrap();
    let plan = InfluencePlan::builder(grid).build().unwrap();
    let n = grid.len();
    let mut seed = 3u64;
    let phi: Vec<f64> = (0..n).map(|_| lcg(&mut seed)).collect();
    let mut out = vec![0.0; n];
    plan.plane_transfer(0.0, 1e-12)
        .unwrap()
        .stress(&phi, &mut out)
        .unwrap();
    for (s, f) in out.iter().zip(&phi) {
        assert!((s + f).abs() < 1e-13);
    }
    let z = 0.004;
    plan.plane_transfer(z, 1e-12)
        .unwrap()
        .stress(&vec![2.0; n], &mut out)
        .unwrap();
    for s in &out {
        assert!(rel(*s, -2.0 * (block.lz() - z) / block.lz(), 1.0) < 1e-13);
    }
}

#[test]
fn plane_transfer_equals_quadrature_of_dg_dz() {
    // Reference: stress at height z averaged over cell i from a unit traction on cell j,
    // (1/ΔA) ∫_i ∫_j ∂G/∂z(x,ξ;y,η;z,0) dA' dA, by Gauss–Legendre.
    let block = Block::new(0.014, 0.005, 0.01).unwrap();
    let grid = Grid::new(block, 14, 5).unwrap();
    let plan = InfluencePlan::builder(grid).build().unwrap();
    let gf = GreenFunction::new(block);
    let n = grid.len();
    let z = 0.002;
    let transfer = plan.plane_transfer(z, 1e-12).unwrap();
    let j = grid.index(5, 2).unwrap();
    let mut unit = vec![0.0; n];
    unit[j] = 1.0;
    let mut out = vec![0.0; n];
    transfer.stress(&unit, &mut out).unwrap();
    let (dx, dy) = (grid.dx(), grid.dy());
    let q = |c: usize, d: f64| rule(c as f64 * d, (c + 1) as f64 * d, 2, 6);
    for (ix, iy) in [(5, 2), (6, 2), (8, 4), (0, 0)] {
        let mut sum = 0.0;
        for &(x, wx) in &q(ix, dx) {
            for &(y, wy) in &q(iy, dy) {
                for &(xi, wxi) in &q(5, dx) {
                    for &(eta, weta) in &q(2, dy) {
                        let v = gf
                            .dz(Point::new(x, y, z), Point::new(xi, eta, 0.0), 1e-9)
                            .unwrap()
                            .value;
                        sum += wx * wy * wxi * weta * v;
                    }
                }
            }
        }
        let reference = sum / (dx * dy);
        let got = out[grid.index(ix, iy).unwrap()];
        assert!(
            (got - reference).abs() < 1e-6 * 0.1_f64.max(reference.abs()),
            "cell ({ix},{iy}): {got} vs {reference}"
        );
    }
}

/// `apply_with_scratch` equals the dense matrix-vector product (assembled from the
/// eigenvalues and cosines, without the DCT) on every transform path, whatever the
/// scratch held before, allocates nothing after the first product, and refuses a short
/// scratch.
#[test]
fn apply_with_scratch_equals_dense_matvec_and_allocates_nothing() {
    let mut grids = grids();
    for (nx, ny) in [(21, 30), (60, 40), (34, 66), (15, 67), (40, 8)] {
        let block = Block::new(nx as f64 * 1e-3, ny as f64 * 1e-3, 0.03).unwrap();
        grids.push(Grid::new(block, nx, ny).unwrap());
    }
    for grid in grids {
        let plan = InfluencePlan::builder(grid).build().unwrap();
        let n = grid.len();
        let dense = plan.dense().unwrap();
        let mut seed = 11u64;
        let v: Vec<f64> = (0..n).map(|_| lcg(&mut seed)).collect();
        let mut scratch = vec![f64::NAN; plan.scratch_len()];
        let mut u = v.clone();
        // One product first: faer's matrix product (the y-transforms of 17 to 64 rows)
        // sets up a per-thread buffer once.
        plan.apply_with_scratch(&mut u, &mut scratch).unwrap();
        let before = crate::common::allocations::count();
        for _ in 0..3 {
            u.copy_from_slice(&v);
            plan.apply_with_scratch(&mut u, &mut scratch).unwrap();
        }
        assert_eq!(
            crate::common::allocations::count(),
            before,
            "{grid:?}: apply_with_scratch allocated"
        );
        let scale = dense.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for i in 0..n {
            let slow: f64 = (0..n).map(|j| dense[i * n + j] * v[j]).sum();
            assert!(
                (u[i] - slow).abs() <= 1e-12 * scale * n as f64,
                "{grid:?} row {i}: {} vs {slow}",
                u[i]
            );
        }
        if plan.scratch_len() > 0 {
            let short = plan.scratch_len() - 1;
            assert!(matches!(
                plan.apply_with_scratch(&mut u, &mut vec![0.0; short]),
                Err(precursors::Error::LengthMismatch { expected, found, .. })
                    if expected == plan.scratch_len() && found == short
            ));
        }
    }
}

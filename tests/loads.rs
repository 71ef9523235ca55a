//! Analytic load terms against numerical quadrature of the point Green function over the
//! loaded face (an independent computation: Gauss–Legendre over the rapid point series).

use crate::common::{rel, rule};
use precursors::green::{top_influence, top_stress_influence};
use precursors::green::{GreenFunction, RodLoad};
use precursors::{Block, Grid, Point};

fn block() -> Block {
    Block::new(0.05, 0.006, 0.03).unwrap()
}

#[test]
fn top_load_is_the_face_integral_of_g() {
    let b = block();
    let gf = GreenFunction::new(b);
    for (x, y) in [(0.01, 0.002), (0.037, 0.0055)] {
        let mut q = 0.0;
        for (xi, wx) in rule(0.0, b.lx(), 10, 8) {
            for (eta, wy) in rule(0.0, b.ly(), 2, 8) {
                q += wx
                    * wy
                    * gf.value(Point::new(x, y, 0.0), Point::new(xi, eta, b.lz()), 1e-12)
                        .unwrap()
                        .value;
            }
        }
        let q = q / (b.lx() * b.ly());
        assert!(
            rel(top_influence(&b), q, 1e-300) < 1e-9,
            "{} vs {q}",
            top_influence(&b)
        );
    }
}

#[test]
fn top_stress_is_the_face_integral_of_dg_dz() {
    let b = block();
    let gf = GreenFunction::new(b);
    for z in [0.002, 0.015] {
        let mut q = 0.0;
        for (xi, wx) in rule(0.0, b.lx(), 10, 8) {
            for (eta, wy) in rule(0.0, b.ly(), 2, 8) {
                q += wx
                    * wy
                    * gf.dz(
                        Point::new(0.02, 0.003, z),
                        Point::new(xi, eta, b.lz()),
                        1e-10,
                    )
                    .unwrap()
                    .value;
            }
        }
        let q = q / (b.lx() * b.ly());
        let v = top_stress_influence(&b, z).unwrap();
        assert!(rel(v, q, 1e-300) < 1e-8, "z {z}: {v} vs {q}");
    }
}

fn rod_quadrature(gf: &GreenFunction, rod: &RodLoad, x: f64, z: f64, dz: bool) -> f64 {
    let b = gf.block();
    let (lo, hi) = (rod.h() - rod.half_width(), rod.h() + rod.half_width());
    let mut q = 0.0;
    for (eta, we) in rule(0.0, b.ly(), 4, 10) {
        for (zeta, wz) in rule(lo, hi, 8, 10) {
            let (r, s) = (Point::new(x, 0.002, z), Point::new(0.0, eta, zeta));
            let v = if dz {
                gf.dz(r, s, 1e-11)
            } else {
                gf.value(r, s, 1e-12)
            };
            q += we * wz * v.unwrap().value;
        }
    }
    q / (2.0 * rod.half_width() * b.ly())
}

#[test]
fn rod_load_is_the_band_integral_of_g() {
    // Reference includes every constant of the closed form (paper Eq. G_x_lat).
    let b = block();
    let gf = GreenFunction::new(b);
    for rod in [
        RodLoad::new(&b, 0.006, 0.002).unwrap(),
        RodLoad::new(&b, 0.02, 0.005).unwrap(),
    ] {
        for x in [0.008, 0.02, 0.045] {
            let q = rod_quadrature(&gf, &rod, x, 0.0, false);
            let v = rod.influence_at(x, 1e-12).unwrap();
            assert!(rel(v.value, q, 1.0) < 1e-8, "x {x}: {v:?} vs {q}");
        }
    }
}

#[test]
fn rod_stress_is_the_band_integral_of_dg_dz() {
    let b = block();
    let gf = GreenFunction::new(b);
    let rod = RodLoad::new(&b, 0.006, 0.002).unwrap();
    for (x, z) in [(0.008, 0.002), (0.015, 0.007), (0.03, 0.02)] {
        let q = rod_quadrature(&gf, &rod, x, z, true);
        let v = rod.stress_influence_at(x, z, 1e-10).unwrap();
        assert!(
            (v.value - q).abs() < 1e-7 * q.abs().max(1.0),
            "({x},{z}): {v:?} vs {q}"
        );
    }
}

#[test]
fn cell_averages_equal_quadrature_of_the_point_formulas() {
    // The first cell uses closed-form Clausen sums; the reference averages the point
    // series, summed term by term, with Gauss–Legendre over each cell.
    let b = block();
    let grid = Grid::new(b, 25, 3).unwrap();
    let rod = RodLoad::new(&b, 0.006, 0.002).unwrap();
    let cells = rod.influence_cells(&grid, 1e-12).unwrap();
    let z = 0.002;
    let stress = rod.stress_influence_cells(&grid, z, 1e-10).unwrap();
    let dx = grid.dx();
    for ix in [0, 1, 2, 10, 24] {
        let (a, c) = (ix as f64 * dx, (ix + 1) as f64 * dx);
        let q: f64 = rule(a, c, 4, 12)
            .into_iter()
            .map(|(x, w)| w * rod.influence_at(x, 1e-13).unwrap().value)
            .sum::<f64>()
            / dx;
        assert!(
            rel(cells[ix], q, 1.0) < 1e-9,
            "cell {ix}: {} vs {q}",
            cells[ix]
        );
        let qs: f64 = rule(a, c, 4, 12)
            .into_iter()
            .map(|(x, w)| w * rod.stress_influence_at(x, z, 1e-12).unwrap().value)
            .sum::<f64>()
            / dx;
        assert!(
            (stress[ix] - qs).abs() < 1e-6 * qs.abs().max(1.0),
            "stress cell {ix}: {} vs {qs}",
            stress[ix]
        );
    }
}

#[test]
fn uniform_side_load_is_the_polynomial_of_model_md() {
    // docs/model.md: for the uniform side load only Lx(x²/(2Lx²) - x/Lx + 1/3)/(Ly Lz) remains,
    // and the stress it adds inside the block vanishes.
    let b = block();
    let grid = Grid::new(b, 10, 2).unwrap();
    let side = RodLoad::uniform_side(&b);
    let cells = side.influence_cells(&grid, 1e-13).unwrap();
    let lx = b.lx();
    for (ix, v) in cells.iter().enumerate() {
        let (a, c) = (ix as f64 * grid.dx(), (ix + 1) as f64 * grid.dx());
        // Exact average of the quadratic by Simpson's rule.
        let p = |x: f64| lx * (x * x / (2.0 * lx * lx) - x / lx + 1.0 / 3.0) / (b.ly() * b.lz());
        let avg = (p(a) + 4.0 * p(0.5 * (a + c)) + p(c)) / 6.0;
        assert!(rel(*v, avg, 1.0) < 1e-12, "cell {ix}: {v} vs {avg}");
    }
    for v in side.stress_influence_cells(&grid, 0.01, 1e-12).unwrap() {
        assert!(v.abs() < 1e-9);
    }
}

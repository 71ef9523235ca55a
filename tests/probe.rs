//! Stress probes against independent references:
//! * a finite-volume solve of the same Neumann problem (cell-centred, second order, its
//!   discrete Laplacian diagonalised by DCTs: discrete eigenvalues, no alias series),
//!   Richardson-extrapolated: bottom displacements and stresses at z = 2 mm;
//! * force balance through any plane (closed form: the flux of the loads above it);
//! * point probes averaged over a cell by Gauss–Legendre quadrature against the plane;
//! * z = 0: the interface tractions.

use crate::common::rule;
use precursors::green::{InfluencePlan, RodLoad};
use precursors::*;
use precursors::{ProbeInput, ProbeSpec, StressProbe};
use rustdct::DctPlanner;

/// 16 x 4 x 8 mm, 8 x 2 cells of 2 mm; rod band [2, 4] mm.
fn setup() -> (Grid, InfluencePlan, RodLoad) {
    let block = Block::new(0.016, 0.004, 0.008).unwrap();
    let grid = Grid::new(block, 8, 2).unwrap();
    let plan = InfluencePlan::builder(grid)
        .plan_tolerance(1e-11)
        .build()
        .unwrap();
    let rod = RodLoad::new(&block, 3e-3, 1e-3).unwrap();
    (grid, plan, rod)
}

/// Cell tractions with a prescribed total `ΔA Σ φ = total` (deterministic pattern).
fn tractions(grid: &Grid, total: f64, salt: usize) -> Vec<f64> {
    let n = grid.len();
    let raw: Vec<f64> = (0..n)
        .map(|i| 1.0 + 0.6 * (((i * 7 + salt * 13) % 11) as f64 / 10.0 - 0.5))
        .collect();
    let sum: f64 = raw.iter().sum::<f64>() * grid.cell_area();
    raw.iter().map(|r| r * total / sum).collect()
}

/// In-place unnormalised DCT-II, or rustdct's DCT-III (`x_0/2 + Σ x_p cos`, `n/2` times the
/// inverse), along one axis of an `n0 x n1 x n2` array (index `(i0*n1+i1)*n2+i2`).
fn dct_axis(
    a: &mut [f64],
    dims: [usize; 3],
    axis: usize,
    inverse: bool,
    planner: &mut DctPlanner<f64>,
) {
    let n = dims[axis];
    let plan = if inverse {
        planner.plan_dct3(n)
    } else {
        planner.plan_dct2(n)
    };
    let stride = match axis {
        0 => dims[1] * dims[2],
        1 => dims[2],
        _ => 1,
    };
    let mut line = vec![0.0; n];
    for i0 in 0..dims[0] {
        for i1 in 0..dims[1] {
            for i2 in 0..dims[2] {
                let idx = [i0, i1, i2];
                if idx[axis] != 0 {
                    continue;
                }
                let base = (i0 * dims[1] + i1) * dims[2] + i2;
                for (k, l) in line.iter_mut().enumerate() {
                    *l = a[base + k * stride];
                }
                if inverse {
                    plan.process_dct3(&mut line);
                } else {
                    plan.process_dct2(&mut line);
                }
                for (k, l) in line.iter().enumerate() {
                    a[base + k * stride] = *l;
                }
            }
        }
    }
}

/// Finite-volume solve of `∇²u = 0` in the box with `∂u/∂n = t/M` on the faces, `h` the
/// mesh size, tractions given per boundary face centre by the closures. Returns the cell
/// values (mean removed), `dims = [nx, ny, nz]`, index `(ix*ny+iy)*nz+iz`.
struct Fv {
    u: Vec<f64>,
    dims: [usize; 3],
    h: f64,
}

fn fv_solve(
    block: &Block,
    h: f64,
    modulus: f64,
    bottom: impl Fn(f64, f64) -> f64,
    top: f64,
    trailing: impl Fn(f64) -> f64,
) -> Fv {
    let dims = [
        (block.lx() / h).round() as usize,
        (block.ly() / h).round() as usize,
        (block.lz() / h).round() as usize,
    ];
    let [nx, ny, nz] = dims;
    let idx = |i: usize, j: usize, k: usize| (i * ny + j) * nz + k;
    // Σ_nb (u_nb - u) = -(h/M) Σ_boundary faces t.
    let mut b = vec![0.0; nx * ny * nz];
    for i in 0..nx {
        for j in 0..ny {
            let (x, y) = ((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
            b[idx(i, j, 0)] -= h / modulus * bottom(x, y);
            b[idx(i, j, nz - 1)] -= h / modulus * top;
        }
    }
    for j in 0..ny {
        for k in 0..nz {
            b[idx(0, j, k)] -= h / modulus * trailing((k as f64 + 0.5) * h);
        }
    }
    let mut planner = DctPlanner::new();
    for axis in 0..3 {
        dct_axis(&mut b, dims, axis, false, &mut planner);
    }
    let eig =
        |p: usize, n: usize| -(2.0 - 2.0 * (std::f64::consts::PI * p as f64 / n as f64).cos());
    for p in 0..nx {
        for m in 0..ny {
            for q in 0..nz {
                let l = eig(p, nx) + eig(m, ny) + eig(q, nz);
                let v = &mut b[idx(p, m, q)];
                *v = if p + m + q == 0 { 0.0 } else { *v / l };
            }
        }
    }
    for axis in 0..3 {
        dct_axis(&mut b, dims, axis, true, &mut planner);
    }
    // DCT-II then DCT-III is n/2 times the identity per axis.
    let scale = 8.0 / (nx * ny * nz) as f64;
    b.iter_mut().for_each(|v| *v *= scale);
    Fv { u: b, dims, h }
}

impl Fv {
    /// Bottom-face values `u(x, y, 0) ≈ u_c + (h/2) φ/M`, averaged over the coarse cells.
    fn bottom(&self, grid: &Grid, traction: &[f64], modulus: f64) -> Vec<f64> {
        let [nx, ny, nz] = self.dims;
        let (fx, fy) = (nx / grid.nx(), ny / grid.ny());
        let mut out = vec![0.0; grid.len()];
        for i in 0..nx {
            for j in 0..ny {
                let c = grid.index(i / fx, j / fy).unwrap();
                let v = self.u[(i * ny + j) * nz] + 0.5 * self.h * traction[c] / modulus;
                out[c] += v / (fx * fy) as f64;
            }
        }
        out
    }

    /// `M ∂u/∂z` on the mesh plane `z`, averaged over the coarse cells.
    fn stress(&self, grid: &Grid, z: f64, modulus: f64) -> Vec<f64> {
        let [nx, ny, nz] = self.dims;
        let k = (z / self.h).round() as usize;
        let (fx, fy) = (nx / grid.nx(), ny / grid.ny());
        let mut out = vec![0.0; grid.len()];
        for i in 0..nx {
            for j in 0..ny {
                let base = (i * ny + j) * nz;
                let d = modulus * (self.u[base + k] - self.u[base + k - 1]) / self.h;
                out[grid.index(i / fx, j / fy).unwrap()] += d / (fx * fy) as f64;
            }
        }
        out
    }
}

fn remove_mean(v: &mut [f64]) {
    let m = v.iter().sum::<f64>() / v.len() as f64;
    v.iter_mut().for_each(|x| *x -= m);
}

fn max_rel(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs() / scale))
}

/// Richardson extrapolation of second-order results at h and h/2.
fn richardson(coarse: &[f64], fine: &[f64]) -> Vec<f64> {
    coarse
        .iter()
        .zip(fine)
        .map(|(c, f)| (4.0 * f - c) / 3.0)
        .collect()
}

#[test]
fn probes_and_displacements_match_a_finite_volume_solve() {
    let (grid, plan, rod) = setup();
    let block = *grid.block();
    let m = Material::default().modulus();
    let area = block.lx() * block.ly();
    let (f_top, f_lat, f_n) = (3.0, 5.0, 40.0);
    let phi_x = tractions(&grid, -(f_top + f_lat), 1);
    let phi_z = tractions(&grid, f_n, 2);
    let z_p = 2e-3;
    let probe = StressProbe::new(
        &plan,
        &ProbeSpec::default()
            .with_plane(z_p)
            .with_tolerance(1e-13)
            .unwrap(),
        Some(&rod),
    )
    .unwrap();
    let input = ProbeInput::new(&phi_x, &phi_z)
        .with_loads(f_top, f_lat, f_n)
        .unwrap();
    let crate_plane = &probe.evaluate(&input).unwrap().planes[0];

    // Crate bottom displacements: (ΔA/M) Ĝ φ + lateral term (constants dropped).
    let lateral = rod.influence_cells(&grid, 1e-14).unwrap();
    let mut ux = vec![0.0; grid.len()];
    plan.apply(&phi_x, &mut ux).unwrap();
    for (i, u) in ux.iter_mut().enumerate() {
        *u = grid.cell_area() / m * *u + f_lat / m * lateral[i % grid.nx()];
    }
    let mut uz = vec![0.0; grid.len()];
    plan.apply(&phi_z, &mut uz).unwrap();
    uz.iter_mut().for_each(|u| *u *= grid.cell_area() / m);
    remove_mean(&mut ux);
    remove_mean(&mut uz);

    let cell = |x: f64, y: f64| {
        grid.index((x / grid.dx()) as usize, (y / grid.dy()) as usize)
            .unwrap()
    };
    let band = |z: f64| {
        if (2e-3..4e-3).contains(&z) {
            f_lat / (block.ly() * 2e-3)
        } else {
            0.0
        }
    };
    let mut results = Vec::new();
    for h in [1.25e-4, 6.25e-5] {
        let x = fv_solve(&block, h, m, |x, y| phi_x[cell(x, y)], f_top / area, band);
        let z = fv_solve(&block, h, m, |x, y| phi_z[cell(x, y)], -f_n / area, |_| 0.0);
        let mut bx = x.bottom(&grid, &phi_x, m);
        let mut bz = z.bottom(&grid, &phi_z, m);
        remove_mean(&mut bx);
        remove_mean(&mut bz);
        results.push([bx, bz, x.stress(&grid, z_p, m), z.stress(&grid, z_p, m)]);
    }
    let names = ["u_x(z=0)", "u_z(z=0)", "tau(z=2mm)", "sigma(z=2mm)"];
    let crate_values = [&ux[..], &uz[..], crate_plane.shear(), crate_plane.normal()];
    for q in 0..4 {
        let fine = &results[1][q];
        let extrapolated = richardson(&results[0][q], fine);
        let before = max_rel(fine, crate_values[q]);
        let after = max_rel(&extrapolated, crate_values[q]);
        eprintln!("{}: FV h/2 {before:.2e}, Richardson {after:.2e}", names[q]);
        assert!(after < 1e-3, "{}: {after:e}", names[q]);
    }
}

#[test]
fn force_balance_through_every_plane() {
    let (grid, plan, rod) = setup();
    let (f_top, f_lat, f_n) = (2.0, 7.0, 30.0);
    let heights = [0.0, 1e-3, 2e-3, 2.5e-3, 3.7e-3, 4e-3, 6e-3, 8e-3];
    let mut spec = ProbeSpec::default();
    for z in heights {
        spec = spec.with_plane(z);
    }
    let probe = StressProbe::new(&plan, &spec, Some(&rod)).unwrap();
    let phi_x = tractions(&grid, -(f_top + f_lat), 3);
    let phi_z = tractions(&grid, f_n, 4);
    let input = ProbeInput::new(&phi_x, &phi_z)
        .with_loads(f_top, f_lat, f_n)
        .unwrap();
    let out = probe.evaluate(&input).unwrap();
    for (plane, z) in out.planes.iter().zip(heights) {
        // The slab above z carries the top load and the part of the band above z.
        let above = ((4e-3 - z) / 2e-3).clamp(0.0, 1.0);
        let shear: f64 = plane.shear().iter().sum::<f64>() * grid.cell_area();
        let normal: f64 = plane.normal().iter().sum::<f64>() * grid.cell_area();
        let expected = f_top + f_lat * above;
        assert!(
            (shear - expected).abs() < 1e-9 * f_lat,
            "z = {z}: {shear} vs {expected}"
        );
        assert!((normal + f_n).abs() < 1e-9 * f_n, "z = {z}: {normal}");
    }
}

#[test]
fn planes_at_the_interface_and_the_top_give_the_tractions() {
    let (grid, plan, rod) = setup();
    let block = *grid.block();
    let probe = StressProbe::new(
        &plan,
        &ProbeSpec::default()
            .with_plane(0.0)
            .with_plane(block.lz())
            .with_point(Point::new(0.003, 0.001, 0.0))
            .with_point(Point::new(0.004, 0.001, 0.0)) // on the edge between two cells
            .with_point(Point::new(0.003, 0.001, block.lz())),
        Some(&rod),
    )
    .unwrap();
    let (f_top, f_lat, f_n) = (1.5, 2.5, 20.0);
    let phi_x = tractions(&grid, -(f_top + f_lat), 5);
    let phi_z = tractions(&grid, f_n, 6);
    let input = ProbeInput::new(&phi_x, &phi_z)
        .with_loads(f_top, f_lat, f_n)
        .unwrap();
    let out = probe.evaluate(&input).unwrap();
    let area = block.lx() * block.ly();
    for i in 0..grid.len() {
        assert!((out.planes[0].shear()[i] + phi_x[i]).abs() < 1e-12 * phi_x[i].abs());
        assert!((out.planes[0].normal()[i] + phi_z[i]).abs() < 1e-12 * phi_z[i].abs());
        assert!((out.planes[1].shear()[i] - f_top / area).abs() < 1e-9 * f_top / area);
        assert!((out.planes[1].normal()[i] + f_n / area).abs() < 1e-9 * f_n / area);
    }
    let c = grid.index(1, 0).unwrap();
    assert!((out.points[0].shear + phi_x[c]).abs() < 1e-12 * phi_x[c].abs());
    let edge = 0.5 * (phi_z[grid.index(1, 0).unwrap()] + phi_z[grid.index(2, 0).unwrap()]);
    assert!((out.points[1].normal + edge).abs() < 1e-12 * edge);
    assert!((out.points[2].normal + f_n / area).abs() < 1e-9 * f_n / area);
}

#[test]
fn point_probes_averaged_over_a_cell_give_the_plane() {
    let (grid, plan, _) = setup();
    let z = 1.5e-3;
    // Cell (ix, iy) = (2, 1): Gauss–Legendre points over it.
    let (x0, y0) = (2.0 * grid.dx(), grid.dy());
    let xs = rule(x0, x0 + grid.dx(), 1, 6);
    let ys = rule(y0, y0 + grid.dy(), 1, 6);
    let mut spec = ProbeSpec::default()
        .with_plane(z)
        .with_tolerance(1e-13)
        .unwrap();
    for &(x, _) in &xs {
        for &(y, _) in &ys {
            spec = spec.with_point(Point::new(x, y, z));
        }
    }
    let probe = StressProbe::new(&plan, &spec, None).unwrap();
    let phi_x = tractions(&grid, -3.0, 7);
    let phi_z = tractions(&grid, 10.0, 8);
    let out = probe
        .evaluate(
            &ProbeInput::new(&phi_x, &phi_z)
                .with_loads(3.0, 0.0, 10.0)
                .unwrap(),
        )
        .unwrap();
    let mut shear = 0.0;
    let mut normal = 0.0;
    let mut k = 0;
    for &(_, wx) in &xs {
        for &(_, wy) in &ys {
            shear += wx * wy * out.points[k].shear;
            normal += wx * wy * out.points[k].normal;
            k += 1;
        }
    }
    let cell_area = grid.cell_area();
    let c = grid.index(2, 1).unwrap();
    let plane = &out.planes[0];
    // The stress is smooth at z = 1.5 mm: 6-point rules integrate it to ~1e-10.
    assert!((shear / cell_area - plane.shear()[c]).abs() < 1e-8 * plane.shear()[c].abs());
    assert!((normal / cell_area - plane.normal()[c]).abs() < 1e-8 * plane.normal()[c].abs());
}

#[test]
fn probe_errors_are_typed() {
    let (grid, plan, _) = setup();
    let lz = grid.block().lz();
    for spec in [
        ProbeSpec::default().with_plane(-1e-3),
        ProbeSpec::default().with_plane(lz * 1.01),
        ProbeSpec::default().with_plane(f64::NAN),
        ProbeSpec::default().with_point(Point::new(0.02, 0.001, 0.001)),
        ProbeSpec::default().with_point(Point::new(0.001, 0.001, f64::INFINITY)),
    ] {
        assert!(
            matches!(
                StressProbe::new(&plan, &spec, None),
                Err(Error::OutsideBlock { .. })
            ),
            "{spec:?}"
        );
    }
    assert!(matches!(
        ProbeSpec::default().with_plane(1e-3).with_tolerance(0.0),
        Err(Error::InvalidTolerance { .. })
    ));
    let probe = StressProbe::new(&plan, &ProbeSpec::default().with_plane(1e-3), None).unwrap();
    let phi = vec![1.0; grid.len()];
    let short = vec![1.0; 3];
    assert!(matches!(
        probe.evaluate(&ProbeInput::new(&short, &phi)),
        Err(Error::LengthMismatch { .. })
    ));
    assert!(matches!(
        probe.evaluate(
            &ProbeInput::new(&phi, &phi)
                .with_loads(0.0, 1.0, 1.0)
                .unwrap()
        ),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(matches!(
        ProbeInput::new(&phi, &phi).with_loads(f64::NAN, 0.0, 1.0),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        ProbeInput::new(&phi, &phi).with_friction_coefficient(-0.1),
        Err(Error::InvalidParameter { .. })
    ));
}

#[test]
fn the_driver_reports_probes_only_when_requested() {
    let base = Scene::builder()
        .block(0.020, 0.004, 0.010)
        .normal_load(60.0)
        .seed(3);
    let plain = base.clone().build().unwrap();
    assert!(plain.probes().is_empty());
    let mut d = plain.driver().unwrap();
    d.step().unwrap();
    let e = d.stresses().unwrap_err();
    assert!(matches!(e, Error::NoProbes), "{e}");
    assert!(e.to_string().contains("SceneBuilder::probes"), "{e}");

    let scene = base
        .probes(ProbeSpec::default().with_plane(0.0).with_plane(2e-3))
        .build()
        .unwrap();
    let mut d = scene.driver().unwrap();
    // Just before the first rupture: after the first LoadRaised.
    loop {
        if let Some(Event::LoadRaised { .. }) = d.step().unwrap() {
            break;
        }
    }
    let s = d.stresses().unwrap();
    let shear = d.shear_traction().unwrap();
    let normal = d.normal_traction().unwrap();
    // Exactly, at z = 0 (no transform is applied there).
    for i in 0..scene.grid().len() {
        assert_eq!(s.planes[0].shear()[i], -shear[i]);
        assert_eq!(s.planes[0].normal()[i], -normal[i]);
    }
    // Through z = 2 mm (below the rod band [4, 8] mm) the whole shear force passes.
    let total: f64 = s.planes[1].shear().iter().sum::<f64>() * scene.grid().cell_area();
    assert!((total - d.force()).abs() < 1e-9 * d.force());
    let profile = s.planes[1].profile();
    assert_eq!(profile.shear().len(), scene.grid().nx());
    // The abscissa of the profile: the columns' centres (m), as the grid places them.
    assert_eq!(profile.x().len(), scene.grid().nx());
    for (ix, &x) in profile.x().iter().enumerate() {
        let (centre, _) = scene.grid().centre(ix, 0).unwrap();
        assert!((x - centre).abs() <= 1e-15, "column {ix}: {x} vs {centre}");
    }
}

/// The probes of `RunOptions::probes` are the scene's probes, planned on the same plan:
/// a driver of a plain scene given them reports, at every event, the stresses a driver
/// of the scene that carries them reports (the reference: the scene's own probe path,
/// `SceneBuilder::probes`), bit for bit, and the same events.
#[test]
fn probes_from_run_options_give_the_stresses_of_the_scenes_probes() {
    let spec = ProbeSpec::default()
        .with_plane(0.0)
        .with_plane(2e-3)
        .with_point(Point::new(0.01, 0.002, 3e-3));
    let base = Scene::builder()
        .block(0.020, 0.004, 0.010)
        .normal_load(60.0)
        .seed(3);
    let carried = base.clone().probes(spec.clone()).build().unwrap();
    // Another scene's probes are replaced, not added to.
    let other = base
        .probes(ProbeSpec::default().with_plane(5e-3))
        .build()
        .unwrap();
    let mut reference = carried.driver().unwrap();
    let mut observed = other.driver_with(&RunOptions::new().probes(spec)).unwrap();
    let mut states = 0;
    loop {
        let (a, b) = (reference.step().unwrap(), observed.step().unwrap());
        assert_eq!(a, b);
        let Some(event) = a else { break };
        if matches!(event, Event::LoadRaised { .. }) {
            states += 1;
            let (sa, sb) = (reference.stresses().unwrap(), observed.stresses().unwrap());
            assert_eq!((sa.planes.len(), sa.points.len()), (2, 1));
            assert_eq!(sa, sb);
        }
    }
    assert!(states > 2, "{states}");
    // Empty probes in the options: the driver starts with none.
    let mut none = carried
        .driver_with(&RunOptions::new().probes(ProbeSpec::default()))
        .unwrap();
    none.step().unwrap();
    assert!(matches!(none.stresses(), Err(Error::NoProbes)));
}

/// Probes of the run options that do not fit the scene are refused by
/// `Scene::driver_with`, naming the key as the scene's own probes would be.
#[test]
fn probes_from_run_options_are_checked_by_key() {
    let scene = Scene::builder().block(0.020, 0.004, 0.010).build().unwrap();
    let outside = RunOptions::new().probes(ProbeSpec::default().with_plane(0.02));
    match scene.driver_with(&outside) {
        Err(Error::OutOfRange { key, .. }) => assert_eq!(key, "probes.planes"),
        other => panic!("{other:?}"),
    }
    let refused = Scene::builder()
        .block(0.020, 0.004, 0.010)
        .probes(ProbeSpec::default().with_plane(0.02))
        .build();
    assert!(matches!(
        refused,
        Err(Error::OutOfRange {
            key: "probes.planes",
            ..
        })
    ));
}

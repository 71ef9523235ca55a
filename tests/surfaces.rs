//! Random surfaces with a length scale (issue 28, item 1; docs/model.md section 3.1):
//! value stability against an independent computation, the same surface at every cell
//! size, the heights' statistics, and the scene-file kinds and sweep axes.

use precursors::{
    Block, Error, Grid, HeightDistribution, HeightSource, Heights, Scene, SceneBuilder,
    SurfaceSpectrum,
};

fn block() -> Block {
    Block::new(0.008, 0.004, 0.005).unwrap()
}

/// Heights pinned to values computed once by `docs/experiments/surface_reference.py`
/// (Python integers for the hash, `math.fsum` for the field, mpmath for the copula, a
/// 16- and 64-point Gauss-Legendre rule per axis: the exact cell averages to about 1e-12
/// of the standard deviation), written from docs/model.md section 3.1, not from the Rust
/// code. The crate's own rule stops when two successive orders agree to `1e-10 s`:
/// tolerance `2e-10 s` on each height.
#[test]
fn pinned_gaussian_surface() {
    let grid = Grid::new(block(), 4, 2).unwrap();
    let heights = Heights::random_surface(
        &grid,
        SurfaceSpectrum::gaussian(2e-3).unwrap(),
        HeightDistribution::default(),
        7,
    )
    .unwrap();
    let expected = [
        8.54041804480647e-07,
        2.1563771961157247e-06,
        2.399535660238577e-06,
        4.028937031629137e-07,
        1.1852332574718672e-06,
        1.7679769464152444e-06,
        1.9310915715644653e-06,
        1.5343090436483465e-06,
    ];
    for (i, (h, e)) in heights.values().iter().zip(expected).enumerate() {
        assert!((h - e).abs() < 2e-10 * 1e-6, "cell {i}: {h:e} vs {e:e}");
    }
}

/// Heights with a spread far below the mean's rounding (`std_dev` 1e-13 to 1e-20 m on a
/// mean of 2 µm) are the mean to a few ulps: the two rules' sums differ by their
/// rounding, which the rule used to compare with `1e-10 s` alone, refusing such surfaces
/// as "cells too large" (issue 53). A spread of 0 was already valid.
#[test]
fn a_spread_below_the_rounding_of_the_mean_gives_the_mean() {
    let grid = Grid::new(block(), 4, 2).unwrap();
    for sd in [1e-13, 1e-16, 1e-20] {
        let heights = Heights::random_surface(
            &grid,
            SurfaceSpectrum::gaussian(2e-3).unwrap(),
            HeightDistribution::new(2e-6, sd).unwrap(),
            7,
        )
        .unwrap_or_else(|e| panic!("std_dev {sd:e}: {e}"));
        for h in heights.values() {
            assert!(
                (h - 2e-6).abs() <= 10.0 * sd + 1e-19,
                "std_dev {sd:e}: {h:e}"
            );
        }
    }
}

/// As [`pinned_gaussian_surface`], for a self-affine surface (H = 0.7, λ_r = 3 mm,
/// λ_s = 0.6 mm, λ_l = 5 mm; 2 mm cells hold many wavelengths: the rule's order is high).
#[test]
fn pinned_self_affine_surface() {
    let grid = Grid::new(block(), 4, 2).unwrap();
    let heights = Heights::random_surface(
        &grid,
        SurfaceSpectrum::self_affine(0.7, 3e-3, 0.6e-3, 5e-3).unwrap(),
        HeightDistribution::new(2e-6, 1e-6).unwrap(),
        11,
    )
    .unwrap();
    let expected = SELF_AFFINE;
    for (i, (h, e)) in heights.values().iter().zip(expected).enumerate() {
        assert!((h - e).abs() < 2e-10 * 1e-6, "cell {i}: {h:e} vs {e:e}");
    }
}

const SELF_AFFINE: [f64; 8] = [
    2.0344040339753738e-06,
    2.05753411430214e-06,
    2.2363011773727377e-06,
    1.6894640388922203e-06,
    1.5114426550800953e-06,
    2.268676081069054e-06,
    1.945880037776935e-06,
    1.9138280237694243e-06,
];

/// The same seed gives the same surface at every cell size: a 1 mm cell's height is the
/// mean of its sixteen 0.25 mm cells' heights, to the quadrature error of both (each is
/// the cell average of `u0` to about `1e-10` of the standard deviation, where two
/// successive rules agree; tolerance `4e-10` of it). White-noise heights (the paper's) have no such relation: checked to fail.
#[test]
fn a_coarse_cell_is_the_average_of_its_fine_cells() {
    let block = Block::new(0.016, 0.004, 0.010).unwrap();
    let d = HeightDistribution::default();
    for spectrum in [
        SurfaceSpectrum::gaussian(2e-3).unwrap(),
        SurfaceSpectrum::self_affine(0.8, 4e-3, 0.8e-3, 8e-3).unwrap(),
    ] {
        let coarse =
            Heights::random_surface(&Grid::new(block, 16, 4).unwrap(), spectrum, d, 3).unwrap();
        let fine =
            Heights::random_surface(&Grid::new(block, 64, 16).unwrap(), spectrum, d, 3).unwrap();
        let mut worst: f64 = 0.0;
        for iy in 0..4 {
            for ix in 0..16 {
                let mut sum = 0.0;
                for fy in 0..4 {
                    for fx in 0..4 {
                        sum += fine.values()[(4 * iy + fy) * 64 + 4 * ix + fx];
                    }
                }
                worst = worst.max((coarse.values()[iy * 16 + ix] - sum / 16.0).abs());
            }
        }
        assert!(worst < 4e-10 * d.std_dev(), "{spectrum:?}: {worst:e} m");
    }
    // The paper's white noise: another surface at each cell size.
    let coarse = Heights::truncated_gaussian(&Grid::new(block, 16, 4).unwrap(), d, 3).unwrap();
    let fine = Heights::truncated_gaussian(&Grid::new(block, 64, 16).unwrap(), d, 3).unwrap();
    let mean: f64 = (0..4)
        .flat_map(|fy| (0..4).map(move |fx| fy * 64 + fx))
        .map(|i| fine.values()[i])
        .sum::<f64>()
        / 16.0;
    assert!((coarse.values()[0] - mean).abs() > 1e-10 * d.std_dev());
}

/// The heights' marginal is the paper's truncated Gaussian: over 300 independent
/// surfaces, the mean and the variance of the cell heights against the truncated
/// Gaussian's, `m + s φ(a)/Q(a)` and `s² (1 + aφ/Q - (φ/Q)²)` (`a = -m/s`; closed form).
/// Tolerances: 4 standard errors, estimated from the scatter of the 300 surfaces' own
/// means and mean squares; the variance also 4 % lower at most, as the cells (`ξ/8`)
/// average `g` over them (`Δ²/(6ξ²)` per axis, 2 %, doubled for the copula).
/// A coarse check of the whole chain (its power: a bias of the mean above about 9 %; a
/// 1 % scale error of the heights passes it, and fails the pinned values and the copula's
/// test against mpmath, which catch small errors).
#[test]
fn the_heights_have_the_truncated_gaussian_marginal() {
    let (m, s) = (1e-6, 1e-6);
    let a: f64 = -m / s;
    let pdf = (-0.5 * a * a).exp() / (2.0 * std::f64::consts::PI).sqrt();
    // Q(-1) = Φ(1) = 0.8413447460685429 (tables).
    let q = 0.841_344_746_068_542_9;
    let mean = m + s * pdf / q;
    let var = s * s * (1.0 + a * pdf / q - (pdf / q) * (pdf / q));
    let grid = Grid::new(Block::new(0.008, 0.004, 0.01).unwrap(), 32, 16).unwrap();
    let spectrum = SurfaceSpectrum::gaussian(2e-3).unwrap();
    let (mut firsts, mut seconds) = (Vec::new(), Vec::new());
    for seed in 0..300 {
        let h = Heights::random_surface(
            &grid,
            spectrum,
            HeightDistribution::new(m, s).unwrap(),
            seed,
        )
        .unwrap();
        let v = h.values();
        firsts.push(v.iter().sum::<f64>() / v.len() as f64);
        seconds.push(v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64);
    }
    let stats = |x: &[f64]| {
        let n = x.len() as f64;
        let mu = x.iter().sum::<f64>() / n;
        let sd = (x.iter().map(|v| (v - mu).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        (mu, sd / n.sqrt())
    };
    let ((m1, e1), (m2, e2)) = (stats(&firsts), stats(&seconds));
    assert!(
        (m1 - mean).abs() < 4.0 * e1,
        "mean {m1:e} vs {mean:e} (se {e1:e})"
    );
    let v = m2 - m1 * m1;
    let se = e2 + 2.0 * m1 * e1;
    assert!(
        v < var + 4.0 * se && v > 0.96 * var - 4.0 * se,
        "variance {v:e} vs {var:e} (se {se:e})"
    );
}

/// The heights AFTER the copula, end to end through the public API: the mean of the
/// cell heights and their covariance at lags of (kx, ky) cells against an independent
/// prediction. `docs/experiments/copula_correlation.py` (mpmath; run it to reproduce the
/// numbers) computes the covariance of `u0 = F⁻¹(Φ(g))` at two points whose `g` are
/// correlated `ρ = exp(-r²/ξ²)` by Mehler's expansion `Σ c_n² ρⁿ/n!`
/// (`c_n = E[u0(Z) He_n(Z)]` by Gauss-Hermite quadrature; checked there against the
/// closed-form variance at `ρ = 1` to 1e-11 and against a direct double integral at
/// `ρ = 0.5` to 1e-12), then averages it over two cells (triangle weights of the
/// difference of two uniform points). The mean is the truncated Gaussian's closed form
/// `m + s φ(a)/Q(a)`, `a = -m/s` (cell averaging keeps it); the variance (lag 0) is the
/// closed form `s²(1 + aφ/Q - (φ/Q)²) = 0.62969 s²` reduced to 0.61635 s² by the 0.5 mm
/// cells (ξ = 2 mm). Each surface (16 x 8 mm, 32 x 16 cells) gives one estimate per
/// statistic, `(h_i - μ)(h_j - μ)` averaged over its pairs with the exact `μ`; over 500
/// independent surfaces their mean must lie within 4 standard errors (from their own
/// scatter) of the prediction (standard errors about 0.8 % of the mean and 0.01 s² of
/// the covariances). Fails when the copula's heights are scaled by 1.05: the mean by 6.5
/// standard errors, and, with the mean's check left out, the variance by 9 (checked).
#[test]
fn the_heights_after_the_copula_have_the_predicted_mean_and_covariance() {
    // From docs/experiments/copula_correlation.py: ((kx, ky), covariance / s²).
    const COVARIANCES: [((usize, usize), f64); 7] = [
        ((0, 0), 0.6163501842020642),
        ((1, 0), 0.5786061959747043),
        ((2, 0), 0.47906087765643834),
        ((4, 0), 0.22690417057594472),
        ((8, 0), 0.01188009767729015),
        ((0, 2), 0.47906087765643873),
        ((3, 3), 0.20049909332117796),
    ];
    let (m, s) = (1e-6, 1e-6);
    let a: f64 = -m / s;
    let pdf = (-0.5 * a * a).exp() / (2.0 * std::f64::consts::PI).sqrt();
    // Q(-1) = Φ(1) = 0.8413447460685429 (tables).
    let mu = m + s * pdf / 0.841_344_746_068_542_9;
    let (nx, ny) = (32, 16);
    let grid = Grid::new(Block::new(0.016, 0.008, 0.010).unwrap(), nx, ny).unwrap();
    let spectrum = SurfaceSpectrum::gaussian(2e-3).unwrap();
    let surfaces = 500;
    // Per surface: its mean height, then one covariance estimate per lag.
    let mut estimates = vec![Vec::with_capacity(surfaces); 1 + COVARIANCES.len()];
    for seed in 0..surfaces as u64 {
        let h = Heights::random_surface(
            &grid,
            spectrum,
            HeightDistribution::new(m, s).unwrap(),
            seed,
        )
        .unwrap();
        let v = h.values();
        estimates[0].push(v.iter().sum::<f64>() / v.len() as f64);
        for (k, ((kx, ky), _)) in COVARIANCES.iter().enumerate() {
            let (mut sum, mut pairs) = (0.0, 0);
            for iy in 0..ny - ky {
                for ix in 0..nx - kx {
                    let (i, j) = (iy * nx + ix, (iy + ky) * nx + ix + kx);
                    sum += (v[i] - mu) * (v[j] - mu);
                    pairs += 1;
                }
            }
            estimates[1 + k].push(sum / pairs as f64 / (s * s));
        }
    }
    let stats = |x: &[f64]| {
        let n = x.len() as f64;
        let mean = x.iter().sum::<f64>() / n;
        let sd = (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        (mean, sd / n.sqrt())
    };
    let (mean, se) = stats(&estimates[0]);
    assert!(
        (mean - mu).abs() < 4.0 * se,
        "mean {mean:e} vs {mu:e} (se {se:e})"
    );
    for (k, ((kx, ky), expected)) in COVARIANCES.iter().enumerate() {
        let (cov, se) = stats(&estimates[1 + k]);
        assert!(
            (cov - expected).abs() < 4.0 * se,
            "lag ({kx}, {ky}): covariance {cov} s² vs {expected} s² (se {se})"
        );
    }
}

#[test]
fn surfaces_refuse_bad_spectra_and_costs_with_typed_errors() {
    assert!(matches!(
        SurfaceSpectrum::gaussian(-1e-3),
        Err(Error::InvalidParameter {
            name: "correlation_length",
            ..
        })
    ));
    assert!(matches!(
        SurfaceSpectrum::self_affine(1.5, 3e-3, 1e-3, 5e-3),
        Err(Error::InvalidParameter { name: "hurst", .. })
    ));
    assert!(matches!(
        SurfaceSpectrum::self_affine(0.5, 3e-3, 1e-3, 2e-3),
        Err(Error::InvalidParameter {
            name: "long_cutoff",
            ..
        })
    ));
    // A correlation length of 1 µm on the calibration block: billions of modes.
    let grid = Grid::new(Block::new(0.14, 0.007, 0.075).unwrap(), 140, 7).unwrap();
    let e = Heights::random_surface(
        &grid,
        SurfaceSpectrum::gaussian(1e-6).unwrap(),
        HeightDistribution::default(),
        1,
    )
    .unwrap_err();
    assert!(matches!(e, Error::SurfaceTooLarge { .. }), "{e}");
    assert!(e.to_string().contains("Fourier modes"), "{e}");
    // The scene checks it before building anything.
    let e = Scene::builder()
        .heights(HeightSource::Surface {
            spectrum: SurfaceSpectrum::gaussian(1e-6).unwrap(),
            distribution: HeightDistribution::default(),
            seed: 1,
        })
        .check()
        .unwrap_err();
    assert!(matches!(e, Error::SurfaceTooLarge { .. }), "{e}");
}

/// The scene file's kinds give the builder's surface, and a sweep axis sets a surface's
/// key (`heights.correlation_length`) with its realizations' seeds.
#[cfg(feature = "serde")]
#[test]
fn scene_files_and_sweeps_set_surfaces() {
    use precursors::sweep::Sweep;
    use precursors::SceneBuilder;
    let base = r#"{ "block": { "lx": 0.016, "ly": 0.004, "lz": 0.010 },
        "cells": { "kind": "size", "dx": 0.001, "dy": 0.001 },
        "normal_load": 200.0,
        "heights": { "kind": "gaussian_surface", "correlation_length": 0.002, "seed": 4 } }"#;
    let builder = SceneBuilder::from_json_str(base).unwrap();
    let scene = builder.clone().build().unwrap();
    let direct = Heights::random_surface(
        scene.grid(),
        SurfaceSpectrum::gaussian(2e-3).unwrap(),
        HeightDistribution::default(),
        4,
    )
    .unwrap();
    assert_eq!(scene.interface().heights(), direct.values());
    assert_eq!(
        SceneBuilder::from_json_str(&builder.to_json().unwrap()).unwrap(),
        builder
    );
    let affine = r#"{ "heights": { "kind": "self_affine_surface", "hurst": 0.8, "roll_off": 0.004,
        "short_cutoff": 0.0008, "long_cutoff": 0.008, "mean": 2e-6 } }"#;
    let builder = SceneBuilder::from_json_str(affine).unwrap();
    assert_eq!(
        builder.clone().build().unwrap().heights(),
        &HeightSource::Surface {
            spectrum: SurfaceSpectrum::self_affine(0.8, 4e-3, 0.8e-3, 8e-3).unwrap(),
            distribution: HeightDistribution::new(2e-6, 1e-6).unwrap(),
            seed: 1,
        }
    );
    // A key of the kind refused by the constructor: the file's error names it.
    let bad = r#"{ "heights": { "kind": "gaussian_surface", "correlation_length": -1.0 } }"#;
    let e = SceneBuilder::from_json_str(bad).unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidParameter {
                name: "correlation_length",
                ..
            }
        ),
        "{e}"
    );
    // A sweep over the correlation length, two realizations per point.
    let sweep = format!(
        r#"{{ "base": {base}, "axes": [ {{ "key": "heights.correlation_length", "values": [0.001, 0.003] }} ],
             "realizations": 2, "seed": 9 }}"#
    );
    let sweep = Sweep::from_json_str(&sweep).unwrap();
    assert_eq!(sweep.runs().len(), 4);
    for run in sweep.runs() {
        let HeightSource::Surface { spectrum, seed, .. } =
            run.scene().clone().build().unwrap().heights().clone()
        else {
            panic!("not a surface");
        };
        let xi = [1e-3, 3e-3][run.coordinates()[0]];
        assert_eq!(spectrum, SurfaceSpectrum::gaussian(xi).unwrap());
        assert_eq!(seed, run.seed());
    }
}

/// The convergence study's files (docs/convergence.md): each parses and expands to 20
/// runs on the calibration geometry with the grid its name says, and realization `r` has
/// the same seed in every file, so the Gaussian surface is the same at every cell size.
#[cfg(feature = "serde")]
#[test]
fn the_convergence_sweeps_share_their_surfaces_across_cell_sizes() {
    use precursors::sweep::Sweep;
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/sweeps/convergence");
    let mut seeds = None;
    for (name, nx, ny) in [
        ("2mm", 70, 4),
        ("1mm", 140, 7),
        ("0.5mm", 280, 14),
        ("0.25mm", 560, 28),
    ] {
        for (prefix, surface) in [("convergence_", true), ("convergence_white_", false)] {
            let path = dir.join(format!("{prefix}{name}.json"));
            let sweep = Sweep::from_json_file(&path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
            assert_eq!(sweep.runs().len(), 20, "{path:?}");
            let scene = sweep.runs()[0].scene();
            let grid = scene.grid().unwrap();
            assert_eq!((grid.nx(), grid.ny()), (nx, ny), "{path:?}");
            let b = grid.block();
            assert_eq!((b.lx(), b.ly(), b.lz()), (0.14, 0.007, 0.075));
            let json: serde_json::Value = serde_json::from_str(&scene.to_json().unwrap()).unwrap();
            let kind = if surface {
                "gaussian_surface"
            } else {
                "gaussian"
            };
            assert_eq!(json["heights"]["kind"], kind, "{path:?}");
            let these: Vec<u64> = sweep.runs().iter().map(|r| r.seed()).collect();
            match &seeds {
                None => seeds = Some(these),
                Some(s) => assert_eq!(s, &these, "{path:?}"),
            }
        }
    }
}

/// The correlation-length sweep of the convergence study (docs/convergence.md, issue 44):
/// per ξ three grids halving the cell, every cell at most ξ/4, the correlation length its
/// name says, and the same seeds on every grid of one ξ (the same surface: the study's
/// differences are taken between grids on the same realization).
#[cfg(feature = "serde")]
#[test]
fn the_correlation_length_sweeps_resolve_xi_and_share_their_surfaces() {
    use precursors::sweep::Sweep;
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/sweeps/convergence");
    for (xi_mm, sizes, runs) in [
        (4.0, ["1mm", "0.5mm", "0.25mm"], 12),
        (8.0, ["2mm", "1mm", "0.5mm"], 20),
        (16.0, ["2mm", "1mm", "0.5mm"], 20),
    ] {
        let mut seeds = None;
        let mut previous_dx: Option<f64> = None;
        for size in sizes {
            let path = dir.join(format!("xi{xi_mm}_{size}.json"));
            let sweep = Sweep::from_json_file(&path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
            assert_eq!(sweep.runs().len(), runs, "{path:?}");
            let scene = sweep.runs()[0].scene();
            let grid = scene.grid().unwrap();
            let (dx, dy) = (grid.dx(), grid.dy());
            let expected_dx: f64 = size.trim_end_matches("mm").parse::<f64>().unwrap() * 1e-3;
            assert!((dx - expected_dx).abs() < 1e-12, "{path:?}: dx {dx}");
            assert!(
                dx.max(dy) <= xi_mm * 1e-3 / 4.0 + 1e-12,
                "{path:?}: cells above ξ/4"
            );
            if let Some(p) = previous_dx {
                assert!(
                    (p / dx - 2.0_f64).abs() < 1e-9,
                    "{path:?}: not half the cell"
                );
            }
            previous_dx = Some(dx);
            let json: serde_json::Value = serde_json::from_str(&scene.to_json().unwrap()).unwrap();
            assert_eq!(json["heights"]["kind"], "gaussian_surface", "{path:?}");
            let xi = json["heights"]["correlation_length"].as_f64().unwrap();
            assert!((xi - xi_mm * 1e-3).abs() < 1e-15, "{path:?}: ξ {xi}");
            let these: Vec<u64> = sweep.runs().iter().map(|r| r.seed()).collect();
            match &seeds {
                None => seeds = Some(these),
                Some(s) => assert_eq!(s, &these, "{path:?}"),
            }
        }
    }
}

/// Heights without spread (`std_dev` 0, documented as valid) are the mean in every cell,
/// for a surface as for white noise (issue 41: the cell averages' rule never converged).
#[test]
fn a_surface_without_spread_is_its_mean_everywhere() {
    let grid = Grid::new(block(), 8, 4).unwrap();
    for spectrum in [
        SurfaceSpectrum::gaussian(2e-3).unwrap(),
        SurfaceSpectrum::self_affine(0.7, 3e-3, 6e-4, 5e-3).unwrap(),
    ] {
        let heights = Heights::random_surface(
            &grid,
            spectrum,
            HeightDistribution::new(1.5e-6, 0.0).unwrap(),
            7,
        )
        .unwrap();
        assert!(heights.values().iter().all(|&h| h == 1.5e-6), "{heights:?}");
    }
}

/// `seed` and `heights` combine in any order (issue 45, item 10): a surface keeps its
/// spectrum and takes the seed; given values refuse a seed, in either order.
#[test]
fn seed_and_heights_combine_in_any_order() {
    let surface = |seed| HeightSource::Surface {
        spectrum: SurfaceSpectrum::gaussian(2e-3).unwrap(),
        distribution: HeightDistribution::default(),
        seed,
    };
    let base = Scene::builder()
        .block(0.008, 0.004, 0.010)
        .cells(8, 4)
        .normal_load(30.0);
    let after = base.clone().heights(surface(1)).seed(5);
    let before = base.clone().seed(5).heights(surface(1));
    assert_eq!(after, base.clone().heights(surface(5)));
    assert_eq!(before, after);
    let heights = |b: SceneBuilder| b.build().unwrap().interface().heights().to_vec();
    let expected = heights(base.clone().heights(surface(5)));
    assert_eq!(heights(after), expected);
    assert_eq!(heights(before), expected);
    // Given values take no seed: set after one they replace the random heights, seed
    // included; a seed set after them is refused, not a silent switch to white noise.
    let values = HeightSource::Values(vec![1e-6; 32]);
    let replaced = base.clone().seed(5).heights(values.clone());
    assert_eq!(replaced, base.clone().heights(values.clone()));
    assert_eq!(heights(replaced), vec![1e-6; 32]);
    let e = base
        .clone()
        .heights(values.clone())
        .seed(5)
        .build()
        .unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidCount {
                name: "seed",
                value: 5,
                ..
            }
        ),
        "{e}"
    );
    // A built scene's builder carries no seed of its own: new values are accepted.
    let built = base.seed(5).build().unwrap();
    assert!(built.to_builder().heights(values).build().is_ok());
}

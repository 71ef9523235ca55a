//! Paper Fig. 7 (and S10): y-averaged shear and normal stresses on the plane z_P = 2 mm
//! just before the first precursor, and the Coulomb stress there and at the interface.
//! Block 200 x 7 x 100 mm, 1 mm cells, F_N = 6.25 kN, shear applied on the top and on the
//! trailing edge by a rod (h = 6 mm, Δh = 2 mm). The paper does not give the split
//! between the two; this example takes F_top = F_lat (n = 1: `ForceLoad::Mixed`).
//! "Just before the first precursor" is the last stable state before ℓ first exceeds
//! `THRESHOLD` = 5 mm: single ruptures at the trailing edge make ℓ flicker between 0 and
//! 2 cells from the smallest loads on, long before the first front (the leap of several
//! cells the paper calls a precursor; see docs/validation.md). The profiles are averaged
//! over height realizations (seeds 1-10; the second argument changes the count).
//!
//! Writes `fig7.csv` (x_m, abs_tau_zP_Pa, abs_sigma_zP_Pa, coulomb_zP_Pa (|τ| - μ|σ| of
//! the y-averages), coulomb_interface_Pa (y-average of τ_C at z = 0)) and `fig7.png`:
//! |τ(x, z_P)|, |σ(x, z_P)|, τ_C(x, z_P) and τ_C(x, 0) in MPa against x (mm), with a
//! legend naming each.
//! Run: `cargo run --release --example fig7_stresses [output directory] [realizations]`.

#[path = "support/report.rs"]
mod report;

#[path = "support/figures.rs"]
mod figures;

use precursors::plot::{Chart, Corner, Style};
use precursors::Event;
use precursors::{ProbeSpec, Profile};
use std::process::ExitCode;

/// The precursor length (m) taken as the first front (see the module docs).
const THRESHOLD: f64 = 5e-3;

fn main() -> ExitCode {
    report::report(run())
}

fn run() -> report::Outcome {
    let figures::Args { dir, seeds } = figures::args(Some(1))?;
    let z_p = 2e-3;
    let mut sums: Option<[Vec<f64>; 4]> = None;
    let mut loads = Vec::new();
    for &seed in &seeds {
        let scene = figures::stress_block()
            .probes(ProbeSpec::default().with_plane(z_p).with_plane(0.0))
            .seed(seed)
            .build()?;
        let mu = scene.material().friction_coefficient();
        let mut driver = scene.driver()?;
        let mut before: Option<(f64, Profile, Profile)> = None;
        while let Some(event) = driver.step()? {
            if let Event::Stable { load, .. } = event {
                if driver.precursor_length()? > THRESHOLD {
                    break;
                }
                let s = driver.stresses()?;
                before = Some((load.force, s.planes[0].profile(), s.planes[1].profile()));
            }
        }
        let (force, plane, interface) = before.ok_or("no stable state before the precursor")?;
        loads.push(force / (mu * scene.normal_load()));
        let columns = [
            plane.shear().iter().map(|v| v.abs()).collect::<Vec<_>>(),
            plane.normal().iter().map(|v| v.abs()).collect(),
            plane.coulomb_of_means().to_vec(),
            interface.mean_coulomb().to_vec(),
        ];
        match &mut sums {
            None => sums = Some(columns),
            Some(s) => {
                for (acc, col) in s.iter_mut().zip(&columns) {
                    acc.iter_mut().zip(col).for_each(|(a, c)| *a += c);
                }
            }
        }
    }
    let n = seeds.len() as f64;
    let mut sums = sums.ok_or("no realization")?;
    sums.iter_mut()
        .for_each(|c| c.iter_mut().for_each(|v| *v /= n));
    let nx = sums[0].len();
    let rows: Vec<String> = (0..nx)
        .map(|i| {
            format!(
                "{:.4e},{:.6e},{:.6e},{:.6e},{:.6e}",
                (i as f64 + 0.5) * 1e-3,
                sums[0][i],
                sums[1][i],
                sums[2][i],
                sums[3][i]
            )
        })
        .collect();
    figures::write_csv(
        &format!("{dir}/fig7.csv"),
        "x_m,abs_tau_zP_Pa,abs_sigma_zP_Pa,coulomb_zP_Pa,coulomb_interface_Pa",
        &rows,
    )?;
    let mean_load = loads.iter().sum::<f64>() / n;
    // Profiles in MPa against x in mm (1 mm cells).
    let mpa = |c: &Vec<f64>| -> Vec<(f64, f64)> {
        c.iter()
            .enumerate()
            .map(|(i, v)| (i as f64 + 0.5, v / 1e6))
            .collect()
    };
    let lx_mm = nx as f64;
    // Room above the curves for the legend.
    let (low, high) = sums
        .iter()
        .flatten()
        .fold((0.0f64, 0.0f64), |(a, b), v| (a.min(*v), b.max(*v)));
    let (low, high) = (low / 1e6, high / 1e6);
    Chart::new(
        &format!(
            "Fig. 7: stresses before the first precursor, F/(μF_N) = {mean_load:.3}, {}",
            figures::realizations(seeds.len())
        ),
        "x (mm)",
        "stress (MPa)",
    )
    .x_range(0.0, lx_mm)
    .y_range(low - 0.05 * (high - low), high + 0.35 * (high - low))
    .line("|τ_{xz}| at z_P = 2 mm", &mpa(&sums[0]))
    .line("|σ_{zz}| at z_P = 2 mm", &mpa(&sums[1]))
    .line("τ_C = |τ| − μ|σ| at z_P = 2 mm", &mpa(&sums[2]))
    .line("τ_C at the interface, z = 0", &mpa(&sums[3]))
    // Zero, where τ_C changes sign: the Coulomb stress ahead of the front.
    .line("", &[(0.0, 0.0), (lx_mm, 0.0)])
    .style(Style::new().colour(140, 140, 140).dashed())
    .legend(Corner::UpperRight)
    .size(1000, 600)
    .save(format!("{dir}/fig7.png"))?;
    let positive = sums[2].iter().filter(|v| **v > 0.0).count();
    let interface_max = sums[3].iter().fold(f64::MIN, |m, v| m.max(*v));
    println!(
        "last state before the first precursor at F/(μF_N) = {mean_load:.3} (mean of {} \
         realizations)",
        seeds.len()
    );
    println!(
        "τ_C(z_P = 2 mm) > 0 on {positive} of {nx} columns; max of the interface τ_C = {:.3} MPa",
        interface_max / 1e6
    );
    println!("wrote {dir}/fig7.csv and {dir}/fig7.png");
    Ok(())
}

//! The ranges of a scene's values that the computation can honour
//! (`docs/scene-format.md`, "Valid ranges"), checked by [`SceneBuilder::check`] before
//! anything is planned or allocated.
//!
//! Each dimensional range spans at least nine decades on either side of the paper's
//! value, so that every product and quotient the model forms from a few of them (tractions
//! `F_N/(Lx Ly)`, compliances `u0/c_z` and `ΔA/M · Ĝ`, the lateral load's `Lx/(Ly Lz)`,
//! volumes, the spring's `μF_N/K_S`) stays finite and normal with hundreds of decades to
//! spare; the dimensionless ratios that set the length of the series (block and cell
//! aspect ratios, depth over cell size) are bounded by what they sum within their term
//! budgets. Outside, a value gave an overflow (`block.lx = 1e308`), a factorisation of
//! zeros (`block.ly = 1e308`), a load ratio of `+∞` (`drive.stiffness = 1e-306`) or
//! garbage (`solver.tolerance = 1`).

use super::{Cells, Drive, ForceLoad, HeightSource, Lateral, SceneBuilder, SiteMap};
use crate::error::{Error, Num, Result};
use crate::geometry::Grid;
use crate::probe::ProbeSpec;
use crate::surface::SurfaceSpectrum;

/// Block lengths `Lx, Ly, Lz` (m).
pub(crate) const LENGTH: (f64, f64) = (1e-9, 1e9);
/// Largest ratio of two block lengths, of the two cell sizes, and of the depth `Lz` to a
/// cell size: the lateral load's series needs about `Lz/Δx` terms for its first column
/// (and the term budget is `2e7`), the eigenvalues' integral `log(ratio)` panels.
pub(crate) const ASPECT: f64 = 1e6;
/// Asperity heights: given values, the Gaussian's mean (in magnitude) and standard
/// deviation (m; a standard deviation may also be 0).
pub(crate) const HEIGHT: (f64, f64) = (1e-15, 1e3);
/// Young's modulus `E` (Pa).
pub(crate) const YOUNG: (f64, f64) = (1e-3, 1e15);
/// Poisson's ratio: `1 + ν ≥ 1e-6`, so that `M = E/(1 + ν)` stays within a million `E`.
pub(crate) const POISSON: (f64, f64) = (-0.999_999, 0.5);
/// The friction coefficient `μ`.
pub(crate) const FRICTION: (f64, f64) = (1e-6, 1e3);
/// `c_x` (N/m³).
pub(crate) const C_X: (f64, f64) = (1e-3, 1e24);
/// `c_z` (N/m²).
pub(crate) const C_Z: (f64, f64) = (1e-3, 1e21);
/// The normal load `F_N` (N).
pub(crate) const NORMAL_LOAD: (f64, f64) = (1e-9, 1e15);
/// The mixed load's `n = F_top/F_lat`.
pub(crate) const RATIO: (f64, f64) = (0.0, 1e12);
/// The driving spring's `K_S` relative to the block's shear stiffness `M·Ly·Lz/Lx`.
/// Below, `K_S Û` (the block's compliance against the spring's) is under 1e-12: the
/// spring is force control to twelve digits, and the drive displacement `F/K_S` heads for
/// overflow (at `K_S = 1e-306` N/m the first threshold gave `U_S = +∞` and `F = +∞`);
/// above, the drive is a rigid displacement control to twelve digits.
pub(crate) const STIFFNESS: (f64, f64) = (1e-12, 1e12);
/// The rod's half-width relative to `Lz`: the band moment `sin(k h₊) - sin(k h₋)` loses
/// `log10(Lz/Δh)` digits to cancellation.
pub(crate) const HALF_WIDTH: f64 = 1e-6;
/// The solver's tolerance (backward error of a linear solve): below about `2e-16` no solve
/// reaches it (rounding; a solve at `1e-17` fails, at `1e-20` spends its whole iteration
/// budget first), and `1e-15` leaves a margin for larger grids; above `1e-6` the results are
/// wrong without notice (measured on the calibration scene, docs/scene-format.md: its
/// contact area at zero shear is off by 1.1e-4 at `1e-5`, 4.2e-2 at `1e-4`, 0.66 at
/// `1e-3`; at `1` every site of a 20 x 4 scene stayed attached, 80 where 18 are).
pub(crate) const SOLVER_TOLERANCE: (f64, f64) = (1e-15, 1e-6);
/// Active-set iterations per normal equilibrium (the default is `1000`).
pub(crate) const ACTIVE_SET_ITERATIONS: (usize, usize) = (1, 1_000_000);
/// Conjugate-gradient iterations per linear solve (the default is `20000`).
pub(crate) const LINEAR_ITERATIONS: (usize, usize) = (1, 10_000_000);
/// The plan tolerance: an upper bound on the eigenvalues' relative error; below about
/// `2e-13` the plan refuses it when built (`Error::SeriesNotConverged`), above `1e-2` it
/// accepts nothing a user could want.
pub(crate) const PLAN_TOLERANCE_MAX: f64 = 1e-2;
/// The probes' tolerance, relative to the largest traction: below `1e-15` the alias sums
/// cannot reach it, above `1e-2` the stresses are noise.
pub(crate) const PROBE_TOLERANCE: (f64, f64) = (1e-15, 1e-2);
/// Planes, and points, of the default probes (each costs a kernel of `N` values).
pub(crate) const MAX_PROBES: usize = 10_000;
/// Largest exponent `F_N/(ΔA c_z)`: a site carrying the whole normal load (the last one
/// attached, before global slip) has `k_x = c_x e^{F_N/(ΔA c_z) - 1}` and a real contact
/// area `ΔA/(e-1) (e^{F_N/(ΔA c_z)} - 1)`: beyond it they overflow.
const MAX_EXPONENT: f64 = 650.0;

/// `value` (`f64`) within `[min, max]`.
fn within(
    key: &'static str,
    value: f64,
    (min, max): (f64, f64),
    unit: &str,
    reason: &'static str,
) -> Result<()> {
    if (min..=max).contains(&value) {
        Ok(())
    } else {
        Err(out_of_range(key, value, min, max, unit, reason))
    }
}

fn out_of_range(
    key: &'static str,
    value: f64,
    min: f64,
    max: f64,
    unit: &str,
    reason: &'static str,
) -> Error {
    let unit = if unit.is_empty() {
        String::new()
    } else {
        format!(" {unit}")
    };
    Error::OutOfRange {
        key,
        value,
        range: format!("[{}, {}]{unit}", End(min, true), End(max, false)),
        reason,
    }
}

/// A value in a message: four significant digits (bounds derived from other keys are not
/// round numbers).
struct Short(f64);

impl std::fmt::Display for Short {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let rounded: f64 = format!("{:.3e}", self.0).parse().unwrap_or(self.0);
        write!(f, "{}", Num(rounded))
    }
}

/// A range's end in a message: exact where eight significant digits write it (`-0.999999`,
/// not the `-1` that four give and that holds a refused `-0.9999991`), else four rounded
/// inward (up for the lower end `lower`, down for the upper), so that every value of the
/// printed range is valid.
struct End(f64, bool);

impl std::fmt::Display for End {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let End(v, lower) = *self;
        let exact = (0..8).any(|d| format!("{v:.d$e}").parse::<f64>() == Ok(v));
        if exact || v == 0.0 || !v.is_finite() {
            return write!(f, "{}", Num(v));
        }
        let scale = 10f64.powi(3 - v.abs().log10().floor() as i32);
        let inward = if lower {
            (v * scale).ceil()
        } else {
            (v * scale).floor()
        };
        write!(f, "{}", Num(inward / scale))
    }
}

/// A count within `[min, max]`.
fn count_within(
    key: &'static str,
    value: usize,
    (min, max): (usize, usize),
    reason: &'static str,
) -> Result<()> {
    if (min..=max).contains(&value) {
        Ok(())
    } else {
        Err(Error::OutOfRange {
            key,
            value: value as f64,
            range: format!("[{min}, {max}]"),
            reason,
        })
    }
}

/// The block and cell sizes that are finite and `> 0` (the others are the block's and
/// the grid's errors), before the block and the grid are built.
pub(super) fn geometry(builder: &SceneBuilder) -> Result<()> {
    const WHY: &str = "block lengths beyond it overflow or underflow the series' products";
    let (lx, ly, lz) = builder.lengths;
    let length = |v: f64| v.is_finite() && v > 0.0;
    for (key, value) in [("block.lx", lx), ("block.ly", ly), ("block.lz", lz)] {
        if length(value) {
            within(key, value, LENGTH, "m", WHY)?;
        }
    }
    if !(length(lx) && length(ly) && length(lz)) {
        return Ok(());
    }
    let ratio = |key: &'static str, value: f64, other: f64, reason: &'static str| {
        let (low, high) = (other / ASPECT, other * ASPECT);
        if (low..=high).contains(&value) {
            Ok(())
        } else {
            Err(out_of_range(key, value, low, high, "m", reason))
        }
    };
    const BLOCK: &str = "the block's aspect ratios must be at most 1e6 (the series' cost \
                         grows with them)";
    ratio("block.ly", ly, lx, BLOCK)?;
    ratio("block.lz", lz, lx, BLOCK)?;
    ratio("block.lz", lz, ly, BLOCK)?;
    let (dx, dy) = match builder.cells {
        Cells::Size(dx, dy) => (dx, dy),
        Cells::Count(nx, ny) => (lx / nx as f64, ly / ny as f64),
    };
    if !(length(dx) && length(dy)) {
        return Ok(());
    }
    // A cell size in [min, max] (m), reported as the scene gives it: a size, or a count.
    let cell = |axis: usize, length: f64, cell: f64, min: f64, max: f64, reason| {
        if (min..=max).contains(&cell) {
            return Ok(());
        }
        Err(match builder.cells {
            Cells::Size(..) => {
                out_of_range(["cells.dx", "cells.dy"][axis], cell, min, max, "m", reason)
            }
            Cells::Count(nx, ny) => Error::OutOfRange {
                key: ["cells.nx", "cells.ny"][axis],
                value: [nx, ny][axis] as f64,
                range: format!(
                    "[{}, {}] (cells of {} to {} m)",
                    (length / max).ceil(),
                    (length / min).floor(),
                    Short(min),
                    Short(max)
                ),
                reason,
            },
        })
    };
    const DEPTH: &str = "Lz over the cell size must be at most 1e6 (the lateral load's \
                         series needs about Lz/Δx terms), and the cell aspect ratio \
                         Δx/Δy at most 1e6";
    cell(
        0,
        lx,
        dx,
        (lz / ASPECT).max(dy / ASPECT),
        dy * ASPECT,
        DEPTH,
    )?;
    cell(
        1,
        ly,
        dy,
        (lz / ASPECT).max(dx / ASPECT),
        dx * ASPECT,
        DEPTH,
    )?;
    Ok(())
}

/// The solver's iteration budgets (`solver.max_active_set_iterations`,
/// `solver.max_linear_iterations`) within their ranges.
pub(super) fn solver_iterations(active_set: usize, linear: usize) -> Result<()> {
    count_within(
        "solver.max_active_set_iterations",
        active_set,
        ACTIVE_SET_ITERATIONS,
        "a normal equilibrium needs at least one iteration, and more than 1e6 is a hang",
    )?;
    count_within(
        "solver.max_linear_iterations",
        linear,
        LINEAR_ITERATIONS,
        "a linear solve needs at least one iteration, and more than 1e7 is a hang",
    )
}

/// The probes `probes` on `grid` (scene-file key `probes`): their tolerance, their
/// positions ([`probe_positions`]) and how many.
pub(crate) fn probes(probes: &ProbeSpec, grid: &Grid) -> Result<()> {
    within(
        "probes.tolerance",
        probes.tolerance(),
        PROBE_TOLERANCE,
        "",
        "below 1e-15 the alias sums cannot reach it, above 1e-2 the stresses are noise",
    )?;
    probe_positions(probes, grid)?;
    count_within(
        "probes.points",
        probes.points().len(),
        (0, MAX_PROBES),
        "each probe costs a kernel of Nx·Ny values",
    )
}

/// The heights of the recorded and probed planes and the probe points: inside the block,
/// and at the interface or high enough for their alias sums to converge within their
/// budget at the probes' tolerance (refused here, by `info` as by `run`, not when the run
/// has begun).
fn probe_positions(probes: &ProbeSpec, grid: &Grid) -> Result<()> {
    planes_within("probes.planes", probes.planes(), grid, probes.tolerance())?;
    let lz = grid.block().lz();
    let block = grid.block();
    let lowest_point = crate::probe::lowest_point(grid, probes.tolerance());
    for p in probes.points() {
        for (axis, value, max) in [
            ("x", p.x, block.lx()),
            ("y", p.y, block.ly()),
            ("z", p.z, lz),
        ] {
            if !(value.is_finite() && (0.0..=max).contains(&value)) {
                return Err(Error::OutOfRange {
                    key: "probes.points",
                    value,
                    range: format!("[0, {}] m for {axis}", End(max, false)),
                    reason: "a probe point lies in the block",
                });
            }
        }
        if p.z != 0.0 && p.z < lowest_point {
            return Err(Error::OutOfRange {
                key: "probes.points",
                value: p.z,
                range: format!(
                    "0 or [{}, {}] m for z",
                    End(lowest_point, true),
                    End(lz, false)
                ),
                reason: "a point closer to the interface than this needs more alias terms than \
                         their budget: use z = 0, or raise the point or probes.tolerance",
            });
        }
    }
    Ok(())
}

/// The heights `planes` (key `key`): `0` (the interface) or within `[z_min, Lz]`, where
/// the transfer's alias sums converge at the probes' `tolerance`.
fn planes_within(key: &'static str, planes: &[f64], grid: &Grid, tolerance: f64) -> Result<()> {
    let lowest = crate::green::lowest_plane(grid, tolerance);
    let lz = grid.block().lz();
    for &z in planes {
        if z == 0.0 || (z.is_finite() && (lowest..=lz).contains(&z)) {
            continue;
        }
        return Err(Error::OutOfRange {
            key,
            value: z,
            range: format!("0 or [{}, {}] m", End(lowest, true), End(lz, false)),
            reason: "a plane lies in the block (z = 0 is the interface); the stresses on a \
                     plane closer to the interface than about 0.007 cells (at \
                     probes.tolerance 1e-10) need more alias terms than their budget: \
                     use z = 0, or raise the plane or probes.tolerance",
        });
    }
    count_within(
        key,
        planes.len(),
        (0, MAX_PROBES),
        "each probe costs a kernel of Nx·Ny values",
    )
}

/// What a run records ([`RunOptions`](crate::recording::RunOptions), scene-file keys
/// `fields` and `profiles`) on `grid` at the probes' `tolerance`: the planes as
/// [`planes_within`], the profiles' loads `F/(μF_N)` within `[0, 1]` and at most
/// [`MAX_PROBES`] of them.
pub(crate) fn run_options(
    options: &crate::recording::RunOptions,
    grid: &Grid,
    tolerance: f64,
) -> Result<()> {
    if let Some(probes) = options.probe_spec() {
        self::probes(probes, grid)?;
    }
    planes_within("fields.planes", options.field_planes(), grid, tolerance)?;
    planes_within("profiles.planes", options.profile_planes(), grid, tolerance)?;
    for &load in options.profile_loads() {
        within(
            "profiles.loads",
            load,
            (0.0, 1.0),
            "(F/(μF_N))",
            "no stable state carries a load beyond the friction limit μF_N",
        )?;
    }
    // `profiles.csv` writes a load with 13 significant digits, and readers find a load's
    // rows by that text.
    for pair in options.profile_loads().windows(2) {
        if format!("{:.12e}", pair[0]) == format!("{:.12e}", pair[1]) {
            return Err(Error::InvalidParameter {
                name: "profiles.loads",
                value: pair[1],
                reason: "it equals another load to the 13 significant digits profiles.csv \
                         writes, so the table could not tell their rows apart: give it once",
            });
        }
    }
    count_within(
        "profiles.loads",
        options.profile_loads().len(),
        (0, MAX_PROBES),
        "each load is a row group of the table",
    )?;
    output(options, grid, &ProbeSpec::default())
}

/// The most bytes a recording may be allowed (`max_output_bytes`): a petabyte.
pub(crate) const MAX_OUTPUT_BYTES: f64 = 1e15;

/// The recorded tables' estimated size against the run's limit (`max_output_bytes`),
/// before anything is planned or written.
fn output(options: &crate::recording::RunOptions, grid: &Grid, probes: &ProbeSpec) -> Result<()> {
    let limit = options.output_limit();
    within(
        "max_output_bytes",
        limit,
        (0.0, MAX_OUTPUT_BYTES),
        "B",
        "the limit on the recorded tables' estimated size (fields.csv and profiles.csv)",
    )?;
    let cost = options.cost(grid, probes);
    if cost.output_bytes() > limit {
        return Err(Error::OutputTooLarge {
            fields_bytes: cost.fields_bytes,
            profiles_bytes: cost.profiles_bytes,
            limit,
        });
    }
    Ok(())
}

/// The mean normal pressure `F_N/(Lx Ly)`, over Young's modulus, below which a block with
/// a length of 1 m or more is taken for millimetres typed as metres: the calibration
/// scene's is 1.2e-3, the same numbers in metres 1.2e-9; a real metre-sized block this
/// lightly pressed confirms it with `confirm_metres`.
pub(crate) const MILLIMETRE_PRESSURE: f64 = 1e-6;

/// Refuses a scene whose numbers point to lengths in millimetres (docs/scene-format.md).
fn millimetres(builder: &SceneBuilder) -> Result<()> {
    let (lx, ly, lz) = builder.lengths;
    let pressure = builder.normal_load / (lx * ly);
    let young = builder.material.young_modulus();
    if builder.confirm_metres || lx.max(ly).max(lz) < 1.0 || pressure >= MILLIMETRE_PRESSURE * young
    {
        return Ok(());
    }
    Err(Error::LikelyMillimetres {
        block: (lx, ly, lz),
        pressure,
        young_modulus: young,
    })
}

/// Everything but the geometry (after the builder's own checks of signs and finiteness).
pub(super) fn physics(builder: &SceneBuilder, grid: &Grid) -> Result<()> {
    const HUGE: &str = "beyond it the model's products overflow or underflow f64";
    let m = builder.material;
    within(
        "material.young_modulus",
        m.young_modulus(),
        YOUNG,
        "Pa",
        HUGE,
    )?;
    within(
        "material.poisson_ratio",
        m.poisson_ratio(),
        POISSON,
        "",
        "1 + ν must be at least 1e-6 (M = E/(1 + ν))",
    )?;
    within(
        "material.friction_coefficient",
        m.friction_coefficient(),
        FRICTION,
        "",
        HUGE,
    )?;
    within("springs.c_x", builder.law.c_x(), C_X, "N/m³", HUGE)?;
    within("springs.c_z", builder.law.c_z(), C_Z, "N/m²", HUGE)?;
    within("normal_load", builder.normal_load, NORMAL_LOAD, "N", HUGE)?;
    millimetres(builder)?;
    heights(&builder.heights)?;
    maps(builder, grid)?;
    drive(builder)?;
    let o = builder.solver;
    within(
        "solver.tolerance",
        o.tolerance(),
        SOLVER_TOLERANCE,
        "",
        "no linear solve reaches a backward error below 1e-15, and above 1e-6 the \
         events and loads are wrong without notice (docs/accuracy.md)",
    )?;
    resolution(builder)?;
    solver_iterations(o.max_active_set_iterations(), o.max_linear_iterations())?;
    if builder.plan_tolerance > PLAN_TOLERANCE_MAX {
        return Err(out_of_range(
            "plan_tolerance",
            builder.plan_tolerance,
            2e-13,
            PLAN_TOLERANCE_MAX,
            "",
            "the eigenvalues are computed to about 1e-13 whatever it is; it is the largest \
             relative error accepted, and above 1e-2 it accepts anything",
        ));
    }
    // The scene's own probes, and those of its run options (which its drivers start
    // with in their place).
    probes(&builder.probes, grid)?;
    run_options(&builder.run, grid, builder.effective_probes().tolerance())?;
    // A drawn c_z map is checked when it is drawn (`SceneBuilder::build`).
    let c_z = match &builder.maps.0[2] {
        None => builder.law.c_z(),
        Some(SiteMap::Values(v)) => v.iter().fold(f64::INFINITY, |a, &b| a.min(b)),
        Some(SiteMap::Surface { .. }) => f64::INFINITY,
    };
    load_exponent(builder, grid, c_z)
}

/// The normal load against the smallest `c_z` (N/m²): the last site attached carries the
/// whole normal load, and its tangential stiffness and area grow like `e^{F_N/(ΔA c_z)}`.
pub(super) fn load_exponent(builder: &SceneBuilder, grid: &Grid, c_z: f64) -> Result<()> {
    let exponent = builder.normal_load / (grid.cell_area() * c_z);
    if exponent.is_nan() || exponent > MAX_EXPONENT {
        return Err(out_of_range(
            "normal_load",
            builder.normal_load,
            NORMAL_LOAD.0,
            MAX_EXPONENT * grid.cell_area() * c_z,
            "N (at most 650 ΔA c_z, with a map of c_z its smallest value)",
            "the last site attached carries the whole normal load, and its stiffness \
             c_x·exp(F_N/(ΔA c_z) - 1) and contact area overflow beyond 650 ΔA c_z",
        ));
    }
    Ok(())
}

/// A map's key, range, unit, and keys of a random map's mean and standard deviation.
type MapBounds = (
    &'static str,
    (f64, f64),
    &'static str,
    &'static str,
    &'static str,
);

/// The maps' keys ([`super::MAP_KEYS`] under `maps`), their ranges (the scalars') and
/// units, and the keys of a random map's mean and standard deviation.
const MAPS: [MapBounds; 3] = [
    (
        "maps.friction_coefficient",
        FRICTION,
        "",
        "maps.friction_coefficient.mean",
        "maps.friction_coefficient.std_dev",
    ),
    ("maps.c_x", C_X, "N/m³", "maps.c_x.mean", "maps.c_x.std_dev"),
    ("maps.c_z", C_Z, "N/m²", "maps.c_z.mean", "maps.c_z.std_dev"),
];

/// The range of the map `k`'s values (in the order of [`super::MAP_KEYS`]) and its unit.
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) fn map_range(k: usize) -> (f64, f64, &'static str) {
    let (_, (min, max), unit, _, _) = MAPS[k];
    (min, max, unit)
}

/// The values of the map `k`: one per site, each within its scalar's range.
pub(super) fn map_values(k: usize, values: &[f64], sites: usize) -> Result<()> {
    let (key, (min, max), unit, _, _) = MAPS[k];
    if values.len() != sites {
        return Err(Error::LengthMismatch {
            name: key,
            expected: sites,
            found: values.len(),
        });
    }
    if let Some((index, &value)) = values
        .iter()
        .enumerate()
        .find(|(_, v)| !(min..=max).contains(*v))
    {
        let unit = if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        };
        return Err(Error::MapValue {
            key,
            index,
            value,
            range: format!(
                "[{}, {}]{unit} (the range of the scalar)",
                End(min, true),
                End(max, false)
            ),
        });
    }
    Ok(())
}

/// The maps of a scene: given values (count and range), a random map's mean and
/// standard deviation (within the scalar's range) and its spectrum on the grid.
fn maps(builder: &SceneBuilder, grid: &Grid) -> Result<()> {
    for (k, map) in builder.maps.0.iter().enumerate() {
        let (_, range, unit, mean_key, std_key) = MAPS[k];
        match map {
            None => {}
            Some(SiteMap::Values(v)) => map_values(k, v, grid.len())?,
            Some(SiteMap::Surface {
                spectrum,
                mean,
                std_dev,
                ..
            }) => {
                within(
                    mean_key,
                    *mean,
                    range,
                    unit,
                    "a map's mean lies in the range of the scalar it replaces",
                )?;
                within(
                    std_key,
                    *std_dev,
                    (0.0, range.1),
                    unit,
                    "a map's standard deviation is finite, >= 0 and within the range of \
                     the scalar it replaces",
                )?;
                crate::surface::Plan::new(grid, spectrum)?;
            }
        }
    }
    Ok(())
}

/// The gaps are resolved to about `tolerance · R` of the asperities' height, where
/// `R = (F_N/(Lx Ly))·max(Lx, Ly, Lz)/(M h̄)` is the block's displacement under the mean
/// pressure over the mean height `h̄`: a linear solve stops at a residual of `tolerance`
/// times the displacements it adds up. Measured on the calibration scene (`R = 180`): the
/// contact area at zero shear is off by 1.4e-4 at `tolerance = 1e-6`, 4.2e-2 at `1e-4`,
/// 0.66 at `1e-3` (docs/scene-format.md), about `tolerance · R`.
const MAX_GAP_ERROR: f64 = 1e-3;

fn resolution(builder: &SceneBuilder) -> Result<()> {
    let (lx, ly, lz) = builder.lengths;
    let mean_height = match &builder.heights {
        HeightSource::Random { distribution, .. } | HeightSource::Surface { distribution, .. }
            if distribution.mean() > 0.0 =>
        {
            distribution.mean()
        }
        HeightSource::Random { distribution, .. } | HeightSource::Surface { distribution, .. } => {
            distribution.std_dev()
        }
        HeightSource::Values(v) => v.iter().sum::<f64>() / v.len() as f64,
    };
    let r = builder.normal_load / (lx * ly) * lx.max(ly).max(lz)
        / (builder.material.modulus() * mean_height);
    let tolerance = builder.solver.tolerance();
    if (tolerance * r).is_nan() || tolerance * r > MAX_GAP_ERROR {
        let most = MAX_GAP_ERROR / r;
        if most >= SOLVER_TOLERANCE.0 {
            return Err(out_of_range(
                "solver.tolerance",
                tolerance,
                SOLVER_TOLERANCE.0,
                most,
                "(at most 1e-3 over R, R = F_N/(Lx Ly)·max(Lx, Ly, Lz)/(M h̄) the block's \
                 displacement over the mean asperity height)",
                "the gaps between block and asperities are resolved to tolerance·R of \
                 their height",
            ));
        }
        return Err(out_of_range(
            "normal_load",
            builder.normal_load,
            NORMAL_LOAD.0,
            builder.normal_load * MAX_GAP_ERROR / (SOLVER_TOLERANCE.0 * r),
            "N (the block's displacement under it at most 1e12 mean asperity heights)",
            "the gaps between block and asperities are resolved to tolerance·R of their \
             height, and R = F_N/(Lx Ly)·max(Lx, Ly, Lz)/(M h̄) is too large for any \
             tolerance (lower the load, stiffen the block or raise the heights)",
        ));
    }
    // A site's contact area follows its compression (h - u_z)/h = φ_z/c_z, about
    // p = F_N/(Lx Ly c_z) under the mean pressure; resolved to tolerance·R of the height,
    // its relative error is about tolerance·R/p. With springs far stiffer than the load
    // (p of 1e-14 at c_z = 1e19 N/m²) the areas were rounding noise written with exit 0.
    // With a map of c_z, its mean (of the values, or of a random map's Gaussian).
    let c_z = match &builder.maps.0[2] {
        None => builder.law.c_z(),
        Some(SiteMap::Values(v)) => v.iter().sum::<f64>() / v.len().max(1) as f64,
        Some(SiteMap::Surface { mean, .. }) => *mean,
    };
    let p = builder.normal_load / (lx * ly * c_z);
    if (tolerance * r / p).is_nan() || tolerance * r > MAX_AREA_ERROR * p {
        let most = MAX_AREA_ERROR * p / r;
        if most >= SOLVER_TOLERANCE.0 {
            return Err(out_of_range(
                "solver.tolerance",
                tolerance,
                SOLVER_TOLERANCE.0,
                most,
                "(at most 5e-2·p/R, p = F_N/(Lx Ly c_z) the springs' compression under the \
                 mean pressure)",
                "the contact areas follow the springs' compression, resolved to about \
                 tolerance·R/p of itself",
            ));
        }
        return Err(out_of_range(
            "springs.c_z",
            builder.law.c_z(),
            C_Z.0,
            builder.normal_load * MAX_AREA_ERROR / (lx * ly * SOLVER_TOLERANCE.0 * r),
            "N/m² (the springs' compression under the mean pressure, F_N/(Lx Ly c_z), at \
             least 1e-15·R/5e-2)",
            "the contact areas follow the springs' compression p = F_N/(Lx Ly c_z), which no \
             solver tolerance resolves for springs this stiff against the load",
        ));
    }
    Ok(())
}

/// The largest relative error of the contact areas [`resolution`] accepts (`tolerance·R/p`,
/// a pessimistic estimate: on the calibration scene at `tolerance = 1e-6` it is 8e-3, the
/// measured error of `A_R(0)` 1.4e-4; the N = 1e4 scene of docs/accuracy.md at `1e-6`: 1.2e-2).
const MAX_AREA_ERROR: f64 = 5e-2;

fn heights(source: &HeightSource) -> Result<()> {
    const WHY: &str = "asperity heights beyond it overflow or underflow the compliances";
    match source {
        HeightSource::Random { distribution, .. } | HeightSource::Surface { distribution, .. } => {
            if let HeightSource::Surface { spectrum, .. } = source {
                surface_lengths(spectrum)?;
            }
            let (mean, sd) = (distribution.mean(), distribution.std_dev());
            if mean.is_finite() && mean != 0.0 {
                within("heights.mean", mean.abs(), HEIGHT, "m (in magnitude)", WHY)?;
            }
            if sd.is_finite() && sd != 0.0 {
                within("heights.std_dev", sd, HEIGHT, "m (or 0)", WHY)?;
            }
        }
        HeightSource::Values(values) => {
            // Values that are not heights at all (NaN, ≤ 0) are the build's errors, by index.
            if let Some(&v) = values
                .iter()
                .find(|v| v.is_finite() && **v > 0.0 && !(HEIGHT.0..=HEIGHT.1).contains(*v))
            {
                within("heights.values", v, HEIGHT, "m", WHY)?;
            }
        }
    }
    Ok(())
}

/// The lengths of a surface's spectrum (m) within [`LENGTH`] (the synthesis' own limits,
/// modes and quadrature points, are checked against the grid by `surface::Plan`).
fn surface_lengths(spectrum: &SurfaceSpectrum) -> Result<()> {
    const WHY: &str = "a surface's lengths must lie within the range of the block's";
    match *spectrum {
        SurfaceSpectrum::Gaussian {
            correlation_length, ..
        } => within(
            "heights.correlation_length",
            correlation_length,
            LENGTH,
            "m",
            WHY,
        ),
        SurfaceSpectrum::SelfAffine {
            roll_off,
            short_cutoff,
            long_cutoff,
            ..
        } => {
            within("heights.roll_off", roll_off, LENGTH, "m", WHY)?;
            within("heights.short_cutoff", short_cutoff, LENGTH, "m", WHY)?;
            within("heights.long_cutoff", long_cutoff, LENGTH, "m", WHY)
        }
    }
}

fn drive(builder: &SceneBuilder) -> Result<()> {
    let lz = builder.lengths.2;
    let half_width = |key: &'static str, lateral: Lateral| match lateral {
        Lateral::Rod { half_width, .. } if half_width.is_finite() && half_width > 0.0 => {
            if half_width < HALF_WIDTH * lz {
                Err(out_of_range(
                    key,
                    half_width,
                    HALF_WIDTH * lz,
                    lz / 2.0,
                    "m (1e-6 Lz to Lz/2)",
                    "the band's load is a difference of sines that loses log10(Lz/Δh) digits",
                ))
            } else {
                Ok(())
            }
        }
        _ => Ok(()),
    };
    match builder.drive {
        Drive::Force(ForceLoad::Top) => Ok(()),
        Drive::Force(ForceLoad::Lateral(l)) => half_width("drive.half_width", l),
        Drive::Force(ForceLoad::Mixed { ratio, lateral }) => {
            if ratio.is_finite() && ratio >= 0.0 {
                within(
                    "drive.ratio",
                    ratio,
                    RATIO,
                    "",
                    "above 1e12 the lateral part is below rounding: use the top drive",
                )?;
            }
            half_width("drive.lateral.half_width", lateral)
        }
        Drive::Spring { stiffness, lateral } => {
            if stiffness.is_finite() && stiffness > 0.0 {
                let (lx, ly, lz) = builder.lengths;
                let block = builder.material.modulus() * ly * lz / lx;
                let (low, high) = (STIFFNESS.0 * block, STIFFNESS.1 * block);
                if !(low..=high).contains(&stiffness) {
                    return Err(Error::OutOfRange {
                        key: "drive.stiffness",
                        value: stiffness,
                        range: format!(
                            "[{}, {}] N/m (1e-12 to 1e12 times the block's shear stiffness \
                             M·Ly·Lz/Lx = {} N/m)",
                            End(low, true),
                            End(high, false),
                            Short(block)
                        ),
                        reason: "a softer spring is force control to twelve digits and its \
                                 drive displacement F/K_S overflows, a stiffer one is a rigid \
                                 displacement control (use those drives)",
                    });
                }
            }
            half_width("drive.lateral.half_width", lateral)
        }
    }
}

/// What a scene's observers cost on `grid` (`SceneBuilder::observer_cost`): its run
/// options' recording and planes, and its own probes, which the scene plans even where
/// the run options give its drivers others.
pub(super) fn observer_cost(builder: &SceneBuilder, grid: &Grid) -> crate::recording::ObserverCost {
    let mut cost = builder.run.cost(grid, &builder.probes);
    if builder.run.probe_spec().is_some() {
        let own = crate::recording::RunOptions::new().cost(grid, &builder.probes);
        cost.memory_bytes += own.memory_bytes;
        cost.plan_seconds += own.plan_seconds;
    }
    cost
}

/// Bytes of a built scene and its driver on `grid` with these probes and heights
/// ([`crate::GridCost`] plus what it leaves out).
pub(super) fn memory_bytes(builder: &SceneBuilder, grid: &Grid) -> f64 {
    let n = grid.len() as f64;
    let cost = crate::cost::GridCost::of(grid.nx(), grid.ny()).memory_bytes;
    let probes = observer_cost(builder, grid).memory_bytes;
    // Given heights are copied into the interface.
    let heights = match &builder.heights {
        HeightSource::Values(v) => 8.0 * v.len() as f64,
        // Drawn heights: the surface's synthesis checks its own memory.
        HeightSource::Random { .. } | HeightSource::Surface { .. } => 0.0,
    };
    // An explicit dense backend above the size `Auto` solves densely (GridCost's own).
    let dense = match builder.solver.backend() {
        crate::solver::Backend::Dense if grid.len() > crate::solver::AUTO_DENSE_LIMIT => {
            crate::green::dense_bytes(n)
        }
        _ => 0.0,
    };
    cost + probes + heights + dense
}

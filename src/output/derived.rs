//! The tables a run's end derives from its whole `events.csv` and `curve.csv`
//! (`RunTables::finish`): `per_avalanche.csv`, one row per avalanche, and `fronts.csv`,
//! the damage front beside `ℓ` at every stable state (docs/statistics.md defines both).
//! Derived, not recorded as the run goes: a resumed run's come out the same, and
//! `precursors stats` derives them again from the checked `events.csv` rather than trust
//! these files.

use super::check::{whole_curve, whole_events, Bounds, CurveRow};
use super::optional;
use crate::avalanche::{Avalanche, Avalanches, DamageFront};
use crate::driver::Event;
use crate::error::{Error, Result};
use crate::files::write_atomically;
use crate::geometry::Grid;
use std::fmt::Write as _;
use std::path::Path;

/// One row per avalanche.
pub(crate) const AVALANCHE_TABLE: &str = "per_avalanche.csv";
/// The damage front and `ℓ` at every stable state.
pub(crate) const FRONTS_TABLE: &str = "fronts.csv";
/// The header of `per_avalanche.csv`.
pub(crate) const AVALANCHE_HEADER: &str = "avalanche,start_event,end_event,ruptures,\
     broken_area_m2,force_before_N,force_after_N,force_drop_N,drive_displacement_before_m,\
     drive_displacement_after_m,energy_J,attaches,detaches,flash_ruptures,global_slip,\
     ruptures_without_flash,contacts_before,contacts_after,spanning,after_spanning,extent_m,\
     centroid_m,potency_m3,slip_centroid_m,released_energy_J";
/// The header of `fronts.csv`.
pub(crate) const FRONTS_HEADER: &str =
    "event,force_N,force_over_mu_FN,precursor_over_Lx,damage_front_m,damage_front_over_Lx,\
     damage_front_quarter_m,damage_front_three_quarters_m";

/// The other thresholds of `fronts.csv`: the share of a column's contacts lost
/// ([`DamageFront::position_at`]), beside the half of [`DamageFront::position`].
const FRONT_THRESHOLDS: [f64; 2] = [0.25, 0.75];

/// What a whole run's events give: its avalanches, and the damage front (m) at each
/// stable state (in order, the zero-shear state first).
#[derive(Debug, Clone)]
pub(crate) struct RunDerived {
    pub avalanches: Vec<Avalanche>,
    pub fronts: Vec<f64>,
    /// The damage front (m) at each stable state at [`FRONT_THRESHOLDS`].
    pub fronts_at: Vec<[f64; 2]>,
}

/// The avalanches and damage fronts of the whole run `events` on `grid`.
///
/// # Errors
/// [`Error::LengthMismatch`] when `events` are not a whole run on `grid`.
pub(crate) fn derive(grid: &Grid, events: &[Event]) -> Result<RunDerived> {
    let zero_shear = DamageFront::zero_shear_states(grid, events)?;
    let mut front = DamageFront::new(grid, &zero_shear)?;
    let mut avalanches = Avalanches::with_zero_shear(grid, &zero_shear)?;
    let mut out = RunDerived {
        avalanches: Vec::new(),
        fronts: Vec::new(),
        fronts_at: Vec::new(),
    };
    for event in events {
        front.observe(event);
        out.avalanches.extend(avalanches.observe(event));
        if let Event::Stable { .. } = event {
            out.fronts.push(front.position());
            out.fronts_at
                .push(FRONT_THRESHOLDS.map(|lost| front.front_lost(lost)));
        }
    }
    Ok(out)
}

/// Writes `per_avalanche.csv` and `fronts.csv` into `dir` (atomically) from the texts of
/// the run's whole `events.csv` and `curve.csv` (read from `paths`, named in errors).
///
/// # Errors
/// [`Error::CorruptTable`] (or [`Error::NonFiniteCell`]) when a table is not a whole run;
/// [`Error::Io`].
pub(crate) fn write(
    dir: &Path,
    grid: &Grid,
    bounds: &Bounds,
    texts: [&str; 2],
    paths: [&Path; 2],
) -> Result<()> {
    let whole = whole_events(texts[0], bounds).map_err(|bad| bad.at(paths[0]))?;
    let curve = whole_curve(texts[1], &whole.stable, bounds).map_err(|bad| bad.at(paths[1]))?;
    let derived = derive(grid, &whole.events).map_err(|e| Error::CorruptTable {
        path: Some(paths[0].to_path_buf()),
        reason: format!("not the whole run of its scene: {e}"),
    })?;
    write_atomically(
        &dir.join(AVALANCHE_TABLE),
        avalanche_text(&derived.avalanches, &curve).as_bytes(),
        "writing table",
    )?;
    write_atomically(
        &dir.join(FRONTS_TABLE),
        fronts_text(&curve, &derived, bounds.lx).as_bytes(),
        "writing table",
    )
}

/// What an avalanche slipped, from the slip per newton of load (`curve.csv`) of the
/// stable state before it and of the one it ends in (docs/statistics.md).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Slip {
    /// `Σ Δu_x ΔA` over the interface (m³).
    pub potency: Option<f64>,
    /// `Σ x Δu_x ΔA / Σ Δu_x ΔA` (m), where the potency is positive.
    pub centroid: Option<f64>,
    /// The work of the load less the change of the elastic energy (J), under force
    /// control: `½ F² (c_after - c_before)`.
    pub released: Option<f64>,
}

impl Slip {
    /// The slip of `a`, an avalanche of the run whose checked `curve.csv` rows are
    /// `curve` (one per stable state, in order).
    pub(crate) fn in_run(a: &Avalanche, curve: &[CurveRow]) -> Slip {
        let next = curve.partition_point(|c| c.event < a.start_event);
        let before = next.checked_sub(1).and_then(|i| curve.get(i));
        let after = curve.get(next).filter(|c| c.event == a.end_event);
        Slip::of(a, before, after)
    }

    /// The slip of `a` from the rows of the stable states before and after it: `None`
    /// where the after state is global slip (no stable state) or a row holds no slip
    /// (kept from a run 1.1 began). The state before holds at the avalanche's starting
    /// load (the set is the same, the equilibrium linear in the load).
    fn of(a: &Avalanche, before: Option<&CurveRow>, after: Option<&CurveRow>) -> Slip {
        let (Some([p0, m0, c0]), Some([p1, m1, c1])) =
            (before.and_then(|r| r.slip), after.and_then(|r| r.slip))
        else {
            return Slip::default();
        };
        let (f0, f1) = (a.load_before.force, a.load_after.force);
        // At one force (force control) the difference is taken first: no rounding of
        // two large products.
        let change = |x0: f64, x1: f64| {
            if f0 == f1 {
                f0 * (x1 - x0)
            } else {
                f1 * x1 - f0 * x0
            }
        };
        let potency = change(p0, p1);
        let moment = change(m0, m1);
        Slip {
            potency: Some(potency),
            centroid: (potency > 0.0).then(|| moment / potency),
            // A driving spring is not the work-conjugate of the lateral load it exerts
            // (the paper ties it to ⟨u_x⟩): no exact balance (docs/statistics.md).
            released: (a.load_before.drive_displacement.is_none() && f0 == f1)
                .then_some(0.5 * f0 * f0 * (c1 - c0)),
        }
    }
}

/// The text of `per_avalanche.csv`, each avalanche's slip from `curve`'s rows.
fn avalanche_text(avalanches: &[Avalanche], curve: &[CurveRow]) -> String {
    let mut text = format!("{AVALANCHE_HEADER}\n");
    for (k, a) in avalanches.iter().enumerate() {
        let slip = Slip::in_run(a, curve);
        let _ = writeln!(
            text,
            "{},{},{},{},{:.12e},{:.12e},{:.12e},{:.12e},{},{},{:.12e},{},{},{},{},{},{},{},{},{},\
             {:.12e},{:.12e},{},{},{}",
            k + 1,
            a.start_event,
            a.end_event,
            a.ruptures,
            a.broken_area,
            a.load_before.force,
            a.load_after.force,
            a.force_drop(),
            optional(a.load_before.drive_displacement),
            optional(a.load_after.drive_displacement),
            a.energy,
            a.attaches,
            a.detaches,
            a.flash_ruptures,
            u8::from(a.global_slip),
            a.ruptures - a.flash_ruptures,
            count(a.contacts_before),
            count(a.contacts_after),
            u8::from(a.spanning),
            u8::from(a.after_spanning),
            a.extent,
            a.centroid,
            optional(slip.potency),
            optional(slip.centroid),
            optional(slip.released),
        );
    }
    text
}

/// A count known only to a recorder told the zero-shear contacts (always, here).
fn count(n: Option<usize>) -> String {
    n.map(|n| n.to_string()).unwrap_or_default()
}

/// The text of `fronts.csv`: `curve`'s stable states (their loads and `ℓ/Lx` as written
/// there) with the damage fronts of each.
fn fronts_text(curve: &[CurveRow], derived: &RunDerived, lx: f64) -> String {
    let mut text = format!("{FRONTS_HEADER}\n");
    for ((c, front), [quarter, three_quarters]) in
        curve.iter().zip(&derived.fronts).zip(&derived.fronts_at)
    {
        let _ = writeln!(
            text,
            "{},{},{},{},{front:.12e},{:.12e},{quarter:.12e},{three_quarters:.12e}",
            c.event,
            c.force_text,
            c.load_text,
            c.precursor_text,
            front / lx,
        );
    }
    text
}

//! The contact rule: every transition of an interfacial site, in one place (issue 55).
//!
//! A site is attached, detached or broken ([`SiteState`]). Which available sites touch is
//! the normal equilibrium's (the solver's active set: its solution is unique, so attach
//! and detach are physics, not rule). The rule says the rest:
//! - when a tangential spring breaks: its threshold, and with it the breaking load
//!   `λ_i` of each site ([`ContactRule::breaking_loads`]), the sites over threshold and
//!   the one of them that breaks first ([`ContactRule::next_rupture`]), the next
//!   threshold of a stable state ([`ContactRule::weakest`]) and global slip;
//! - which attach and detach events a new normal equilibrium gives
//!   ([`ContactRule::changes`]);
//! - whether a broken site re-forms, and so which sequences of site events a run can
//!   write ([`Replay`]) and which states a checkpoint can hold.
//!
//! The driver, its checkpoints and the resume's replay of `events.csv` ask it; none
//! re-derives it. The rules are a closed enum, matched once per call outside the
//! per-site loops: the paper's rule costs what the code it replaced cost, and gives the
//! same bits.

use crate::error::{check_slice, Error, Result};
use crate::interface::{Interface, SiteState};

/// The rule of a run's site transitions. Only the paper's for now.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) enum ContactRule {
    /// The paper's: the Coulomb threshold `|φ_x| = μ φ_z` of a spring anchored at
    /// `u_x = 0`; among the sites over threshold the one of largest elastic energy
    /// breaks first; a broken site never re-forms.
    #[default]
    Paper,
}

/// A change of one site's state, as the events `rupture`, `detach` and `attach` record it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SiteChange {
    /// The tangential spring broke (attached → broken).
    Rupture,
    /// The site left the contact (attached → detached).
    Detach,
    /// The site entered the contact (detached → attached).
    Attach,
}

impl SiteChange {
    /// The state the change leaves the site in.
    pub(crate) fn to(self) -> SiteState {
        match self {
            SiteChange::Rupture => SiteState::Broken,
            SiteChange::Detach => SiteState::Detached,
            SiteChange::Attach => SiteState::Attached,
        }
    }
}

/// The paper's threshold test: a site breaks once the load reaches its breaking load.
#[inline]
fn paper_over(breaking: f64, force: f64) -> bool {
    breaking <= force
}

/// The paper's breaking load of one site (N): the threshold `μ φ_z` (Pa) over the shear
/// traction per newton `|g|` (Pa/N), `+∞` where the site carries no shear. One
/// expression for every caller: `(μ f) / |g|`, in that order, gives the same bits as
/// the 1.x code.
#[inline]
fn paper_breaking_load(friction_coefficient: f64, f: f64, g: f64) -> f64 {
    if g == 0.0 {
        f64::INFINITY
    } else {
        friction_coefficient * f / g.abs()
    }
}

impl ContactRule {
    /// The shear load (N) at which each site reaches its threshold, from the normal
    /// tractions (Pa), the shear tractions per newton of load (Pa/N) and the friction
    /// coefficient; `+∞` for sites that carry no shear.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] or [`Error::NonFinite`] for slices of the wrong length or
    /// with a value that is not finite; [`Error::InvalidParameter`] for a friction
    /// coefficient that is negative or not finite.
    pub(crate) fn breaking_loads(
        self,
        interface: &Interface,
        normal_traction: &[f64],
        shear_per_newton: &[f64],
        friction_coefficient: f64,
    ) -> Result<Vec<f64>> {
        let n = interface.states().len();
        check_slice("normal_traction", normal_traction, n)?;
        check_slice("shear_per_newton", shear_per_newton, n)?;
        if !(friction_coefficient.is_finite() && friction_coefficient >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "friction_coefficient",
                value: friction_coefficient,
                reason: "the friction coefficient must be finite and >= 0",
            });
        }
        Ok(match self {
            ContactRule::Paper => shear_per_newton
                .iter()
                .zip(normal_traction)
                .map(|(g, f)| paper_breaking_load(friction_coefficient, *f, *g))
                .collect(),
        })
    }

    /// The attached site with the smallest finite breaking load, and that load (N): the
    /// threshold a stable state's load is raised to. `None` when no attached site
    /// carries shear.
    pub(crate) fn weakest(self, states: &[SiteState], breaking: &[f64]) -> Option<(usize, f64)> {
        match self {
            ContactRule::Paper => {
                let mut best: Option<(usize, f64)> = None;
                for (i, &b) in breaking.iter().enumerate() {
                    if states[i] == SiteState::Attached
                        && b.is_finite()
                        && best.is_none_or(|(_, v)| b < v)
                    {
                        best = Some((i, b));
                    }
                }
                best
            }
        }
    }

    /// The first attached site over its threshold under the shear force `force` (N):
    /// what a stable state may not hold.
    pub(crate) fn first_over_threshold(
        self,
        states: &[SiteState],
        breaking: &[f64],
        force: f64,
    ) -> Option<usize> {
        match self {
            ContactRule::Paper => (0..breaking.len())
                .find(|&i| states[i] == SiteState::Attached && paper_over(breaking[i], force)),
        }
    }

    /// The site that breaks next in an avalanche under the shear force `force` (N), and
    /// its elastic energy (J): among the attached sites over threshold (and `forced`, the
    /// site whose threshold the load was raised to, over it by construction though
    /// rounding may say otherwise), the one of largest energy `½ φ_x² ΔA / k_x`, with
    /// `φ_x = F g` from the shear tractions per newton `traction` (Pa/N) at the normal
    /// displacements `u_z` (m); `cell` is `ΔA` (m²). `None` when no site is over
    /// threshold: the avalanche has ended.
    ///
    /// # Errors
    /// [`Error::NonFinite`] when the chosen site's compliance overflows.
    #[allow(clippy::too_many_arguments)] // the state of one avalanche step, as the driver holds it
    pub(crate) fn next_rupture(
        self,
        interface: &Interface,
        breaking: &[f64],
        force: f64,
        forced: Option<usize>,
        traction: &[f64],
        u_z: &[f64],
        cell: f64,
    ) -> Result<Option<(usize, f64)>> {
        let best = match self {
            ContactRule::Paper => {
                largest_energy(interface, breaking, force, forced, traction, u_z, cell)
            }
        };
        match best {
            Some(i) => {
                let phi = force * traction[i];
                Ok(Some((i, interface.rupture_energy(i, u_z[i], phi, cell)?)))
            }
            None => Ok(None),
        }
    }

    /// Whether the interface slides as a whole: every spring broke.
    pub(crate) fn global_slip(self, interface: &Interface) -> bool {
        match self {
            ContactRule::Paper => interface.broken_count() == interface.states().len(),
        }
    }

    /// The attach and detach events of a new normal equilibrium, in site order: `emit`
    /// is called with each site that went from `before` to `after` into the contact
    /// (`true`, an attach) or out of it (`false`, a detach). A rupture is the protocol's
    /// own event, never a change of an equilibrium.
    pub(crate) fn changes(
        self,
        before: &[SiteState],
        after: &[SiteState],
        mut emit: impl FnMut(usize, bool),
    ) {
        match self {
            ContactRule::Paper => {
                for (i, (old, new)) in before.iter().zip(after).enumerate() {
                    match (old, new) {
                        (SiteState::Attached, SiteState::Detached) => emit(i, false),
                        (SiteState::Detached, SiteState::Attached) => emit(i, true),
                        _ => {}
                    }
                }
            }
        }
    }

    /// The most ruptures the avalanche under way can have had in the site states
    /// `states`: each broke a site that is still broken (no site re-forms inside an
    /// avalanche).
    pub(crate) fn avalanche_ruptures_bound(self, states: &[SiteState]) -> usize {
        match self {
            ContactRule::Paper => states.iter().filter(|s| **s == SiteState::Broken).count(),
        }
    }

    /// Whether a site that broke may change again (re-form).
    fn reforms(self) -> bool {
        match self {
            ContactRule::Paper => false,
        }
    }
}

/// The paper's choice of the next rupture ([`ContactRule::next_rupture`]): its index.
/// The order key is `ln` of the energy ([`Interface::log_rupture_energy`]), which
/// neither underflow nor overflow can tie; ties keep the first site.
fn largest_energy(
    interface: &Interface,
    breaking: &[f64],
    force: f64,
    forced: Option<usize>,
    traction: &[f64],
    u_z: &[f64],
    cell: f64,
) -> Option<usize> {
    let states = interface.states();
    let mut best: Option<(usize, f64)> = None;
    for i in 0..states.len() {
        if states[i] != SiteState::Attached {
            continue;
        }
        if paper_over(breaking[i], force) || forced == Some(i) {
            let phi = force * traction[i];
            let key = interface.log_rupture_energy(i, u_z[i], phi, cell);
            if best.is_none_or(|(_, k)| key > k) {
                best = Some((i, key));
            }
        }
    }
    best.map(|(i, _)| i)
}

/// The site states a run's site events leave, replayed in order under a rule: the
/// resume's check of a checkpoint's states against its `events.csv`. Each change is
/// tagged (with its line in the table) so that a refusal names where it happened.
pub(crate) struct Replay {
    rule: ContactRule,
    /// Per site: the state its last change left and that change's tag.
    last: Vec<Option<(SiteState, usize)>>,
}

impl Replay {
    /// No change yet on `sites` sites.
    pub(crate) fn new(rule: ContactRule, sites: usize) -> Self {
        Self {
            rule,
            last: vec![None; sites],
        }
    }

    /// Applies `change` of site `index` (tagged `tag`). `Err(tag of the rupture)` when
    /// the rule forbids it: under the paper's rule, any change of a broken site. A site
    /// beyond the grid is ignored (the row checks refuse it).
    pub(crate) fn apply(
        &mut self,
        index: usize,
        change: SiteChange,
        tag: usize,
    ) -> Result<(), usize> {
        let reforms = self.rule.reforms();
        let Some(slot) = self.last.get_mut(index) else {
            return Ok(());
        };
        if let Some((SiteState::Broken, broke)) = *slot {
            if !reforms {
                return Err(broke);
            }
        }
        *slot = Some((change.to(), tag));
        Ok(())
    }

    /// The state the changes so far leave site `index` in when `state` is not one of
    /// them, with the tag of its last change (`None` without one); `None` when `state`
    /// fits. A site no change touched may be attached or detached (the normal
    /// equilibrium at zero shear chose), never broken: only a rupture breaks a site.
    pub(crate) fn mismatch(
        &self,
        index: usize,
        state: SiteState,
    ) -> Option<(SiteState, Option<usize>)> {
        let (expected, tag) = match self.last.get(index).copied().flatten() {
            Some((s, tag)) => (s, Some(tag)),
            None if state == SiteState::Broken => (SiteState::Attached, None),
            None => return None,
        };
        (expected != state).then_some((expected, tag))
    }
}

impl Interface {
    /// The Coulomb rule: the shear load (N) at which each site reaches the threshold
    /// `|φ_x| = μ φ_z`, `λ_i = μ φ_z,i / |φ_x,i(1)|` (paper Eq. lambda_Amonton_dscrt), from
    /// the normal tractions (Pa) and the shear tractions per newton of load (Pa/N,
    /// [`crate::solver::TangentialResponse::traction`]). `+∞` for sites that carry no shear
    /// (detached, broken, or exactly unloaded).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] for slices of the wrong length;
    /// [`Error::InvalidParameter`] for a friction coefficient that is negative or not
    /// finite.
    pub fn breaking_loads(
        &self,
        normal_traction: &[f64],
        shear_per_newton: &[f64],
        friction_coefficient: f64,
    ) -> Result<Vec<f64>> {
        // Defined here, not in interface.rs: the threshold is the contact rule's.
        ContactRule::Paper.breaking_loads(
            self,
            normal_traction,
            shear_per_newton,
            friction_coefficient,
        )
    }
}

#[cfg(test)]
mod tests;

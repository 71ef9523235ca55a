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

mod law;

pub use law::{ContactLaw, CustomRule, SiteView};

use crate::error::{check_slice, Error, Result};
use crate::interface::{Interface, SiteState};
use std::sync::Arc;

/// The rule of a run's site transitions ([`SceneBuilder::contact_rule`](crate::SceneBuilder::contact_rule),
/// scene-file key `contact`, `docs/scene-format.md`; the physics in `docs/model.md`).
/// The built-in rules are scene-file values; a downstream crate writes its own as a
/// [`ContactLaw`] ([`ContactRule::custom`]).
///
/// ```
/// use precursors::{ContactRule, Delay, Scene};
/// let rule = ContactRule::Rejuvenation { delay: Delay::new(3, 0.02)? };
/// let scene = Scene::builder()
///     .block(0.012, 0.002, 0.010)
///     .normal_load(40.0)
///     .contact_rule(rule.clone())
///     .build()?;
/// assert_eq!(scene.contact_rule(), &rule);
/// assert_eq!(rule.name(), "rejuvenation");
/// let default = Scene::builder().block(0.012, 0.002, 0.010).normal_load(40.0).build()?;
/// assert_eq!(default.contact_rule(), &ContactRule::Paper);
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub enum ContactRule {
    /// The paper's (the default): the Coulomb threshold `|φ_x| = μ φ_z` (Pa) of a spring
    /// anchored at `u_x = 0`; among the sites over threshold the one of largest elastic
    /// energy breaks first; a broken site never re-forms.
    #[default]
    Paper,
    /// The paper's threshold and order, with each spring anchored where its site
    /// attached: `φ_x = -k_x (u_x - a)`, `a` the site's `u_x` (m) when it attached, so
    /// that a site carries no shear at its attachment. A broken site never re-forms.
    Anchored,
    /// [`ContactRule::Anchored`], and a broken site re-forms (broken → detached, then
    /// the normal equilibrium decides whether it touches) once its [`Delay`] has passed,
    /// at the move from a stable state to the next load. Refused under a spring drive.
    Rejuvenation {
        /// How long a broken site stays broken.
        delay: Delay,
    },
    /// A rule written outside the crate ([`ContactLaw`], made by [`ContactRule::custom`]).
    /// Not a scene-file value: what it gives up is in [`ContactLaw`]'s documentation.
    Custom(CustomRule),
}

/// How long a broken site stays broken under [`ContactRule::Rejuvenation`], in the
/// protocol's quasi-static clock: both must have passed. Made by [`Delay::new`]; the
/// default is one stable state and no load.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Delay {
    /// Stable states reached since the rupture (`>= 1`).
    pub stable_states: u64,
    /// Increase of the shear force since the rupture, in units of `μ F_N`
    /// (dimensionless, finite, `>= 0`).
    pub load: f64,
}

impl Default for Delay {
    fn default() -> Self {
        Self {
            stable_states: 1,
            load: 0.01,
        }
    }
}

impl Delay {
    /// A delay of `stable_states` stable states (`>= 1`) and a shear-force increase of
    /// `load` times `μ F_N` (dimensionless, finite, `> 0`), both since the rupture. The
    /// default is 1 and 0.01. A load increase is required: at a constant load, sites that
    /// re-form after stable states alone can break and re-form again for ever (seen on
    /// the calibration scene: 40 000 ruptures at `F/(μF_N)` = 0.527), so a run under force
    /// control would not end; with `load = x` a site re-forms at most `1/x` times.
    ///
    /// # Errors
    /// [`Error::InvalidCount`] for no stable state, [`Error::InvalidParameter`] for a load
    /// that is not positive or not finite; each names its scene-file key
    /// (`contact.delay.*`).
    pub fn new(stable_states: u64, load: f64) -> Result<Self> {
        Self {
            stable_states,
            load,
        }
        .check()
    }

    /// The delay if it is valid ([`Delay::new`]'s checks).
    pub(crate) fn check(self) -> Result<Self> {
        if self.stable_states == 0 {
            return Err(Error::InvalidCount {
                name: "contact.delay.stable_states",
                value: 0,
                reason: "a broken site re-forms at a later stable state: the delay is >= 1",
            });
        }
        if !(self.load.is_finite() && self.load > 0.0) {
            return Err(Error::InvalidParameter {
                name: "contact.delay.load",
                value: self.load,
                reason: "the load increase a broken site waits for, in units of mu F_N, is \
                         finite and > 0: at a constant load re-formed sites may break and \
                         re-form for ever",
            });
        }
        Ok(self)
    }

    /// Whether a site broken at `since` may re-form at the clock tick `clock` under the
    /// force `force` (N); `load_scale` is `μ F_N` (N), `slack` (N) what the force may
    /// fall short by (rounding of a table's written forces).
    fn due(self, since: BrokenSince, clock: u64, force: f64, load_scale: f64, slack: f64) -> bool {
        clock.saturating_sub(since.clock) >= self.stable_states
            && force - since.force + slack >= self.load * load_scale
    }
}

/// When a site broke: the clock tick (stable states passed) and the force (N).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub(crate) struct BrokenSince {
    /// The clock tick of its avalanche.
    pub(crate) clock: u64,
    /// The shear force at the rupture (N).
    pub(crate) force: f64,
}

/// What a rule other than the paper's carries from one event to the next (none under
/// the paper's): the anchors, and for re-forming sites the clock and when each broken
/// site broke; under a custom rule also how often each site broke.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub(crate) struct ContactState {
    /// Per site, the `u_x` (m) at which its spring carries no shear: the site's `u_x` when
    /// it attached; `0` off the attached sites (and always, under a custom rule that
    /// does not anchor).
    pub(crate) anchors: Vec<f64>,
    /// The quasi-static clock: moves from a stable state to the next load made.
    pub(crate) clock: u64,
    /// Per site (re-forming rules only, else empty), when it broke if it is broken.
    pub(crate) broken_since: Vec<Option<BrokenSince>>,
    /// Per site, its ruptures so far (custom rules only, else empty). Never in a
    /// checkpoint: a custom rule has none.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub(crate) ruptures: Vec<u64>,
}

/// The fields of the current equilibrium a [`SiteView`] shows, as the driver holds them.
pub(crate) struct Fields<'a> {
    /// The site states.
    pub(crate) states: &'a [SiteState],
    /// `φ_z` (Pa) per site.
    pub(crate) normal_traction: &'a [f64],
    /// `u_z` (m) per site.
    pub(crate) normal_displacement: &'a [f64],
    /// `μ` (dimensionless) of the material.
    pub(crate) friction_coefficient: f64,
    /// `μ_i` per site where the scene has a friction map (it replaces the material's).
    pub(crate) friction_map: Option<&'a [f64]>,
    /// `F` (N).
    pub(crate) force: f64,
}

impl ContactState {
    /// The state at the start of a run of `sites` sites under `rule`: every spring
    /// anchored at 0 (the contact forms at zero shear); `None` under the paper's rule.
    pub(crate) fn new(rule: &ContactRule, sites: usize) -> Option<Self> {
        let (reforms, counts) = match rule {
            ContactRule::Paper => return None,
            ContactRule::Anchored => (false, false),
            ContactRule::Rejuvenation { .. } => (true, false),
            ContactRule::Custom(_) => (true, true),
        };
        Some(Self {
            anchors: vec![0.0; sites],
            clock: 0,
            broken_since: if reforms {
                vec![None; sites]
            } else {
                Vec::new()
            },
            ruptures: if counts { vec![0; sites] } else { Vec::new() },
        })
    }

    /// Records the rupture of `site` under the force `force` (N), at the current tick.
    pub(crate) fn broke(&mut self, site: usize, force: f64) {
        self.anchors[site] = 0.0;
        if let Some(slot) = self.broken_since.get_mut(site) {
            *slot = Some(BrokenSince {
                clock: self.clock,
                force,
            });
        }
        if let Some(count) = self.ruptures.get_mut(site) {
            *count += 1;
        }
    }

    /// What a custom law sees of site `i` in the equilibrium `fields`.
    fn view(&self, i: usize, fields: &Fields) -> SiteView {
        let since = self.broken_since.get(i).copied().flatten();
        SiteView {
            index: i,
            state: fields.states[i],
            normal_traction: fields.normal_traction[i],
            normal_displacement: fields.normal_displacement[i],
            friction_coefficient: fields
                .friction_map
                .map_or(fields.friction_coefficient, |mu| mu[i]),
            anchor: self.anchors[i],
            ruptures: self.ruptures.get(i).copied().unwrap_or(0),
            stable_states: self.clock,
            rupture_stable_states: since.map(|b| b.clock),
            rupture_force: since.map(|b| b.force),
            force: fields.force,
        }
    }

    /// The next tick of the clock (a move from a stable state to the next load) in the
    /// stable state `fields` (its force `F`, N): the broken sites whose delay has passed,
    /// or that a custom law re-forms, which re-form now (forgotten here); `load_scale` is
    /// `μ F_N` (N). None under [`ContactRule::Anchored`].
    pub(crate) fn tick(
        &mut self,
        rule: &ContactRule,
        fields: &Fields,
        load_scale: f64,
    ) -> Vec<usize> {
        self.clock += 1;
        let clock = self.clock;
        let mut due = Vec::new();
        match rule {
            ContactRule::Rejuvenation { delay } => {
                for (i, slot) in self.broken_since.iter_mut().enumerate() {
                    if let Some(since) = *slot {
                        if delay.due(since, clock, fields.force, load_scale, 0.0) {
                            *slot = None;
                            due.push(i);
                        }
                    }
                }
            }
            ContactRule::Custom(custom) => {
                due = (0..self.broken_since.len())
                    .filter(|&i| {
                        self.broken_since[i].is_some()
                            && custom.law().reforms(&self.view(i, fields))
                    })
                    .collect();
                for &i in &due {
                    self.broken_since[i] = None;
                }
            }
            ContactRule::Paper | ContactRule::Anchored => {}
        }
        due
    }

    /// The Coulomb threshold `τ_i` (Pa) a custom law gives each site of the equilibrium
    /// `fields` (0 off the attached sites, which carry no shear); `None` under a built-in
    /// rule (whose threshold is `μ φ_z`).
    ///
    /// # Errors
    /// [`Error::InvalidThreshold`] for a threshold that is negative or not finite.
    pub(crate) fn custom_thresholds(
        &self,
        rule: &ContactRule,
        fields: &Fields,
    ) -> Result<Option<Vec<f64>>> {
        let ContactRule::Custom(custom) = rule else {
            return Ok(None);
        };
        let law = custom.law();
        let mut taus = vec![0.0; fields.states.len()];
        for (i, tau) in taus.iter_mut().enumerate() {
            if fields.states[i] != SiteState::Attached {
                continue;
            }
            *tau = law.threshold(&self.view(i, fields));
            if !(tau.is_finite() && *tau >= 0.0) {
                return Err(Error::InvalidThreshold {
                    rule: law.name().to_string(),
                    site: i,
                    value: *tau,
                });
            }
        }
        Ok(Some(taus))
    }

    /// Whether the state fits `states` under `rule` on `sites` sites: its lengths, finite
    /// anchors zero off the attached sites, and a rupture time for each broken site and
    /// for it alone (re-forming rules). `Err(reason)` otherwise.
    pub(crate) fn check(
        &self,
        rule: &ContactRule,
        states: &[SiteState],
    ) -> std::result::Result<(), String> {
        let n = states.len();
        if self.anchors.len() != n {
            return Err(format!("{} anchors for {n} sites", self.anchors.len()));
        }
        if let Some(i) = (0..n).find(|&i| {
            !self.anchors[i].is_finite()
                || (states[i] != SiteState::Attached && self.anchors[i] != 0.0)
        }) {
            return Err(format!(
                "site {i} is {:?} with the anchor {:e} m (finite, and 0 unless attached)",
                states[i], self.anchors[i]
            ));
        }
        let reforms = matches!(
            rule,
            ContactRule::Rejuvenation { .. } | ContactRule::Custom(_)
        );
        if self.broken_since.len() != if reforms { n } else { 0 } {
            return Err(format!(
                "{} rupture times for {n} sites under the rule {rule:?}",
                self.broken_since.len()
            ));
        }
        if let Some(i) = (0..self.broken_since.len()).find(|&i| {
            (states[i] == SiteState::Broken) != self.broken_since[i].is_some()
                || self.broken_since[i]
                    .is_some_and(|b| b.clock > self.clock || !b.force.is_finite())
        }) {
            return Err(format!(
                "site {i} is {:?} with the rupture time {:?} (one for each broken site, at \
                 or before the clock {})",
                states[i], self.broken_since[i], self.clock
            ));
        }
        Ok(())
    }
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

/// An anchored site's threshold test: the load is out of its window, above or below.
#[inline]
fn anchored_over(high: f64, low: f64, force: f64) -> bool {
    high <= force || force <= low
}

/// The breaking load of one site (N) of a spring anchored at 0: the threshold `τ` (Pa)
/// over the shear traction per newton `|g|` (Pa/N), `+∞` where the site carries no
/// shear. One expression for every caller: `τ / |g|` with the paper's `τ = μ f` gives
/// the same bits as the 1.x code's `(μ f) / |g|`.
#[inline]
fn breaking_load(tau: f64, g: f64) -> f64 {
    if g == 0.0 {
        f64::INFINITY
    } else {
        tau / g.abs()
    }
}

/// The window of loads (N) inside which an anchored site holds, `(λ_high, λ_low)`: its
/// shear `φ_x = F g1 + g0` (Pa, `g1` per newton, `g0` the anchors') reaches the threshold
/// `τ` (Pa) at `F = (±τ - g0 sgn g1)/|g1|`. A site that carries no shear per newton
/// holds at every load (`(+∞, -∞)`) or at none (`(-∞, +∞)`).
#[inline]
fn anchored_window(tau: f64, g1: f64, g0: f64) -> (f64, f64) {
    if g1 == 0.0 {
        return match g0 != 0.0 && g0.abs() >= tau {
            true => (f64::NEG_INFINITY, f64::INFINITY),
            false => (f64::INFINITY, f64::NEG_INFINITY),
        };
    }
    let shift = g0 * g1.signum();
    ((tau - shift) / g1.abs(), (-tau - shift) / g1.abs())
}

/// The checks of [`ContactRule::breaking_loads`]' input.
fn check_threshold_inputs(
    interface: &Interface,
    normal_traction: &[f64],
    shear_per_newton: &[f64],
    friction_coefficient: f64,
) -> Result<()> {
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
    Ok(())
}

impl ContactRule {
    /// A rule of a downstream crate's `law` (see [`ContactLaw`] for its contract and
    /// what it gives up).
    pub fn custom(law: impl ContactLaw + 'static) -> Self {
        ContactRule::Custom(CustomRule::new(Arc::new(law)))
    }

    /// The rule's name: its scene-file value (`"paper"`, `"anchored"`,
    /// `"rejuvenation"`) or the custom law's [`ContactLaw::name`].
    pub fn name(&self) -> &str {
        match self {
            ContactRule::Paper => "paper",
            ContactRule::Anchored => "anchored",
            ContactRule::Rejuvenation { .. } => "rejuvenation",
            ContactRule::Custom(custom) => custom.law().name(),
        }
    }

    /// Refuses a custom rule where only a built-in one goes: `operation` records the
    /// scene by its scene-file keys (a checkpoint, a scene file, a run directory).
    ///
    /// # Errors
    /// [`Error::CustomContactRule`] under [`ContactRule::Custom`].
    pub(crate) fn built_in(&self, operation: &'static str) -> Result<()> {
        match self {
            ContactRule::Custom(custom) => Err(Error::CustomContactRule {
                rule: custom.law().name().to_string(),
                operation,
            }),
            _ => Ok(()),
        }
    }

    /// The shear load (N) at which each site reaches its threshold, from the normal
    /// tractions (Pa), the shear tractions per newton of load (Pa/N) and the friction
    /// coefficient (each site's from the interface's friction map where it has one);
    /// `+∞` for sites that carry no shear.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] or [`Error::NonFinite`] for slices of the wrong length or
    /// with a value that is not finite; [`Error::InvalidParameter`] for a friction
    /// coefficient that is negative or not finite.
    pub(crate) fn breaking_loads(
        &self,
        interface: &Interface,
        normal_traction: &[f64],
        shear_per_newton: &[f64],
        friction_coefficient: f64,
    ) -> Result<Vec<f64>> {
        check_threshold_inputs(
            interface,
            normal_traction,
            shear_per_newton,
            friction_coefficient,
        )?;
        // The anchored rules' window starts from the same checks; its loads are
        // [`ContactRule::thresholds`]'. A friction map is matched outside the loop.
        let loads = shear_per_newton.iter().zip(normal_traction);
        Ok(match interface.friction_map() {
            None => loads
                .map(|(g, f)| breaking_load(friction_coefficient * f, *g))
                .collect(),
            Some(mu) => loads
                .zip(mu)
                .map(|((g, f), mu)| breaking_load(mu * f, *g))
                .collect(),
        })
    }

    /// Whether the rule anchors springs where their sites attach (all but the paper's,
    /// and custom rules that do not).
    pub(crate) fn anchors(&self) -> bool {
        match self {
            ContactRule::Paper => false,
            ContactRule::Anchored | ContactRule::Rejuvenation { .. } => true,
            ContactRule::Custom(custom) => custom.anchors(),
        }
    }

    /// The loads (N) at which each site reaches its threshold, `(λ_high, λ_low)`: the
    /// site holds for `λ_low < F < λ_high`. Under the paper's rule
    /// [`ContactRule::breaking_loads`] and no `λ_low` (empty: a spring anchored at 0
    /// under `F >= 0` has none); under an anchored rule the window of each site from its
    /// shear per newton `g1` and its anchors' shear `g0` (Pa, `anchor_traction`; `None`
    /// when the rule does not anchor). The threshold is `μ φ_z`, or a custom law's
    /// `taus` (Pa, [`ContactState::custom_thresholds`]).
    ///
    /// # Errors
    /// As [`ContactRule::breaking_loads`]; `anchor_traction` of the wrong length or not
    /// finite (anchored rules).
    pub(crate) fn thresholds(
        &self,
        interface: &Interface,
        (normal_traction, shear_per_newton): (&[f64], &[f64]),
        anchor_traction: Option<&[f64]>,
        friction_coefficient: f64,
        taus: Option<&[f64]>,
    ) -> Result<(Vec<f64>, Vec<f64>)> {
        if matches!(self, ContactRule::Paper) {
            let high = self.breaking_loads(
                interface,
                normal_traction,
                shear_per_newton,
                friction_coefficient,
            )?;
            return Ok((high, Vec::new()));
        }
        check_threshold_inputs(
            interface,
            normal_traction,
            shear_per_newton,
            friction_coefficient,
        )?;
        let n = normal_traction.len();
        if let Some(taus) = taus {
            check_slice("thresholds", taus, n)?;
        }
        let map = interface.friction_map();
        let tau = |i: usize| match taus {
            Some(taus) => taus[i],
            None => map.map_or(friction_coefficient, |mu| mu[i]) * normal_traction[i],
        };
        let Some(anchor_traction) = anchor_traction else {
            // A custom rule that does not anchor: the paper's springs, its threshold.
            let high = (0..n)
                .map(|i| breaking_load(tau(i), shear_per_newton[i]))
                .collect();
            return Ok((high, Vec::new()));
        };
        check_slice("anchor_traction", anchor_traction, n)?;
        Ok((0..n)
            .map(|i| anchored_window(tau(i), shear_per_newton[i], anchor_traction[i]))
            .unzip())
    }

    /// The attached site with the smallest finite breaking load, and that load (N): the
    /// threshold a stable state's load is raised to. `None` when no attached site
    /// carries shear.
    /// Every rule raises the load (`F` grows with the control under both drives), so
    /// the next threshold is the smallest `λ_high`.
    pub(crate) fn weakest(&self, states: &[SiteState], breaking: &[f64]) -> Option<(usize, f64)> {
        let mut best: Option<(usize, f64)> = None;
        for (i, &b) in breaking.iter().enumerate() {
            if states[i] == SiteState::Attached && b.is_finite() && best.is_none_or(|(_, v)| b < v)
            {
                best = Some((i, b));
            }
        }
        best
    }

    /// The first attached site over its threshold under the shear force `force` (N):
    /// what a stable state may not hold. `low` is [`ContactRule::thresholds`]' `λ_low`.
    pub(crate) fn first_over_threshold(
        &self,
        states: &[SiteState],
        breaking: &[f64],
        low: &[f64],
        force: f64,
    ) -> Option<usize> {
        // The paper's springs (anchored at 0) under the paper's rule and a custom rule
        // that does not anchor; the window under the others.
        match self.anchors() {
            false => (0..breaking.len())
                .find(|&i| states[i] == SiteState::Attached && paper_over(breaking[i], force)),
            true => (0..breaking.len()).find(|&i| {
                states[i] == SiteState::Attached && anchored_over(breaking[i], low[i], force)
            }),
        }
    }

    /// The site that breaks next in an avalanche under the shear force `force` (N), and
    /// its elastic energy (J): among the attached sites over threshold (and `forced`, the
    /// site whose threshold the load was raised to, over it by construction though
    /// rounding may say otherwise), the one of largest energy `½ φ_x² ΔA / k_x`, with
    /// `φ_x = F g + g0` from the shear tractions per newton `traction` (Pa/N) and those of
    /// the anchors `anchor_traction` (Pa; empty under the paper's rule, and `low` with
    /// them) at the normal displacements `u_z` (m); `cell` is `ΔA` (m²). `None` when no
    /// site is over threshold: the avalanche has ended.
    ///
    /// # Errors
    /// [`Error::NonFinite`] when the chosen site's compliance overflows.
    #[allow(clippy::too_many_arguments)] // the state of one avalanche step, as the driver holds it
    pub(crate) fn next_rupture(
        &self,
        interface: &Interface,
        (breaking, low): (&[f64], &[f64]),
        force: f64,
        forced: Option<usize>,
        (traction, anchor_traction): (&[f64], &[f64]),
        u_z: &[f64],
        cell: f64,
    ) -> Result<Option<(usize, f64)>> {
        let best = match self.anchors() {
            false => largest_energy(
                interface,
                |i| paper_over(breaking[i], force) || forced == Some(i),
                |i| force * traction[i],
                u_z,
                cell,
            ),
            true => largest_energy(
                interface,
                |i| anchored_over(breaking[i], low[i], force) || forced == Some(i),
                |i| force * traction[i] + anchor_traction[i],
                u_z,
                cell,
            ),
        };
        Ok(match best {
            Some((i, phi)) => Some((i, interface.rupture_energy(i, u_z[i], phi, cell)?)),
            None => None,
        })
    }

    /// Whether the interface slides as a whole: every spring broke.
    pub(crate) fn global_slip(&self, interface: &Interface) -> bool {
        // Every rule: a re-forming site re-forms only at a stable state, never inside
        // the avalanche that breaks the last spring.
        interface.broken_count() == interface.states().len()
    }

    /// The attach and detach events of a new normal equilibrium, in site order: `emit`
    /// is called with each site that went from `before` to `after` into the contact
    /// (`true`, an attach) or out of it (`false`, a detach). A rupture is the protocol's
    /// own event, never a change of an equilibrium.
    pub(crate) fn changes(
        &self,
        before: &[SiteState],
        after: &[SiteState],
        mut emit: impl FnMut(usize, bool),
    ) {
        // Every rule: a re-formed site is detached before its equilibrium.
        for (i, (old, new)) in before.iter().zip(after).enumerate() {
            match (old, new) {
                (SiteState::Attached, SiteState::Detached) => emit(i, false),
                (SiteState::Detached, SiteState::Attached) => emit(i, true),
                _ => {}
            }
        }
    }

    /// The most ruptures the avalanche under way can have had in the site states
    /// `states`: each broke a site that is still broken (no site re-forms inside an
    /// avalanche).
    pub(crate) fn avalanche_ruptures_bound(&self, states: &[SiteState]) -> usize {
        // Every rule: sites re-form between avalanches only.
        states.iter().filter(|s| **s == SiteState::Broken).count()
    }

    /// The delay after which a broken site re-forms; `None` when it never does (or a
    /// custom law decides).
    pub(crate) fn delay(&self) -> Option<Delay> {
        match self {
            ContactRule::Paper | ContactRule::Anchored | ContactRule::Custom(_) => None,
            ContactRule::Rejuvenation { delay } => Some(*delay),
        }
    }
}

/// The choice of the next rupture ([`ContactRule::next_rupture`]): among the attached
/// sites `over` threshold the one of largest energy under its shear `phi` (Pa); its index
/// and shear. The order key is `ln` of the energy ([`Interface::log_rupture_energy`]),
/// which neither underflow nor overflow can tie; ties keep the first site.
fn largest_energy(
    interface: &Interface,
    over: impl Fn(usize) -> bool,
    phi: impl Fn(usize) -> f64,
    u_z: &[f64],
    cell: f64,
) -> Option<(usize, f64)> {
    let states = interface.states();
    let mut best: Option<(usize, f64, f64)> = None;
    for i in 0..states.len() {
        if states[i] != SiteState::Attached {
            continue;
        }
        if over(i) {
            let phi = phi(i);
            let key = interface.log_rupture_energy(i, u_z[i], phi, cell);
            if best.is_none_or(|(_, k, _)| key > k) {
                best = Some((i, key, phi));
            }
        }
    }
    best.map(|(i, _, phi)| (i, phi))
}

/// The site states a run's site events leave, replayed in order under a rule: the
/// resume's check of a checkpoint's states against its `events.csv`. Each change is
/// tagged (with its line in the table) so that a refusal names where it happened. The
/// stable states keep the quasi-static clock of a re-forming rule
/// ([`Replay::stable`]): a broken site may change again only by attaching when its
/// delay has passed, and is broken at the end unless its delay passed.
pub(crate) struct Replay {
    rule: ContactRule,
    /// `μ F_N` (N): the unit of a [`Delay`]'s load.
    load_scale: f64,
    /// Per site: the state its last change left and that change's tag.
    last: Vec<Option<(SiteState, usize)>>,
    /// Per site: when its last rupture happened (clock tick, force in N).
    broke: Vec<Option<BrokenSince>>,
    /// Stable states so far, and the forces (N) of the last two.
    stable: u64,
    forces: [f64; 2],
}

impl Replay {
    /// No change yet on `sites` sites; `load_scale` is `μ F_N` (N).
    pub(crate) fn new(rule: ContactRule, sites: usize, load_scale: f64) -> Self {
        Self {
            rule,
            load_scale,
            last: vec![None; sites],
            broke: vec![None; sites],
            stable: 0,
            forces: [0.0; 2],
        }
    }

    /// A stable state at the force `force` (N): the driver's next move ticks the clock
    /// (and re-forms the sites then due).
    pub(crate) fn stable(&mut self, force: f64) {
        self.stable += 1;
        self.forces = [self.forces[1], force];
    }

    /// Whether a site broken at `since` was due at the move after the `back`-th last
    /// stable state (0: the last). The table's forces are written to 13 digits: a due
    /// load may fall short of the delay's by their rounding.
    fn due(&self, since: BrokenSince, back: usize) -> bool {
        let Some(delay) = self.rule.delay() else {
            return false;
        };
        let clock = self.stable.saturating_sub(back as u64);
        let force = self.forces[1 - back];
        let slack = 1e-11 * (force.abs() + since.force.abs() + self.load_scale);
        clock > since.clock && delay.due(since, clock, force, self.load_scale, slack)
    }

    /// Applies `change` of site `index` (tagged `tag`) under the force `force` (N, the
    /// rupture's). `Err(tag of the rupture)` when the rule forbids it: any change of a
    /// broken site but its attachment once its delay has passed (a re-forming rule). A
    /// site beyond the grid is ignored (the row checks refuse it).
    pub(crate) fn apply(
        &mut self,
        index: usize,
        change: SiteChange,
        tag: usize,
        force: f64,
    ) -> Result<(), usize> {
        let Some(slot) = self.last.get(index).copied() else {
            return Ok(());
        };
        if let Some((SiteState::Broken, broke)) = slot {
            let reformed = change == SiteChange::Attach
                && self.broke[index].is_some_and(|since| self.due(since, 0));
            if !reformed {
                return Err(broke);
            }
        }
        if change == SiteChange::Rupture {
            self.broke[index] = Some(BrokenSince {
                clock: self.stable,
                force,
            });
        }
        self.last[index] = Some((change.to(), tag));
        Ok(())
    }

    /// The state the changes so far leave site `index` in when `state` is not one of
    /// them, with the tag of its last change (`None` without one); `None` when `state`
    /// fits. A site no change touched may be attached or detached (the normal
    /// equilibrium at zero shear chose), never broken: only a rupture breaks a site. A
    /// site a rupture left broken is detached, and only detached, once its delay passed
    /// (by the move after the last-but-one stable state: the replay ends at a stable
    /// state, before its move).
    pub(crate) fn mismatch(
        &self,
        index: usize,
        state: SiteState,
    ) -> Option<(SiteState, Option<usize>)> {
        let (mut expected, tag) = match self.last.get(index).copied().flatten() {
            Some((s, tag)) => (s, Some(tag)),
            None if state == SiteState::Broken => (SiteState::Attached, None),
            None => return None,
        };
        if expected == SiteState::Broken && self.broke[index].is_some_and(|b| self.due(b, 1)) {
            expected = SiteState::Detached;
        }
        (expected != state).then_some((expected, tag))
    }
}

impl Interface {
    /// The Coulomb rule: the shear load (N) at which each site reaches the threshold
    /// `|φ_x| = μ φ_z`, `λ_i = μ φ_z,i / |φ_x,i(1)|` (paper Eq. lambda_Amonton_dscrt), from
    /// the normal tractions (Pa) and the shear tractions per newton of load (Pa/N,
    /// [`crate::solver::TangentialResponse::traction`]). `+∞` for sites that carry no shear
    /// (detached, broken, or exactly unloaded). On an interface with a friction map
    /// ([`Interface::with_friction_map`]) each site's `μ_i` takes the place of
    /// `friction_coefficient`, which is still checked.
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

//! Unit tests of the paper's contact rule, against values worked out by hand here.

use super::*;
use crate::geometry::{Block, Grid};
use crate::interface::{Heights, SpringLaw};
use SiteState::{Attached, Broken, Detached};

/// Four 1 mm cells, heights 1 µm, every site attached.
fn interface() -> Interface {
    let grid = Grid::new(Block::new(0.004, 0.001, 0.005).unwrap(), 4, 1).unwrap();
    let heights = Heights::from_values(&grid, vec![1e-6; 4]).unwrap();
    Interface::new(grid, heights, SpringLaw::default()).unwrap()
}

/// The threshold: `μ f / |g|`, `+∞` at `g = ±0`, the same bits as the public
/// `Interface::breaking_loads`; bad input refused with typed errors.
#[test]
fn breaking_loads_are_the_coulomb_rule() {
    let interface = interface();
    let (f, g) = ([1e3, 2e3, 0.0, 5.0], [10.0, -4.0, 3.0, -0.0]);
    let loads = ContactRule::Paper
        .breaking_loads(&interface, &f, &g, 0.5)
        .unwrap();
    // 0.5·1e3/10 = 50, 0.5·2e3/4 = 250, 0/3 = 0, and no shear: +∞.
    assert_eq!(loads, vec![50.0, 250.0, 0.0, f64::INFINITY]);
    let public = interface.breaking_loads(&f, &g, 0.5).unwrap();
    assert!(loads
        .iter()
        .zip(&public)
        .all(|(a, b)| a.to_bits() == b.to_bits()));
    let rule = ContactRule::Paper;
    assert!(matches!(
        rule.breaking_loads(&interface, &f[..3], &g, 0.5),
        Err(Error::LengthMismatch {
            name: "normal_traction",
            ..
        })
    ));
    assert!(matches!(
        rule.breaking_loads(&interface, &f, &[f64::NAN; 4], 0.5),
        Err(Error::NonFinite {
            name: "shear_per_newton",
            ..
        })
    ));
    for mu in [-0.1, f64::INFINITY, f64::NAN] {
        assert!(matches!(
            rule.breaking_loads(&interface, &f, &g, mu),
            Err(Error::InvalidParameter {
                name: "friction_coefficient",
                ..
            })
        ));
    }
}

/// The next threshold is the smallest finite load of an attached site; a site over it
/// is one whose load is at or below the force; none when nothing is attached.
#[test]
fn weakest_and_over_threshold_look_at_attached_sites_only() {
    let rule = ContactRule::Paper;
    let states = [Attached, Detached, Attached, Broken];
    let breaking = [7.0, 1.0, 3.0, 2.0];
    assert_eq!(rule.weakest(&states, &breaking), Some((2, 3.0)));
    assert_eq!(rule.weakest(&states, &[f64::INFINITY; 4]), None);
    assert_eq!(
        rule.weakest(&[Detached, Broken, Detached, Broken], &breaking),
        None
    );
    // A tie keeps the first site.
    assert_eq!(rule.weakest(&states, &[3.0, 1.0, 3.0, 2.0]), Some((0, 3.0)));
    assert_eq!(
        rule.first_over_threshold(&states, &breaking, &[], 2.9),
        None
    );
    assert_eq!(
        rule.first_over_threshold(&states, &breaking, &[], 3.0),
        Some(2)
    );
    assert_eq!(
        rule.first_over_threshold(&states, &breaking, &[], 10.0),
        Some(0)
    );
}

/// The next rupture is the site over threshold (or forced) of largest energy
/// `½ φ² ΔA / k_x` with `k_x = c_x e^{-u_z/u0}`, worked out here; none once no site is
/// over threshold.
#[test]
fn the_site_of_largest_energy_breaks_first() {
    let mut interface = interface();
    let rule = ContactRule::Paper;
    let cell = 1e-6; // m²
    let u_z = [0.0, 0.0, 1e-6, 0.0];
    let traction = [1e6, 2e6, 1.5e6, 4e6]; // Pa/N
    let breaking = [0.5, 0.5, 0.5, 5.0]; // N
    let energy = |i: usize, force: f64| {
        let phi = force * traction[i];
        let k_x = SpringLaw::default().c_x() * (-u_z[i] / 1e-6_f64).exp();
        0.5 * phi * phi * cell / k_x
    };
    // At F = 1 N sites 0-2 are over; site 2's compliance is e times larger, so 1.5² e =
    // 6.1 beats 2² = 4: site 2. Site 3 carries the most but is under its threshold.
    let (i, e) = rule
        .next_rupture(
            &interface,
            (&breaking, &[]),
            1.0,
            None,
            (&traction, &[]),
            &u_z,
            cell,
        )
        .unwrap()
        .unwrap();
    assert_eq!(i, 2);
    assert!((e / energy(2, 1.0) - 1.0).abs() < 1e-12, "{e} J");
    // Forced in, site 3 (16 against 6.1) breaks first.
    let (i, _) = rule
        .next_rupture(
            &interface,
            (&breaking, &[]),
            1.0,
            Some(3),
            (&traction, &[]),
            &u_z,
            cell,
        )
        .unwrap()
        .unwrap();
    assert_eq!(i, 3);
    // Broken and detached sites never break; under every threshold, none does.
    interface
        .set_states(&[Attached, Detached, Attached, Attached])
        .unwrap();
    interface.break_site(2).unwrap();
    let next = rule.next_rupture(
        &interface,
        (&breaking, &[]),
        1.0,
        None,
        (&traction, &[]),
        &u_z,
        cell,
    );
    assert_eq!(next.unwrap().map(|(i, _)| i), Some(0));
    let next = rule.next_rupture(
        &interface,
        (&breaking, &[]),
        0.4,
        None,
        (&traction, &[]),
        &u_z,
        cell,
    );
    assert_eq!(next.unwrap(), None);
}

/// Global slip is every site broken; the attach and detach events of an equilibrium are
/// its changes into and out of the contact, in site order, and nothing else.
#[test]
fn global_slip_and_the_changes_of_an_equilibrium() {
    let mut interface = interface();
    let rule = ContactRule::Paper;
    for i in 0..4 {
        assert!(!rule.global_slip(&interface));
        interface.break_site(i).unwrap();
    }
    assert!(rule.global_slip(&interface));
    let before = [Attached, Detached, Attached, Broken, Detached];
    let after = [Detached, Attached, Attached, Broken, Detached];
    let mut seen = Vec::new();
    rule.changes(&before, &after, |i, attached| seen.push((i, attached)));
    assert_eq!(seen, vec![(0, false), (1, true)]);
    assert_eq!(rule.avalanche_ruptures_bound(&before), 1);
}

/// The replay of a run's site events: under the paper's rule any change of a broken
/// site is refused, naming the rupture's tag; the states the events leave are the only
/// ones that fit, and a site no event touched may be anything but broken.
#[test]
fn a_broken_site_never_changes_again() {
    let rule = ContactRule::Paper;
    for change in [SiteChange::Rupture, SiteChange::Detach, SiteChange::Attach] {
        let mut replay = Replay::new(rule.clone(), 3, 1.0);
        replay.apply(0, SiteChange::Detach, 10, 0.0).unwrap();
        replay.apply(0, SiteChange::Attach, 11, 0.0).unwrap();
        replay.apply(0, SiteChange::Rupture, 12, 0.0).unwrap();
        assert_eq!(replay.apply(0, change, 13, 0.0), Err(12));
    }
    let mut replay = Replay::new(rule, 3, 1.0);
    replay.apply(0, SiteChange::Rupture, 5, 0.0).unwrap();
    replay.apply(1, SiteChange::Detach, 6, 0.0).unwrap();
    replay.apply(7, SiteChange::Rupture, 8, 0.0).unwrap(); // beyond the grid: the row checks'
    assert_eq!(replay.mismatch(0, Broken), None);
    assert_eq!(replay.mismatch(0, Attached), Some((Broken, Some(5))));
    assert_eq!(replay.mismatch(1, Detached), None);
    assert_eq!(replay.mismatch(1, Attached), Some((Detached, Some(6))));
    assert_eq!(replay.mismatch(2, Attached), None);
    assert_eq!(replay.mismatch(2, Detached), None);
    assert_eq!(replay.mismatch(2, Broken), Some((Attached, None)));
}

/// An anchored site holds inside its window `λ_low < F < λ_high`, the roots of
/// `|F g1 + g0| = μ f` worked out here; with no anchor shear its `λ_high` is the paper's
/// load bit for bit; a site without shear per newton holds always or never.
#[test]
fn an_anchored_site_holds_inside_its_window() {
    let interface = interface();
    let rule = ContactRule::Anchored;
    let f = [1e3, 1e3, 1e3, 1e3];
    let g1 = [10.0, -4.0, 0.0, 0.0];
    let g0 = [100.0, 100.0, 600.0, 100.0];
    let (high, low) = rule
        .thresholds(&interface, (&f, &g1), Some(&g0[..]), 0.5, None)
        .unwrap();
    // τ = 500 Pa. Site 0: 10 F + 100 = ±500 at F = 40, -60. Site 1: -4 F + 100 = -500 at
    // F = 150, = 500 at F = -100. Site 2: |600| ≥ 500 at any load; site 3: never.
    assert_eq!(high, vec![40.0, 150.0, f64::NEG_INFINITY, f64::INFINITY]);
    assert_eq!(low, vec![-60.0, -100.0, f64::INFINITY, f64::NEG_INFINITY]);
    let states = [Attached; 4];
    assert_eq!(
        rule.first_over_threshold(&states, &high, &low, 30.0),
        Some(2)
    );
    let states = [Attached, Attached, Detached, Attached];
    assert_eq!(rule.first_over_threshold(&states, &high, &low, 30.0), None);
    assert_eq!(
        rule.first_over_threshold(&states, &high, &low, -60.0),
        Some(0)
    );
    assert_eq!(
        rule.first_over_threshold(&states, &high, &low, 40.0),
        Some(0)
    );
    assert_eq!(rule.weakest(&states, &high), Some((0, 40.0)));
    // No anchor shear: the paper's loads, bit for bit.
    let (high, _) = rule
        .thresholds(&interface, (&f, &g1), Some(&[0.0; 4][..]), 0.5, None)
        .unwrap();
    let paper = ContactRule::Paper
        .breaking_loads(&interface, &f, &g1, 0.5)
        .unwrap();
    assert!(high
        .iter()
        .zip(&paper)
        .all(|(a, b)| a.to_bits() == b.to_bits()));
    assert!(matches!(
        rule.thresholds(&interface, (&f, &g1), Some(&g0[..2]), 0.5, None),
        Err(Error::LengthMismatch {
            name: "anchor_traction",
            ..
        })
    ));
}

/// Under an anchored rule the energy is that of the shear `F g1 + g0`: the anchors' shear
/// can make a site of smaller `g1` the one that breaks.
#[test]
fn an_anchored_rupture_counts_the_anchors_shear() {
    let interface = interface();
    let cell = 1e-6;
    let u_z = [0.0; 4];
    let traction = [1e6, 2e6, 0.0, 0.0];
    let anchor = [3e6, 0.0, 0.0, 0.0];
    let over = [0.5, 0.5, f64::INFINITY, f64::INFINITY];
    let low = [f64::NEG_INFINITY; 4];
    let next = |rule: ContactRule, anchor: &[f64]| {
        rule.next_rupture(
            &interface,
            (&over, &low),
            1.0,
            None,
            (&traction, anchor),
            &u_z,
            cell,
        )
        .unwrap()
        .unwrap()
    };
    // Paper: site 1 (2e6 against 1e6). Anchored: site 0 carries 4e6.
    assert_eq!(next(ContactRule::Paper, &[]).0, 1);
    let (i, e) = next(ContactRule::Anchored, &anchor);
    assert_eq!(i, 0);
    let expected = 0.5 * 4e6 * 4e6 * cell / SpringLaw::default().c_x();
    assert!((e / expected - 1.0).abs() < 1e-12);
}

/// The re-forming rule's replay: a broken site attaches again only once both delays
/// have passed (stable states counted from its rupture's, load in `μ F_N`), never
/// detaches or breaks while broken, and at the end is detached exactly when it was due
/// at the last move.
#[test]
fn a_re_forming_site_waits_for_its_delay() {
    let rule = ContactRule::Rejuvenation {
        delay: Delay {
            stable_states: 2,
            load: 0.1,
        },
    };
    // μ F_N = 10 N: the load delay is 1 N.
    let mut replay = Replay::new(rule, 2, 10.0);
    replay.stable(0.0);
    replay.apply(0, SiteChange::Rupture, 3, 5.0).unwrap(); // at tick 1
    replay.stable(5.0);
    assert_eq!(replay.apply(0, SiteChange::Attach, 5, 0.0), Err(3)); // 1 tick
    replay.stable(5.5);
    assert_eq!(replay.apply(0, SiteChange::Attach, 7, 0.0), Err(3)); // 0.5 N
    assert_eq!(replay.mismatch(0, Broken), None);
    replay.stable(6.0);
    assert_eq!(replay.apply(0, SiteChange::Detach, 9, 0.0), Err(3));
    assert_eq!(replay.apply(0, SiteChange::Rupture, 9, 6.0), Err(3));
    // Not yet due at the move after the stable state at 5.5 N; due at the one at 6 N.
    assert_eq!(replay.mismatch(0, Detached), Some((Broken, Some(3))));
    replay.stable(6.0);
    assert_eq!(replay.mismatch(0, Detached), None);
    assert_eq!(replay.mismatch(0, Broken), Some((Detached, Some(3))));
    replay.apply(0, SiteChange::Attach, 11, 0.0).unwrap();
    assert_eq!(replay.mismatch(0, Attached), None);
    // The paper's rule: never.
    let mut paper = Replay::new(ContactRule::Paper, 1, 10.0);
    paper.apply(0, SiteChange::Rupture, 1, 5.0).unwrap();
    for k in 0..10 {
        paper.stable(100.0 * k as f64);
    }
    assert_eq!(paper.apply(0, SiteChange::Attach, 2, 0.0), Err(1));
}

/// The re-forming rule's clock: a site re-forms at the first tick where both delays have
/// passed, and a state that does not fit its sites is refused with the reason.
#[test]
fn the_clock_re_forms_sites_when_due() {
    let delay = Delay {
        stable_states: 2,
        load: 0.1,
    };
    let rule = ContactRule::Rejuvenation { delay };
    let mut state = ContactState::new(&rule, 2).unwrap();
    assert!(ContactState::new(&ContactRule::Paper, 2).is_none());
    let (states, zero) = ([Attached; 2], [0.0; 2]);
    let at = |force: f64| Fields {
        states: &states,
        normal_traction: &zero,
        normal_displacement: &zero,
        friction_coefficient: 0.5,
        friction_map: None,
        force,
    };
    assert!(state.tick(&rule, &at(0.0), 10.0).is_empty()); // tick 1
    state.broke(1, 5.0);
    assert!(state.tick(&rule, &at(9.0), 10.0).is_empty()); // 1 tick
    assert!(state.tick(&rule, &at(5.5), 10.0).is_empty()); // 0.5 N
    assert_eq!(state.tick(&rule, &at(6.0), 10.0), vec![1]);
    assert_eq!(state.broken_since, vec![None, None]);
    assert!(state.check(&rule, &[Attached, Detached]).is_ok());
    state.broke(0, 6.0);
    assert!(state.check(&rule, &[Attached, Detached]).is_err()); // 0 is not broken
    assert!(state.check(&rule, &[Broken, Detached]).is_ok());
    state.anchors[1] = 1e-9;
    assert!(state.check(&rule, &[Broken, Detached]).is_err()); // an anchor off contact
    assert!(state
        .check(&ContactRule::Anchored, &[Broken, Attached])
        .is_err());
}

/// A law that gives `scale` times the paper's threshold (`NaN` at `bad`, if any), and
/// re-forms a broken site two ticks after its rupture.
#[derive(Debug)]
struct Scaled {
    scale: f64,
    bad: Option<usize>,
}

impl ContactLaw for Scaled {
    fn name(&self) -> &str {
        "scaled"
    }
    fn threshold(&self, site: &SiteView) -> f64 {
        match self.bad == Some(site.index) {
            true => f64::NAN,
            false => self.scale * site.friction_coefficient * site.normal_traction,
        }
    }
    fn reforms(&self, site: &SiteView) -> bool {
        site.rupture_stable_states
            .is_some_and(|at| site.stable_states >= at + 2)
    }
}

/// A custom law's thresholds: asked for the attached sites only (0 elsewhere), its
/// breaking loads `τ / |g|`; the paper's threshold gives the paper's loads bit for bit,
/// twice the threshold twice the loads; a threshold that is not finite fails with the
/// site; the law re-forms a site when it says so, and the view counts its ruptures.
#[test]
fn a_custom_law_sets_the_threshold_and_the_re_formations() {
    let interface = interface();
    let states = [Attached, Attached, Detached, Attached];
    let (f, g) = ([1e3, 2e3, 0.0, 5.0], [10.0, -4.0, 0.0, -0.0]);
    let u_z = [0.0; 4];
    let fields = |force: f64| Fields {
        states: &states,
        normal_traction: &f,
        normal_displacement: &u_z,
        friction_coefficient: 0.5,
        friction_map: None,
        force,
    };
    let paper = ContactRule::Paper
        .breaking_loads(&interface, &f, &g, 0.5)
        .unwrap();
    for (scale, expected) in [(1.0, [50.0, 250.0]), (2.0, [100.0, 500.0])] {
        let rule = ContactRule::custom(Scaled { scale, bad: None });
        assert!(!rule.anchors());
        assert_eq!(rule.name(), "scaled");
        let state = ContactState::new(&rule, 4).unwrap();
        let taus = state
            .custom_thresholds(&rule, &fields(0.0))
            .unwrap()
            .unwrap();
        assert_eq!(taus, vec![500.0 * scale, 1000.0 * scale, 0.0, 2.5 * scale]);
        let (high, low) = rule
            .thresholds(&interface, (&f, &g), None, 0.5, Some(taus.as_slice()))
            .unwrap();
        assert!(low.is_empty());
        assert_eq!(&high[..2], &expected);
        assert_eq!(high[3], f64::INFINITY);
        if scale == 1.0 {
            assert!(high
                .iter()
                .zip(&paper)
                .all(|(a, b)| a.to_bits() == b.to_bits()));
        }
    }
    let rule = ContactRule::custom(Scaled {
        scale: 1.0,
        bad: Some(1),
    });
    let state = ContactState::new(&rule, 4).unwrap();
    assert!(matches!(
        state.custom_thresholds(&rule, &fields(0.0)),
        Err(Error::InvalidThreshold { site: 1, ref rule, .. }) if rule == "scaled"
    ));
    // Built-in rules have no custom thresholds.
    let anchored = ContactState::new(&ContactRule::Anchored, 4).unwrap();
    assert_eq!(
        anchored
            .custom_thresholds(&ContactRule::Anchored, &fields(0.0))
            .unwrap(),
        None
    );
    // Re-formation: site 3 breaks at tick 1 and re-forms at tick 3.
    let rule = ContactRule::custom(Scaled {
        scale: 1.0,
        bad: None,
    });
    let mut state = ContactState::new(&rule, 4).unwrap();
    assert!(state.tick(&rule, &fields(1.0), 1.0).is_empty());
    state.broke(3, 1.0);
    assert_eq!(state.view(3, &fields(1.0)).ruptures, 1);
    assert_eq!(state.view(3, &fields(1.0)).rupture_force, Some(1.0));
    assert!(state.tick(&rule, &fields(2.0), 1.0).is_empty());
    assert_eq!(state.tick(&rule, &fields(3.0), 1.0), vec![3]);
    assert_eq!(state.view(3, &fields(3.0)).rupture_stable_states, None);
    assert_eq!(state.view(3, &fields(3.0)).ruptures, 1);
    // What a custom rule gives up is a typed error naming it and the operation.
    assert!(matches!(
        rule.built_in("writing a checkpoint"),
        Err(Error::CustomContactRule {
            operation: "writing a checkpoint",
            ..
        })
    ));
    assert!(ContactRule::Anchored
        .built_in("writing a checkpoint")
        .is_ok());
}

/// `Delay::new` refuses what the scene file refuses, naming the key.
#[test]
fn a_delay_is_checked() {
    assert_eq!(Delay::new(1, 0.01).unwrap(), Delay::default());
    assert!(matches!(
        Delay::new(0, 0.01),
        Err(Error::InvalidCount {
            name: "contact.delay.stable_states",
            ..
        })
    ));
    for load in [-0.1, 0.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            Delay::new(1, load),
            Err(Error::InvalidParameter {
                name: "contact.delay.load",
                ..
            })
        ));
    }
}

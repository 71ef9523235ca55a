//! A small program against the public API of `precursors` with its default features: a
//! scene from the builder, events to global slip, the observables between them, a stress
//! probe, a checkpoint and an error matched by variant; a contact rule of its own (a
//! slip-weakening threshold), run against the paper's. It fails (exit 1) when a promise it
//! relies on breaks; it fails to compile when the API changes incompatibly.

use precursors::{ContactLaw, ContactRule, Error, Event, ProbeSpec, Scene, SiteState, SiteView};

/// Slip weakening, written here as a user would: a site holds the static threshold
/// `μ_s φ_z` (Pa) until its spring first breaks; it re-forms (anchored, no shear at its
/// attachment) two stable states and a load increase `load` later, and then holds only
/// `μ_d φ_z`, `μ_d < μ_s`. The threshold depends on the site's state and history only,
/// never on the load, so it is fixed between events (the trait's contract); the load
/// delay bounds the run (re-formed sites cannot break again at one load for ever).
#[derive(Debug)]
struct SlipWeakening {
    /// `μ_d` (dimensionless).
    dynamic: f64,
    /// The load increase (N) a broken site waits for.
    load: f64,
}

impl ContactLaw for SlipWeakening {
    fn name(&self) -> &str {
        "slip-weakening"
    }
    fn threshold(&self, site: &SiteView) -> f64 {
        let mu = match site.ruptures {
            0 => site.friction_coefficient,
            _ => self.dynamic,
        };
        mu * site.normal_traction
    }
    fn anchors(&self) -> bool {
        true
    }
    fn reforms(&self, site: &SiteView) -> bool {
        match (site.rupture_stable_states, site.rupture_force) {
            (Some(at), Some(force)) => {
                site.stable_states >= at + 2 && site.force - force >= self.load
            }
            _ => false,
        }
    }
}

/// The events of `scene`'s run (at most 20 000), each checked for force balance
/// (`ΔA Σ φ_x = -F`, `ΔA Σ φ_z = F_N`) and, at a stable state, for every attached site
/// within `μ_s φ_z`; with the number of sites that broke more than once.
fn checked_run(scene: &Scene) -> Result<(Vec<Event>, usize), Error> {
    let mut driver = scene.driver()?;
    let cell = scene.grid().cell_area();
    let mu = scene.material().friction_coefficient();
    let mut events = Vec::new();
    let mut ruptures = vec![0usize; scene.grid().len()];
    while let Some(event) = driver.step()? {
        if let Event::Rupture { site, .. } = event {
            ruptures[site.index] += 1;
        }
        if !matches!(event, Event::GlobalSlip { .. }) {
            let phi_x = driver.shear_traction()?;
            let phi_z = driver.normal_traction()?;
            let force = driver.force();
            let carried: f64 = cell * phi_x.iter().sum::<f64>();
            let scale = cell * phi_x.iter().map(|p| p.abs()).sum::<f64>() + force.abs();
            assert!(
                (carried + force).abs() <= 1e-9 * scale + 1e-12,
                "{event:?}: the interface carries {carried:e} N against F = {force:e} N"
            );
            let normal: f64 = cell * phi_z.iter().sum::<f64>();
            let f_n = scene.normal_load();
            assert!(
                (normal - f_n).abs() <= 1e-9 * f_n,
                "{normal} N against {f_n} N"
            );
            if let Event::Stable { .. } = event {
                for (i, state) in driver.site_states().iter().enumerate() {
                    if *state == SiteState::Attached {
                        assert!(phi_x[i].abs() <= mu * phi_z[i] * (1.0 + 1e-9), "site {i}");
                    }
                }
            }
        }
        events.push(event);
        assert!(events.len() < 20_000, "no global slip after 20 000 events");
    }
    Ok((events, ruptures.iter().filter(|&&r| r > 1).count()))
}

fn main() -> Result<(), Error> {
    let scene = Scene::builder()
        .block(0.020, 0.005, 0.075)
        .cell_size(1e-3, 1e-3)
        .normal_load(500.0)
        .seed(3)
        .probes(ProbeSpec::default().with_plane(1e-3))
        .build()?;
    let mut driver = scene.driver()?;
    let (mut ruptures, mut stable) = (0usize, 0usize);
    let mut slip = None;
    while let Some(event) = driver.step()? {
        match event {
            Event::Rupture { .. } => ruptures += 1,
            Event::Stable { .. } => {
                stable += 1;
                let area = driver.real_contact_area()?;
                let ell = driver.precursor_length()?;
                let planes = &driver.stresses()?.planes;
                assert!(area > 0.0 && ell >= 0.0 && planes.len() == 1);
            }
            Event::GlobalSlip { load } => slip = Some(load.force),
            _ => {}
        }
    }
    let slip = slip.expect("a drive to global slip ends with Event::GlobalSlip");
    // The same scene from its checkpoint gives the same next state.
    let _checkpoint = driver.checkpoint();
    // A block of negative length is refused with a typed error, matched by variant.
    match Scene::builder().block(-1.0, 0.005, 0.075).build() {
        Err(Error::InvalidLength { .. }) => {}
        Err(other) => panic!("unexpected error: {other}"),
        Ok(_) => panic!("a negative length was accepted"),
    }
    println!("{stable} stable states, {ruptures} ruptures, global slip at F = {slip:.3} N");

    // A rule of this crate's own against the paper's, on a small scene.
    let builder = Scene::builder()
        .block(0.016, 0.004, 0.010)
        .cells(16, 4)
        .normal_load(60.0)
        .seed(1);
    let paper = builder.clone().build()?;
    let mu = paper.material().friction_coefficient();
    let weakening = builder
        .contact_rule(ContactRule::custom(SlipWeakening {
            dynamic: 0.5 * mu,
            load: 0.02 * mu * paper.normal_load(),
        }))
        .build()?;
    assert_eq!(weakening.contact_rule().name(), "slip-weakening");
    let (paper_events, paper_twice) = checked_run(&paper)?;
    let (events, twice) = checked_run(&weakening)?;
    // The paper's sites break once; here sites re-form, weaker, and break again.
    assert_eq!(paper_twice, 0, "a paper site broke twice");
    assert!(twice > 0, "no site re-formed and broke again");
    assert_ne!(
        paper_events, events,
        "the custom rule ran the paper's events"
    );
    // Both start from the same stable state at zero shear.
    assert_eq!(paper_events[0], events[0]);
    // What the rule gives up: a checkpoint cannot be resumed (typed error, no panic).
    let mut driver = weakening.driver()?;
    driver.step()?;
    match weakening.resume(&driver.checkpoint()) {
        Err(Error::CustomContactRule { rule, .. }) => assert_eq!(rule, "slip-weakening"),
        Err(other) => panic!("unexpected error: {other}"),
        Ok(_) => panic!("a custom rule's checkpoint was resumed"),
    }
    println!(
        "slip weakening: {} events ({twice} sites broke again), the paper's {}",
        events.len(),
        paper_events.len()
    );
    Ok(())
}

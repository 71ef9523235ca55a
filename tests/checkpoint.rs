//! Checkpoint and resume: a resumed run returns exactly (bit for bit) the events and the
//! states of the uninterrupted run, on both backends, wherever the checkpoint falls
//! (at a stable state, inside an avalanche, with events still queued). The reference is
//! the uninterrupted run itself.

use precursors::solver::{Backend, Parallelism, SolverOptions};
use precursors::*;

/// Every remaining event of `driver`, and its normal tractions at the end.
fn finish(mut driver: Driver) -> (Vec<Event>, Vec<f64>) {
    let events = driver.by_ref().collect::<Result<Vec<_>>>().unwrap();
    (events, driver.normal_traction().unwrap().to_vec())
}

/// Checkpoints taken after events `at` of an uninterrupted run, each resumed and run to
/// the end, must return the uninterrupted run's events.
fn check_resume(scene: &Scene, at: &[usize], through: impl Fn(Checkpoint) -> Checkpoint) {
    let mut driver = scene.driver().unwrap();
    let mut checkpoints = Vec::new();
    let mut events = Vec::new();
    while let Some(event) = driver.step().unwrap() {
        events.push(event);
        if at.contains(&events.len()) {
            checkpoints.push((events.len(), driver.checkpoint()));
        }
    }
    let end = driver.normal_traction().unwrap().to_vec();
    assert!(matches!(events.last(), Some(Event::GlobalSlip { .. })));
    assert_eq!(
        checkpoints.len(),
        at.len(),
        "the run has {} events",
        events.len()
    );
    for (k, checkpoint) in checkpoints {
        assert_eq!(checkpoint.event_count(), k);
        let resumed = scene.resume(&through(checkpoint)).unwrap();
        assert_eq!(resumed.event_count(), k);
        let (rest, traction) = finish(resumed);
        assert_eq!(rest.len(), events.len() - k, "checkpoint after event {k}");
        assert!(
            rest == events[k..],
            "checkpoint after event {k}: events differ"
        );
        assert!(
            traction == end,
            "checkpoint after event {k}: final tractions differ"
        );
    }
}

/// The index (1-based count) of a rupture whose re-equilibration queued attachments:
/// a checkpoint there holds pending events.
fn rupture_with_queue(scene: &Scene) -> usize {
    let events = scene.driver().unwrap().collect::<Result<Vec<_>>>().unwrap();
    events
        .windows(2)
        .position(|w| {
            matches!(w[0], Event::Rupture { .. })
                && matches!(w[1], Event::Attach { .. } | Event::Detach { .. })
        })
        .map(|i| i + 1)
        .expect("a rupture followed by a state change")
}

#[test]
fn resumed_runs_repeat_the_uninterrupted_one_dense() {
    // The calibration scene (dense backend, factor updates and refactorisations).
    let scene = Scene::builder().seed(1).build().unwrap();
    let queued = rupture_with_queue(&scene);
    check_resume(&scene, &[1, 2, queued, 1200], |c| c);
}

#[test]
fn resumed_runs_repeat_the_uninterrupted_one_spectral() {
    let scene = Scene::builder()
        .block(0.060, 0.010, 0.030)
        .normal_load(1.5e3)
        .solver_options(
            SolverOptions::default()
                .with_backend(Backend::Spectral)
                .unwrap(),
        )
        .seed(4)
        .build()
        .unwrap();
    let queued = rupture_with_queue(&scene);
    check_resume(&scene, &[1, queued, 300], |c| c);
}

/// Any thread count repeats the one-thread run bit for bit (events, tractions), and a
/// checkpoint taken at one count resumes at another (the reference: the one-thread run).
/// The 128 x 64 grid is cut into 8 parts, so 2, 3, 4 and 8 threads share them unevenly
/// (8 threads oversubscribe the CI's 2 cores: helpers that are late find no work).
#[test]
fn any_thread_count_repeats_the_sequential_run_and_resumes_it() {
    let builder = |parallelism| {
        Scene::builder()
            .block(0.128, 0.064, 0.030)
            .normal_load(3.5e6 * 0.128 * 0.064)
            .solver_options(
                SolverOptions::default()
                    .with_backend(Backend::Spectral)
                    .unwrap()
                    .with_parallelism(parallelism)
                    .unwrap(),
            )
            .seed(5)
    };
    // The first `count` events and the tractions after them.
    let first = |mut driver: Driver, count: usize| {
        let events: Vec<Event> = (0..count)
            .map(|_| driver.step().unwrap().unwrap())
            .collect();
        (events, driver.normal_traction().unwrap().to_vec())
    };
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let count = 150;
    let one = builder(Parallelism::Sequential).build().unwrap();
    let (events, traction) = first(one.driver().unwrap(), count);
    assert!(
        events
            .iter()
            .filter(|e| matches!(e, Event::Rupture { .. }))
            .count()
            > 20,
        "too few ruptures to compare"
    );
    for par in [
        Parallelism::Threads(2),
        Parallelism::Threads(3),
        Parallelism::Threads(4),
        Parallelism::Threads(8),
        Parallelism::CurrentPool,
    ] {
        let scene = builder(par).build().unwrap();
        let (got, t) = first(scene.driver().unwrap(), count);
        assert!(got == events, "{par:?}: events differ");
        assert_eq!(bits(&t), bits(&traction), "{par:?}: tractions differ");
    }
    // The thread count of the run options, on the sequential scene (and a scene of 3
    // threads set back to 1 by them).
    for (scene, n) in [
        (&one, 3),
        (&one, 4),
        (&builder(Parallelism::Threads(3)).build().unwrap(), 1),
    ] {
        let driver = scene.driver_with(&RunOptions::new().threads(n)).unwrap();
        assert_eq!(driver.threads(), n);
        let (got, t) = first(driver, count);
        assert!(got == events, "RunOptions::threads({n}): events differ");
        assert_eq!(
            bits(&t),
            bits(&traction),
            "RunOptions::threads({n}): tractions differ"
        );
    }
    // One driver switching counts between events.
    let mut driver = one.driver().unwrap();
    let mut switched = Vec::new();
    for k in 0..count {
        let par = [
            Parallelism::Threads(4),
            Parallelism::Sequential,
            Parallelism::Threads(3),
        ][k % 3];
        driver.set_parallelism(par).unwrap();
        switched.push(driver.step().unwrap().unwrap());
    }
    assert!(switched == events, "switching counts: events differ");
    assert!(driver.set_parallelism(Parallelism::Threads(0)).is_err());
    // Checkpoints: taken on 3 threads, resumed on 1 and on 8; taken on 1, resumed on 2.
    for (from, to) in [
        (Parallelism::Threads(3), Parallelism::Sequential),
        (Parallelism::Threads(3), Parallelism::Threads(8)),
        (Parallelism::Sequential, Parallelism::Threads(2)),
    ] {
        let mut driver = builder(from).build().unwrap().driver().unwrap();
        for _ in 0..count / 2 {
            driver.step().unwrap();
        }
        let resumed = builder(to)
            .build()
            .unwrap()
            .resume(&driver.checkpoint())
            .unwrap();
        let (rest, t) = first(resumed, count - count / 2);
        assert!(
            rest == events[count / 2..],
            "{from:?} -> {to:?}: events differ"
        );
        assert_eq!(
            bits(&t),
            bits(&traction),
            "{from:?} -> {to:?}: tractions differ"
        );
    }
}

#[test]
fn resume_under_displacement_control() {
    let scene = Scene::builder()
        .block(0.040, 0.004, 0.020)
        .normal_load(400.0)
        .drive(Drive::Spring {
            stiffness: 4e6,
            lateral: Lateral::Side,
        })
        .seed(7)
        .build()
        .unwrap();
    check_resume(&scene, &[3, 50], |c| c);
}

#[test]
fn a_checkpoint_is_refused_on_another_scene() {
    let scene = Scene::builder()
        .block(0.020, 0.004, 0.020)
        .normal_load(200.0)
        .seed(1)
        .build()
        .unwrap();
    let mut driver = scene.driver().unwrap();
    driver.step().unwrap();
    let checkpoint = driver.checkpoint();
    // Each refusal names the first differing option by its scene-file key.
    let key_of = |other: SceneBuilder| match other.build().unwrap().resume(&checkpoint) {
        Err(Error::CheckpointSceneMismatch { key, reason }) => {
            eprintln!("{key}: {reason}");
            key
        }
        other => panic!("not refused with a key: {other:?}"),
    };
    let b = scene.to_builder();
    assert_eq!(key_of(b.clone().seed(2)), "heights.seed");
    assert_eq!(key_of(b.clone().normal_load(201.0)), "normal_load");
    assert_eq!(key_of(b.clone().block(0.024, 0.004, 0.020)), "block.lx");
    assert_eq!(
        key_of(b.clone().area_law(AreaLaw::Capped)),
        "springs.area_law"
    );
    assert_eq!(
        key_of(b.clone().drive(Drive::Force(Lateral::Side.into()))),
        "drive.kind"
    );
    assert_eq!(
        key_of(
            b.clone().drive(Drive::Force(
                Lateral::Rod {
                    height: 7e-3,
                    half_width: 2e-3
                }
                .into()
            ))
        ),
        "drive.height"
    );
    let message = b
        .clone()
        .normal_load(201.0)
        .build()
        .unwrap()
        .resume(&checkpoint)
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("normal_load") && message.contains("200.0") && message.contains("201.0"),
        "{message}"
    );
    // The thread count is not part of the run's identity.
    let threads = b.solver_options(
        SolverOptions::default()
            .with_parallelism(Parallelism::Threads(2))
            .unwrap(),
    );
    assert!(threads.build().unwrap().resume(&checkpoint).is_ok());
    // The checkpoint names its scene: building that resumes.
    let rebuilt = checkpoint.scene().clone().build().unwrap();
    assert!(rebuilt.resume(&checkpoint).is_ok());
}

#[cfg(feature = "serde")]
pub(crate) mod json {
    use super::*;
    use crate::common::scratch;

    /// FNV-1a, 64 bits (offset basis 0xcbf29ce484222325, prime 0x100000001b3: the
    /// published constants), written here from its definition.
    fn fnv1a_64(bytes: &[u8]) -> u64 {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for &b in bytes {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        h
    }

    /// `text` (a checkpoint's JSON, possibly edited) with its digest recomputed, as a
    /// deliberate editor would: the digest covers the text before `,"digest":"..."`,
    /// closed with `}`.
    pub(crate) fn resigned(text: &str) -> String {
        let at = text.rfind(",\"digest\":\"").expect("a digest");
        let body = format!("{}}}", &text[..at]);
        format!(
            "{},\"digest\":\"{:016x}\"}}",
            &text[..at],
            fnv1a_64(body.as_bytes())
        )
    }

    fn round_trip(c: Checkpoint) -> Checkpoint {
        let text = c.to_json().unwrap();
        let back = Checkpoint::from_json_str(&text).unwrap();
        assert!(back == c, "the checkpoint changed through JSON");
        back
    }

    #[test]
    fn resume_through_json_is_exact() {
        let scene = Scene::builder().seed(1).build().unwrap();
        let queued = rupture_with_queue(&scene);
        check_resume(&scene, &[queued, 1800], round_trip);
        let spectral = Scene::builder()
            .block(0.040, 0.010, 0.030)
            .normal_load(1.0e3)
            .solver_options(
                SolverOptions::default()
                    .with_backend(Backend::Spectral)
                    .unwrap(),
            )
            .seed(5)
            .build()
            .unwrap();
        check_resume(&spectral, &[100], round_trip);
    }

    /// A checkpoint of the CUDA backend resumes on the spectral one and the reverse (issue
    /// 42): the scene identity counts "cuda" as "spectral" and both keep one solver state.
    /// The CUDA run's checkpoint is the spectral one's with its solver state's backend set
    /// to `Cuda` (what a GPU run writes; no GPU here): resumed on the spectral backend it
    /// ends exactly as the uninterrupted run. A spectral checkpoint resumed on a "cuda"
    /// scene passes the checkpoint's checks and stops only at the device where there is
    /// none (`CudaUnavailable`, not a scene mismatch).
    #[test]
    fn a_checkpoint_resumes_across_the_spectral_and_cuda_backends() {
        let scene = |backend| {
            Scene::builder()
                .block(0.040, 0.010, 0.030)
                .normal_load(1.0e3)
                .solver_options(SolverOptions::default().with_backend(backend).unwrap())
                .seed(5)
                .build()
                .unwrap()
        };
        let spectral = scene(Backend::Spectral);
        let as_cuda = |c: Checkpoint| {
            let text = c.to_json().unwrap();
            let from = "\"backend\":\"Spectral\"";
            // The solver state's and the two equilibria's reports.
            assert_eq!(text.matches(from).count(), 3, "{text}");
            assert!(text.contains("\"solver\":{\"backend\":\"Spectral\""));
            Checkpoint::from_json_str(&resigned(&text.replace(from, "\"backend\":\"Cuda\"")))
                .unwrap()
        };
        check_resume(&spectral, &[100], as_cuda);
        let mut driver = spectral.driver().unwrap();
        for _ in 0..50 {
            driver.step().unwrap();
        }
        match scene(Backend::Cuda).resume(&driver.checkpoint()) {
            Ok(_) => {} // a machine with a GPU
            Err(Error::CudaUnavailable { .. }) => {}
            Err(e) => panic!("a spectral checkpoint on a cuda scene: {e}"),
        }
    }

    #[test]
    fn a_checkpoint_whose_scene_was_edited_is_refused_naming_the_key() {
        let scene = Scene::builder()
            .block(0.020, 0.004, 0.020)
            .normal_load(200.0)
            .seed(1)
            .build()
            .unwrap();
        let mut driver = scene.driver().unwrap();
        for _ in 0..5 {
            driver.step().unwrap();
        }
        let text = driver.checkpoint().to_json().unwrap();
        for (from, to, key) in [
            (
                "\"normal_load\":200.0",
                "\"normal_load\":210.0",
                "normal_load",
            ),
            (
                "\"friction_coefficient\":0.5",
                "\"friction_coefficient\":0.6",
                "material.friction_coefficient",
            ),
            ("\"seed\":1", "\"seed\":3", "heights.seed"),
            (
                "\"area_law\":\"paper\"",
                "\"area_law\":\"capped\"",
                "springs.area_law",
            ),
        ] {
            // The first occurrence is in the scene (the solver reports repeat F_N).
            let digest = text.find("\"scene_digest\"").unwrap();
            assert!(text.find(from).unwrap() < digest, "{from}");
            let edited = text.replacen(from, to, 1);
            // Refused when read: the content's digest differs, and the scene's names the key.
            match Checkpoint::from_json_str(&edited) {
                Err(Error::CheckpointSceneMismatch { key: k, reason }) => {
                    assert_eq!(k, key, "{reason}");
                    assert!(reason.contains("edited"), "{reason}");
                }
                other => panic!("{key}: not refused when read: {other:?}"),
            }
            // With the content's digest recomputed, the scene's digest still refuses it:
            // resumed on its own (edited) scene, or on the original one.
            let edited = Checkpoint::from_json_str(&resigned(&edited)).unwrap();
            let own = edited.scene().clone().build().unwrap();
            for target in [&own, &scene] {
                match target.resume(&edited) {
                    Err(Error::CheckpointSceneMismatch { key: k, reason }) => {
                        assert_eq!(k, key, "{reason}");
                        assert!(reason.contains("edited"), "{reason}");
                    }
                    other => panic!("{key}: not refused: {other:?}"),
                }
            }
        }
        // Unedited, it resumes.
        let c = Checkpoint::from_json_str(&text).unwrap();
        assert!(c.scene().clone().build().unwrap().resume(&c).is_ok());
    }

    #[test]
    fn checkpoint_files_are_written_atomically_and_read_back() {
        let scene = Scene::builder()
            .block(0.020, 0.004, 0.020)
            .normal_load(200.0)
            .seed(1)
            .build()
            .unwrap();
        let mut driver = scene.driver().unwrap();
        let dir = scratch("checkpoint-files");
        let path = dir.join("cp.json");
        // Written twice (the second replaces the first), read back equal.
        for _ in 0..2 {
            for _ in 0..7 {
                driver.step().unwrap();
            }
            let c = driver.checkpoint();
            c.write_to(&path).unwrap();
            assert!(Checkpoint::read_from(&path).unwrap() == c);
            assert_eq!(
                std::fs::read_to_string(&path).unwrap(),
                c.to_json().unwrap()
            );
        }
        // Concurrent writers of one file (the tasks of a job array sharing a directory):
        // every write succeeds and the file is always one whole checkpoint.
        let texts = [
            std::fs::read_to_string(&path).unwrap(),
            scene.driver().unwrap().checkpoint().to_json().unwrap(),
        ];
        let shared = dir.join("shared.json");
        std::thread::scope(|s| {
            for w in 0..4 {
                let (shared, texts, scene) = (&shared, &texts, &scene);
                s.spawn(move || {
                    let c = [
                        Checkpoint::from_json_str(&texts[0]).unwrap(),
                        scene.driver().unwrap().checkpoint(),
                    ];
                    for k in 0..25 {
                        c[(w + k) % 2].write_to(shared).unwrap();
                        let now = std::fs::read_to_string(shared).unwrap();
                        assert!(texts.contains(&now), "a torn checkpoint file");
                    }
                });
            }
        });
        std::fs::remove_file(&shared).unwrap();
        let names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, ["cp.json"], "no temporary file is left behind");
        // A resumed run from the file repeats the rest of the run.
        let resumed = scene
            .resume(&Checkpoint::read_from(&path).unwrap())
            .unwrap();
        let (rest, _) = finish(resumed);
        let (expected, _) = finish(driver);
        assert!(rest == expected);
        // Typed errors carrying the path.
        let missing = dir.join("missing.json");
        match Checkpoint::read_from(&missing) {
            Err(Error::Io { path, .. }) => assert_eq!(path, missing.display().to_string()),
            other => panic!("{other:?}"),
        }
        let cut = dir.join("cut.json");
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::write(&cut, &text[..text.len() / 3]).unwrap();
        match Checkpoint::read_from(&cut) {
            Err(Error::CheckpointFile { path, .. }) => assert_eq!(path, cut.display().to_string()),
            other => panic!("{other:?}"),
        }
        let nowhere = dir.join("no-such-dir").join("cp.json");
        assert!(matches!(
            scene.driver().unwrap().checkpoint().write_to(&nowhere),
            Err(Error::Io { .. })
        ));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// `text` with the JSON array (or value) after `"key":` replaced by `value`.
    pub(crate) fn replace_value(text: &str, key: &str, value: &str) -> String {
        let at = text.find(&format!("\"{key}\":")).expect(key) + key.len() + 3;
        let rest = &text[at..];
        let end = match rest.chars().next() {
            Some(open @ ('[' | '{')) => {
                let close = if open == '[' { ']' } else { '}' };
                let mut depth = 0;
                let k = rest
                    .char_indices()
                    .find(|&(_, c)| {
                        depth += i32::from(c == open) - i32::from(c == close);
                        depth == 0
                    })
                    .unwrap()
                    .0;
                at + k + 1
            }
            _ => at + rest.find([',', '}']).unwrap(),
        };
        format!("{}{value}{}", &text[..at], &text[end..])
    }

    /// Forged checkpoints, their digest recomputed as a deliberate editor would (issue
    /// 41): arrays a driver never leaves so are refused when resumed, not run into other
    /// tables. What a driver holds after its first event and before it is written from
    /// the driver's protocol (docs/model.md), not from the checkpoint code.
    #[test]
    fn forged_checkpoints_with_a_recomputed_digest_are_refused() {
        for backend in [Backend::Dense, Backend::Spectral] {
            let scene = Scene::builder()
                .block(0.020, 0.004, 0.020)
                .normal_load(200.0)
                .solver_options(SolverOptions::default().with_backend(backend).unwrap())
                .seed(1)
                .build()
                .unwrap();
            let fresh = scene.driver().unwrap().checkpoint().to_json().unwrap();
            let mut driver = scene.driver().unwrap();
            for _ in 0..12 {
                driver.step().unwrap();
            }
            let text = driver.checkpoint().to_json().unwrap();
            for (case, forged) in [
                (
                    "no initial columns",
                    replace_value(&text, "initial_columns", "[]"),
                ),
                (
                    "a negative column area",
                    replace_value(
                        &text,
                        "initial_columns",
                        "[-1.0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0]",
                    ),
                ),
                (
                    "no normal warm start",
                    replace_value(&text, "warm_normal", "[]"),
                ),
                (
                    "no tangential warm start",
                    replace_value(&text, "warm_tangential", "[]"),
                ),
                (
                    "no normal equilibrium",
                    replace_value(&text, "normal", "null"),
                ),
                (
                    "columns before the first event",
                    replace_value(
                        &fresh,
                        "initial_columns",
                        &format!("[{}]", ["1e-6"; 20].join(",")),
                    ),
                ),
            ] {
                assert_ne!(forged, text, "{case}: nothing forged");
                let checkpoint = Checkpoint::from_json_str(&resigned(&forged))
                    .unwrap_or_else(|e| panic!("{case}: the forged text does not parse: {e}"));
                match scene.resume(&checkpoint) {
                    Err(Error::InvalidCheckpoint { reason }) => {
                        assert!(!reason.is_empty(), "{case}")
                    }
                    other => panic!("{case} ({backend:?}): not refused: {:?}", other.map(|_| ())),
                }
            }
            // With events queued (a rupture followed by a state change): a queued site
            // outside the grid.
            let queued = rupture_with_queue(&scene);
            let mut d = scene.driver().unwrap();
            for _ in 0..queued {
                d.step().unwrap();
            }
            let with_queue = d.checkpoint().to_json().unwrap();
            let pending = with_queue.find("\"pending\":").unwrap();
            let ix = pending + with_queue[pending..].find("\"ix\":").unwrap();
            let forged_site = format!(
                "{}{}",
                &with_queue[..ix],
                replace_value(&with_queue[ix..], "ix", "999")
            );
            assert_ne!(forged_site, with_queue);
            for (case, forged) in [
                ("a queued site outside the grid", forged_site),
                (
                    "the start phase after events",
                    replace_value(&text, "phase", "\"Start\""),
                ),
                (
                    "more ruptures than broken sites",
                    replace_value(&text, "avalanche_ruptures", "100000"),
                ),
            ] {
                assert_ne!(forged, text, "{case}: nothing forged");
                let checkpoint = Checkpoint::from_json_str(&resigned(&forged))
                    .unwrap_or_else(|e| panic!("{case}: the forged text does not parse: {e}"));
                assert!(
                    matches!(
                        scene.resume(&checkpoint),
                        Err(Error::InvalidCheckpoint { .. })
                    ),
                    "{case} ({backend:?}): not refused"
                );
            }
            // The checkpoints as written resume.
            for t in [&fresh, &text, &with_queue] {
                scene
                    .resume(&Checkpoint::from_json_str(t).unwrap())
                    .unwrap();
            }
        }
    }

    /// A checkpoint whose load was edited (its digest recomputed) is consistent in itself,
    /// but not with the tables of its run: `RunTables::resume` refuses it before writing.
    #[test]
    fn a_checkpoint_whose_load_was_edited_does_not_resume_its_tables() {
        let dir = scratch("load");
        let scene = Scene::builder()
            .block(0.020, 0.004, 0.020)
            .normal_load(200.0)
            .seed(1)
            .build()
            .unwrap();
        let mut driver = scene.driver().unwrap();
        let mut tables = output::RunTables::create(&dir, &driver).unwrap();
        let mut stable = 0;
        let mut text = String::new();
        while let Some(event) = driver.step().unwrap() {
            tables.record(&driver, &event).unwrap();
            if matches!(event, Event::Stable { .. }) {
                stable += 1;
                if stable == 6 {
                    tables.flush().unwrap();
                    text = driver.checkpoint().to_json().unwrap();
                    break;
                }
            }
        }
        drop(tables);
        let control: f64 = {
            let at = text.find("\"control\":").unwrap() + "\"control\":".len();
            let end = at + text[at..].find(',').unwrap();
            text[at..end].parse().unwrap()
        };
        let forged = replace_value(&text, "control", &format!("{:?}", control * 1.001));
        let checkpoint = Checkpoint::from_json_str(&resigned(&forged)).unwrap();
        let resumed = scene.resume(&checkpoint).unwrap();
        let before = std::fs::read(dir.join("events.csv.partial")).unwrap();
        match output::RunTables::resume(&dir, &resumed) {
            Err(Error::CorruptTable { reason, .. }) => {
                assert!(reason.contains("the checkpoint's load"), "{reason}")
            }
            other => panic!("not refused: {:?}", other.map(|_| ())),
        }
        assert_eq!(
            std::fs::read(dir.join("events.csv.partial")).unwrap(),
            before
        );
        // The checkpoint as written resumes its tables.
        let good = scene
            .resume(&Checkpoint::from_json_str(&text).unwrap())
            .unwrap();
        output::RunTables::resume(&dir, &good).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn damaged_checkpoints_are_refused_with_typed_errors() {
        let scene = Scene::builder()
            .block(0.020, 0.004, 0.020)
            .normal_load(200.0)
            .seed(1)
            .build()
            .unwrap();
        let mut driver = scene.driver().unwrap();
        for _ in 0..5 {
            driver.step().unwrap();
        }
        let text = driver.checkpoint().to_json().unwrap();
        // The test's digest is the program's.
        assert_eq!(resigned(&text), text);
        let refused = |text: &str| match Checkpoint::from_json_str(text) {
            Err(Error::InvalidCheckpoint { reason }) => reason,
            other => panic!("not refused: {other:?}"),
        };
        let reason = refused(&text[..text.len() / 2]);
        assert!(reason.contains("EOF"), "{reason}");
        // Another layout version, newer or older (older ones carry no digest): refused,
        // saying which.
        for (version, words) in [(6, "layout version 6"), (2, "layout version 2")] {
            let other = text.replacen("\"format\":4", &format!("\"format\":{version}"), 1);
            assert_ne!(other, text);
            let reason = refused(&other);
            assert!(
                reason.contains(words) && reason.contains("reads versions 3 to 5"),
                "{reason}"
            );
        }
        // Version 5 is an anchored contact rule's: the paper's state under it, signed
        // again, is read but not resumed.
        let five = resigned(&text.replacen("\"format\":4", "\"format\":5", 1));
        let resumed = scene.resume(&Checkpoint::from_json_str(&five).unwrap());
        assert!(
            matches!(&resumed, Err(Error::InvalidCheckpoint { reason }) if reason.contains("layout version 5 without")),
            "{resumed:?}"
        );
        // Edits and damage: the event count, a site's state, a key this build does not
        // know (at the top, inside), a flipped byte, a missing or altered digest.
        let states = text.find("\"states\":[").unwrap();
        let attached = states
            + text[states..]
                .find("\"Attached\"")
                .expect("an attached site");
        let flip = text.len() / 2;
        let flipped = {
            let mut bytes = text.clone().into_bytes();
            bytes[flip] ^= 0x01;
            String::from_utf8(bytes).unwrap()
        };
        let digest_at = text.rfind("\"digest\"").unwrap();
        for (name, edited, words) in [
            (
                "events",
                text.replacen("\"events\":5,", "\"events\":6,", 1),
                "does not match its digest",
            ),
            (
                "state",
                format!(
                    "{}\"Broken\"{}",
                    &text[..attached],
                    &text[attached + "\"Attached\"".len()..]
                ),
                "does not match its digest",
            ),
            (
                "unknown key",
                text.replacen("{\"format\"", "{\"note\":1,\"format\"", 1),
                "unknown field `note`",
            ),
            (
                "unknown key inside",
                {
                    // In the solver's state (the last `solver`; the first is the scene's).
                    let at = text.rfind("\"solver\":{").unwrap() + "\"solver\":{".len();
                    format!("{}\"note\":1,{}", &text[..at], &text[at..])
                },
                "does not match its digest",
            ),
            ("flipped byte", flipped, ""),
            (
                "no digest",
                format!("{}}}", &text[..digest_at - 1]),
                "does not end with its digest",
            ),
            (
                "altered digest",
                text.replacen("\"digest\":\"", "\"digest\":\"0", 1),
                "does not end with its digest",
            ),
        ] {
            assert_ne!(edited, text, "{name}");
            let reason = refused(&edited);
            assert!(reason.contains(words), "{name}: {reason}");
        }
        // Unedited, it is read back equal.
        assert!(Checkpoint::from_json_str(&text).unwrap() == driver.checkpoint());
        // A warm start of the wrong length, the digest recomputed: refused on resume.
        let key = "\"warm_normal\":[";
        let at = text.find(key).unwrap() + key.len();
        let short = resigned(&format!("{}0.0,{}", &text[..at], &text[at..]));
        let c = Checkpoint::from_json_str(&short).unwrap();
        assert!(matches!(
            scene.resume(&c),
            Err(Error::InvalidCheckpoint { .. })
        ));
    }
}

/// On a grid large enough for the two-level preconditioner (32 768 cells and more: the
/// coarse space of aggregates corrects FSAI in the normal solves), two threads repeat the
/// one-thread run bit for bit and a checkpoint resumes it bit for bit (the coarse matrix
/// and its factor are functions of the set alone, rebuilt on resume). FSAI alone takes 32
/// CG iterations per normal solve on this run (checked by raising the threshold); fewer
/// than 20 show the coarse space is in use.
#[test]
fn two_level_solves_repeat_across_threads_and_resume() {
    let builder = |parallelism| {
        Scene::builder()
            .block(0.256, 0.128, 0.075)
            .normal_load(1e6 * 0.256 * 0.128)
            .solver_options(
                SolverOptions::default()
                    .with_parallelism(parallelism)
                    .unwrap(),
            )
            .seed(2)
    };
    let count = 40;
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let mut one = builder(Parallelism::Sequential)
        .build()
        .unwrap()
        .driver()
        .unwrap();
    let events: Vec<Event> = (0..count).map(|_| one.step().unwrap().unwrap()).collect();
    let traction = one.normal_traction().unwrap().to_vec();
    let stats = one.solve_stats();
    // The first (cold) solve explores with another preconditioner; the warm ones follow.
    let warm = (stats.normal_solves - 1) as f64;
    assert!(warm >= 10.0, "{stats:?}");
    assert!(
        events
            .iter()
            .filter(|e| matches!(e, Event::Rupture { .. }))
            .count()
            >= 10,
        "too few ruptures"
    );
    let mut two = builder(Parallelism::Threads(2))
        .build()
        .unwrap()
        .driver()
        .unwrap();
    let mut checkpoint = None;
    for (k, event) in events.iter().enumerate() {
        assert!(
            two.step().unwrap().as_ref() == Some(event),
            "event {k} differs on two threads"
        );
        if k + 1 == count / 2 {
            checkpoint = Some(two.checkpoint());
        }
    }
    assert_eq!(bits(two.normal_traction().unwrap()), bits(&traction));
    let mut resumed = builder(Parallelism::Sequential)
        .build()
        .unwrap()
        .resume(&checkpoint.unwrap())
        .unwrap();
    for (k, event) in events.iter().enumerate().skip(count / 2) {
        assert!(
            resumed.step().unwrap().as_ref() == Some(event),
            "event {k} differs resumed"
        );
    }
    assert_eq!(bits(resumed.normal_traction().unwrap()), bits(&traction));
    let per_solve =
        resumed.solve_stats().normal_iterations as f64 / resumed.solve_stats().normal_solves as f64;
    assert!(
        per_solve < 20.0,
        "{per_solve} CG iterations per normal solve"
    );
}

/// What a resume keeps (issue 53): every kept row is the one the checkpoint covers, the
/// checkpoint's state is the one its events and equilibria give, and the observers it
/// continues are those the run recorded; anything else is refused before the directory
/// is touched.
#[cfg(feature = "serde")]
mod kept {
    use super::json::{replace_value, resigned};
    use super::*;
    use crate::common::{copy_dir, killed_after_checkpoint, scratch};
    use std::path::Path;

    /// The tables a run recording fields and profiles keeps on resume.
    const TABLES: [&str; 5] = [
        "events.csv",
        "curve.csv",
        "contact_map.csv",
        "fields.csv",
        "profiles.csv",
    ];

    fn options() -> RunOptions {
        RunOptions::new()
            .record_fields(2, &[0.002])
            .record_profiles(&[0.05, 0.1, 0.2], &[0.002])
    }

    fn scene() -> Scene {
        Scene::builder()
            .block(0.020, 0.004, 0.020)
            .normal_load(200.0)
            .seed(1)
            .run_options(options())
            .build()
            .unwrap()
    }

    /// Every file of `dir` with its bytes.
    fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
        let mut out: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| {
                let path = e.unwrap().path();
                let name = path.file_name().unwrap().to_string_lossy().to_string();
                (name, std::fs::read(&path).unwrap())
            })
            .collect();
        out.sort();
        out
    }

    /// A run of `scene()` into a new directory, killed 30 events past a checkpoint at
    /// its 12th stable state; the checkpoint as JSON.
    fn cut_run(name: &str) -> (std::path::PathBuf, String) {
        let dir = scratch(name);
        let checkpoint = killed_after_checkpoint(&scene(), &dir, 12, 30);
        (dir, checkpoint.to_json().unwrap())
    }

    /// A finite edit of a cell, in its own format: an integer plus one, a number times
    /// 1.5 (or a small number for a zero), a word swapped for `other` (another value of
    /// its column); `None` for an empty cell.
    fn edited(cell: &str, other: Option<&str>) -> Option<String> {
        if cell.is_empty() {
            return None;
        }
        if let Ok(i) = cell.parse::<i64>() {
            return Some((i + 1).to_string());
        }
        if let Ok(x) = cell.parse::<f64>() {
            let y = if x == 0.0 { 1e-9 } else { 1.5 * x };
            return Some(match cell.split_once('.') {
                Some((_, decimals)) if !cell.contains('e') => {
                    format!(
                        "{:.*}",
                        decimals.len(),
                        x + 10f64.powi(-(decimals.len() as i32))
                    )
                }
                _ => format!("{y:.12e}"),
            });
        }
        other.map(String::from)
    }

    /// Each table kept on resume, each of its columns: a finite edit of one kept row
    /// (before the checkpoint's event) is refused with a typed error naming the table,
    /// and the directory is left as it was. Reference: the untouched copy resumes.
    #[test]
    fn every_kept_table_refuses_a_finite_edit_of_each_column() {
        let (base, text) = cut_run("edits");
        let checkpoint = Checkpoint::from_json_str(&text).unwrap();
        let k = checkpoint.event_count();
        let work = base.with_extension("work");
        let resume = |dir: &Path| {
            let driver = scene().resume(&checkpoint).unwrap();
            output::RunTables::resume(dir, &driver).map(|_| ())
        };
        let mut edits = 0;
        for table in TABLES {
            let name = format!("{table}.partial");
            let original = std::fs::read_to_string(base.join(&name)).unwrap();
            let lines: Vec<&str> = original.lines().collect();
            let header: Vec<&str> = lines[0].split(',').collect();
            // The event each row records (profiles.csv: its second column).
            let event_column = usize::from(table == "profiles.csv");
            let kept: Vec<usize> = (1..lines.len())
                .filter(|&l| {
                    let event = lines[l].split(',').nth(event_column).unwrap();
                    event.parse::<usize>().is_ok_and(|e| e < k)
                })
                .collect();
            assert!(kept.len() >= 2, "{table}: {} kept rows", kept.len());
            for (column, key) in header.iter().enumerate() {
                let cell = |l: usize| lines[l].split(',').nth(column).unwrap();
                // The middle kept row with a value in the column.
                let rows: Vec<usize> = kept
                    .iter()
                    .copied()
                    .filter(|&l| !cell(l).is_empty())
                    .collect();
                let Some(&line) = rows.get(rows.len() / 2) else {
                    continue; // never written before the checkpoint (no cell to edit)
                };
                let other = kept.iter().map(|&l| cell(l)).find(|c| *c != cell(line));
                let Some(value) = edited(cell(line), other) else {
                    continue;
                };
                let mut cells: Vec<String> = lines[line].split(',').map(String::from).collect();
                cells[column] = value;
                let mut forged: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
                forged[line] = cells.join(",");
                copy_dir(&base, &work);
                std::fs::write(work.join(&name), forged.join("\n") + "\n").unwrap();
                let before = files(&work);
                let case = format!("{table} line {} column {key}", line + 1);
                match resume(&work) {
                    Err(Error::CorruptTable { path, reason }) => {
                        let path = path.unwrap();
                        assert!(
                            path.ends_with(&name),
                            "{case}: {} ({reason})",
                            path.display()
                        );
                    }
                    Err(Error::InvalidCheckpoint { .. }) => {}
                    other => panic!("{case}: not refused: {:?}", other.map(|_| ())),
                }
                assert!(files(&work) == before, "{case}: the directory changed");
                edits += 1;
            }
        }
        assert!(edits > 40, "{edits} edits");
        // An edit the row checks cannot see is named by its line: a rupture's energy.
        let events = std::fs::read_to_string(base.join("events.csv.partial")).unwrap();
        let (line, row) = events
            .lines()
            .enumerate()
            .find(|(_, l)| l.contains(",rupture,"))
            .unwrap();
        let mut cells: Vec<String> = row.split(',').map(String::from).collect();
        cells[6] = edited(&cells[6], None).unwrap();
        copy_dir(&base, &work);
        std::fs::write(
            work.join("events.csv.partial"),
            events.replacen(row, &cells.join(","), 1),
        )
        .unwrap();
        match resume(&work) {
            Err(Error::CorruptTable { reason, .. }) => assert!(
                reason.contains(&format!("line {}", line + 1)) || reason.contains("lines "),
                "{reason}"
            ),
            other => panic!("not refused: {:?}", other.map(|_| ())),
        }
        // The untouched copy resumes.
        copy_dir(&base, &work);
        resume(&work).unwrap();
        std::fs::remove_dir_all(&base).unwrap();
        std::fs::remove_dir_all(&work).unwrap();
    }

    /// Checkpoints forged with a recomputed digest, consistent in their own keys, but not
    /// with the physics or the events before them: refused with typed errors, the tables
    /// untouched. Reference: the model's equations (docs/model.md), not the check's code.
    #[test]
    fn forged_states_tractions_and_loads_are_refused() {
        let (dir, text) = cut_run("forged");
        let before = files(&dir);
        // The first broken site, set back to attached (in the states and the normal
        // equilibrium's states alike).
        let states_at = text.find("\"states\":[").unwrap();
        let broken = states_at + text[states_at..].find("\"Broken\"").unwrap();
        let index = text[states_at + 10..broken].matches('"').count() / 2;
        let attach_all = |t: &str| {
            let mut out = String::new();
            let mut rest = t;
            let mut seen = 0;
            while let Some(at) = rest.find("\"states\":[") {
                let (head, tail) = rest.split_at(at + 10);
                out.push_str(head);
                let end = tail.find(']').unwrap();
                let mut states: Vec<&str> = tail[..end].split(',').collect();
                states[index] = "\"Attached\"";
                out.push_str(&states.join(","));
                rest = &tail[end..];
                seen += 1;
            }
            out.push_str(rest);
            assert_eq!(seen, 2, "the states and the normal equilibrium's");
            out
        };
        let scaled = |t: &str, key: &str, factor: f64| {
            let pattern = format!("\"{key}\":{{\"traction\":[");
            let at = t.find(&pattern).unwrap() + pattern.len();
            let end = at + t[at..].find(']').unwrap();
            let values: Vec<String> = t[at..end]
                .split(',')
                .map(|v| format!("{:?}", v.parse::<f64>().unwrap() * factor))
                .collect();
            format!("{}{}{}", &t[..at], values.join(","), &t[end..])
        };
        let control: f64 = {
            let at = text.find("\"control\":").unwrap() + 10;
            let end = at + text[at..].find(',').unwrap();
            text[at..end].parse().unwrap()
        };
        for (case, forged) in [
            ("a broken site set back to attached", attach_all(&text)),
            ("the normal tractions scaled", scaled(&text, "normal", 1.01)),
            (
                "the shear tractions scaled",
                scaled(&text, "response", 1.01),
            ),
            (
                "the load raised past the weakest site",
                replace_value(&text, "control", &format!("{:?}", control * 1.5)),
            ),
        ] {
            assert_ne!(forged, text, "{case}: nothing forged");
            let checkpoint = Checkpoint::from_json_str(&resigned(&forged))
                .unwrap_or_else(|e| panic!("{case}: does not parse: {e}"));
            let refused = match scene().resume(&checkpoint) {
                Err(e) => Err(e),
                Ok(driver) => output::RunTables::resume(&dir, &driver).map(|_| ()),
            };
            match refused {
                Err(Error::InvalidCheckpoint { reason }) => assert!(!reason.is_empty()),
                Err(Error::CorruptTable { reason, .. }) => assert!(!reason.is_empty()),
                other => panic!("{case}: not refused: {:?}", other.map(|_| ())),
            }
            assert!(files(&dir) == before, "{case}: the directory changed");
        }
        // As written, it resumes.
        let driver = scene()
            .resume(&Checkpoint::from_json_str(&text).unwrap())
            .unwrap();
        output::RunTables::resume(&dir, &driver).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Checks a directory resumed from a run begun by 1.1 (`work`: its `curve.csv` had no
    /// slip columns up to the checkpoint's event `kept`) against the uninterrupted run
    /// `whole`: the same files; `curve.csv` with 1.2's header, the kept rows with empty slip
    /// cells and the others as the uninterrupted run writes them; `per_avalanche.csv` with
    /// slip where both of an avalanche's states have it; every other file byte for byte.
    fn assert_resumed_from_1_1(work: &Path, whole: &Path, kept: usize) {
        let (resumed, reference) = (files(work), files(whole));
        let names = |f: &[(String, Vec<u8>)]| f.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>();
        assert_eq!(names(&resumed), names(&reference));
        let (mut empty, mut filled) = (0, 0);
        for ((name, a), (_, b)) in resumed.iter().zip(&reference) {
            let (a, b) = (String::from_utf8_lossy(a), String::from_utf8_lossy(b));
            match name.as_str() {
                "curve.csv" => {
                    assert_eq!(a.lines().count(), b.lines().count());
                    for (a, b) in a.lines().zip(b.lines()) {
                        let event: usize = b.split(',').next().unwrap().parse().unwrap_or(0);
                        if event > 0 && event <= kept {
                            let cells: Vec<&str> = b.split(',').collect();
                            assert_eq!(a, format!("{},,,", cells[..10].join(",")));
                            empty += 1;
                        } else {
                            assert_eq!(a, b);
                        }
                    }
                }
                "per_avalanche.csv" => {
                    assert_eq!(a.lines().count(), b.lines().count());
                    for (a, b) in a.lines().zip(b.lines()).skip(1) {
                        let (a, b): (Vec<&str>, Vec<&str>) =
                            (a.split(',').collect(), b.split(',').collect());
                        let n = b.len();
                        assert_eq!(a[..n - 3], b[..n - 3]);
                        let start: usize = b[1].parse().unwrap();
                        // The state before the avalanche that starts after the
                        // checkpoint's is a kept row.
                        if start <= kept + 1 {
                            assert_eq!(a[n - 3..], ["", "", ""], "avalanche {}", b[0]);
                        } else {
                            assert_eq!(a[n - 3..], b[n - 3..], "avalanche {}", b[0]);
                            filled += usize::from(!b[n - 3].is_empty());
                        }
                    }
                }
                _ => assert!(a == b, "{name} differs from the uninterrupted run's"),
            }
        }
        assert!(empty >= 7, "{empty} kept rows");
        assert!(
            filled > 3,
            "{filled} avalanches with slip after the checkpoint"
        );
    }

    /// A run begun by 1.1 resumes: `curve.csv` without the slip columns 1.2 added, under a
    /// checkpoint of layout 3 (no table digests), made here from a run of today's code
    /// (`assert_resumed_from_1_1` says what the resumed tables hold; reference: the run from
    /// the start in another directory).
    #[test]
    fn a_run_begun_by_1_1_resumes_with_empty_slip_cells_on_its_kept_rows() {
        let (work, text) = cut_run("from-1-1");
        let whole = scratch("from-1-1-whole");
        let mut driver = scene().driver().unwrap();
        output::RunTables::create(&whole, &driver)
            .unwrap()
            .run_to_slip(&mut driver, None, |_, _| {})
            .unwrap();
        // As 1.1 left it: ten columns in curve.csv, no digests in the checkpoint.
        let partial = work.join("curve.csv.partial");
        let curve = std::fs::read_to_string(&partial).unwrap();
        let old: String = curve
            .lines()
            .map(|l| l.split(',').take(10).collect::<Vec<_>>().join(",") + "\n")
            .collect();
        assert!(old
            .lines()
            .next()
            .unwrap()
            .ends_with(",attached,area_exceeds_nominal"));
        std::fs::write(&partial, old).unwrap();
        let text = text.replacen("\"format\":4", "\"format\":3", 1);
        let tables = text.find(",\"tables\":").unwrap();
        let end = text.rfind(",\"digest\":").unwrap();
        let text = resigned(&format!("{}{}", &text[..tables], &text[end..]));
        let checkpoint = Checkpoint::from_json_str(&text).unwrap();
        let kept = checkpoint.event_count();
        let mut driver = scene().resume(&checkpoint).unwrap();
        output::RunTables::resume(&work, &driver)
            .unwrap()
            .run_to_slip(&mut driver, None, |_, _| {})
            .unwrap();
        assert_resumed_from_1_1(&work, &whole, kept);
        std::fs::remove_dir_all(&work).unwrap();
        std::fs::remove_dir_all(&whole).unwrap();
    }

    /// A checkpoint and the partial tables of its run as the 1.1 code wrote them
    /// (`tests/data/checkpoints/paper-1.1`: a 12 x 2 run cut 7 events past a checkpoint at
    /// its 7th stable state, written before the contact rule became one component, issue
    /// 55, and before `curve.csv`'s slip columns). Resumed, the tables end as those of the
    /// uninterrupted run today's code records, derived tables included, but for the slip
    /// cells of the kept rows (`assert_resumed_from_1_1`). The reference is that
    /// uninterrupted run. Like every resume, this needs the same float results (same CPU
    /// features) as the machine that wrote the fixture.
    #[test]
    fn a_1_1_checkpoint_resumes_its_tables_to_the_uninterrupted_run() {
        let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/checkpoints");
        let checkpoint = Checkpoint::read_from(data.join("paper-1.1.json")).unwrap();
        let scene = checkpoint.scene().clone().build().unwrap();
        // The fixture holds rows past the checkpoint, which the resume cuts away.
        let events = std::fs::read_to_string(data.join("paper-1.1/events.csv.partial")).unwrap();
        let last: usize = events
            .lines()
            .last()
            .unwrap()
            .split(',')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        assert!(last > checkpoint.event_count() && checkpoint.event_count() > 0);
        let whole = scratch("fixture-whole");
        let mut driver = scene.driver().unwrap();
        output::RunTables::create(&whole, &driver)
            .unwrap()
            .run_to_slip(&mut driver, None, |_, _| {})
            .unwrap();
        let work = scratch("fixture-resumed");
        copy_dir(&data.join("paper-1.1"), &work);
        let mut driver = scene.resume(&checkpoint).unwrap();
        output::RunTables::resume(&work, &driver)
            .unwrap()
            .run_to_slip(&mut driver, None, |_, _| {})
            .unwrap();
        assert_resumed_from_1_1(&work, &whole, checkpoint.event_count());
        std::fs::remove_dir_all(&whole).unwrap();
        std::fs::remove_dir_all(&work).unwrap();
    }

    /// A resume whose observers differ from those the directory recorded (its tables or
    /// its scene.json) is refused before anything is touched: no recorded table is
    /// removed, scene.json keeps describing the tables present.
    #[test]
    fn resume_across_other_observers_is_refused_and_removes_nothing() {
        let (base, text) = cut_run("observers");
        let checkpoint = Checkpoint::from_json_str(&text).unwrap();
        let work = base.with_extension("work");
        // The checkpoint's scene without observers, resumed into the directory that
        // recorded fields and profiles: the checkpoint, and the tables, say otherwise.
        let bare = RunOptions::new();
        let scene = scene();
        for (case, options) in [
            ("no observers", bare.clone()),
            ("fields only", bare.clone().record_fields(2, &[0.002])),
        ] {
            copy_dir(&base, &work);
            let before = files(&work);
            let driver = scene.resume(&checkpoint).unwrap();
            match output::RunTables::resume_with(&work, &driver, &options) {
                Err(Error::InvalidCheckpoint { .. } | Error::RunDirectory { .. }) => {}
                other => panic!("{case}: not refused: {:?}", other.map(|_| ())),
            }
            assert!(files(&work) == before, "{case}: the directory changed");
        }
        // The same without the checkpoint's table digests (a 1.x checkpoint): the
        // recorded tables and scene.json still refuse it.
        let old = text.replacen("\"format\":4", "\"format\":3", 1);
        let tables = old.find(",\"tables\":").unwrap();
        let end = old.rfind(",\"digest\":").unwrap();
        let old = resigned(&format!("{}{}", &old[..tables], &old[end..]));
        let old = Checkpoint::from_json_str(&old).unwrap();
        copy_dir(&base, &work);
        let before = files(&work);
        let driver = scene.resume(&old).unwrap();
        match output::RunTables::resume_with(&work, &driver, &bare) {
            Err(Error::RunDirectory { reason, .. }) => {
                assert!(reason.contains("fields.csv"), "{reason}")
            }
            other => panic!("not refused: {:?}", other.map(|_| ())),
        }
        assert!(files(&work) == before, "the directory changed");
        // scene.json's observers edited: refused, with the checkpoint's own options too.
        copy_dir(&base, &work);
        let record = std::fs::read_to_string(work.join("scene.json")).unwrap();
        let edited = record.replacen("0.05", "0.06", 1);
        assert_ne!(edited, record);
        std::fs::write(work.join("scene.json"), edited).unwrap();
        let before = files(&work);
        let driver = scene.resume(&old).unwrap();
        match output::RunTables::resume(&work, &driver) {
            Err(Error::RunDirectory { reason, .. }) => {
                assert!(reason.contains("profiles"), "{reason}")
            }
            other => panic!("not refused: {:?}", other.map(|_| ())),
        }
        assert!(files(&work) == before, "the directory changed");
        // The 1.x checkpoint resumes the untouched directory, with today's checks.
        copy_dir(&base, &work);
        let driver = scene.resume(&old).unwrap();
        output::RunTables::resume(&work, &driver).unwrap();
        std::fs::remove_dir_all(&base).unwrap();
        std::fs::remove_dir_all(&work).unwrap();
    }
}

"""Checkpoints between Python and the program `precursors`, both ways, and as bytes."""

import shutil

import precursors
from conftest import CALIBRATION, run_program
from test_events import _as_row, _events_csv


def test_bytes_round_trip_resumes_with_the_same_events(calibration):
    driver = calibration.driver()
    driver.run(until=0.3 * driver.friction_coefficient * driver.normal_load)
    checkpoint = precursors.Checkpoint.from_bytes(driver.checkpoint().to_bytes())
    assert checkpoint.event_count == driver.event_count
    resumed = checkpoint.scene().resume(checkpoint)
    rest = [_as_row(e) for e in driver]
    assert rest == [_as_row(e) for e in resumed]
    assert "event_count" in repr(checkpoint)


def test_python_checkpoint_resumed_by_the_program(calibration, program_run, tmp_path):
    # The program's finished run directory: `resume` cuts its tables back to the
    # checkpoint's event and runs on; the tables must end as the uninterrupted run's.
    out = tmp_path / "run"
    shutil.copytree(program_run, out)
    driver = calibration.driver()
    driver.run(until=0.5 * driver.friction_coefficient * driver.normal_load)
    driver.run(until="stable")
    path = tmp_path / "checkpoint.json"
    driver.checkpoint().write_to(path)
    run_program("resume", str(path), "--out", str(out), "--quiet")
    for name in ("events.csv", "curve.csv", "contact_map.csv"):
        assert (out / name).read_bytes() == (program_run / name).read_bytes(), name


def test_program_checkpoint_resumed_in_python(program_run, tmp_path):
    path = tmp_path / "checkpoint.json"
    run_program(
        "run", str(CALIBRATION), "--out", str(tmp_path / "run"), "--quiet",
        "--checkpoint", str(path), "--every", "40",
    )
    checkpoint = precursors.Checkpoint.read_from(path)
    assert checkpoint.event_count > 0
    expected = _events_csv(program_run / "events.csv")
    resumed = checkpoint.scene().resume(checkpoint)
    rest = [_as_row(e) for e in resumed]
    assert rest == expected[checkpoint.event_count:]

"""Ctrl-C: SIGINT to a process running a long run stops it between events with
KeyboardInterrupt, and leaves no table under its complete name."""

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import precursors

# A run of a few minutes: the calibration block with 0.25 mm cells (560 x 28).
LONG_RUN = """
import sys, precursors
scene = precursors.Scene(cell_size=(0.00025, 0.00025), backend="spectral")
{body}
"""


def _interrupt(body: str, tmp_path: Path, ready) -> subprocess.CompletedProcess:
    child = subprocess.Popen(
        [sys.executable, "-c", LONG_RUN.format(body=body)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
    )
    try:
        deadline = time.monotonic() + 120
        while not ready() and child.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        assert child.poll() is None, child.communicate()
        sent = time.monotonic()
        child.send_signal(signal.SIGINT)
        # Between events: well before the run would have ended (minutes).
        out, err = child.communicate(timeout=30)
        assert time.monotonic() - sent < 30
    finally:
        child.kill()
        child.wait()
    return subprocess.CompletedProcess(child.args, child.returncode, out, err)


def test_ctrl_c_stops_run_with_keyboard_interrupt_and_partial_tables(tmp_path):
    out = tmp_path / "out"
    partial = out / "events.csv.partial"
    done = _interrupt(
        "precursors.run(scene, 'out')",
        tmp_path,
        lambda: partial.is_file() and partial.stat().st_size > 200,
    )
    assert done.returncode != 0
    assert "KeyboardInterrupt" in done.stderr
    for name in ("events.csv", "curve.csv", "contact_map.csv"):
        assert not (out / name).exists(), name
    assert partial.is_file()
    lines = partial.read_text().splitlines()
    assert lines[0].startswith("index,kind")
    assert len(lines) > 2


def test_ctrl_c_stops_driver_run(tmp_path):
    marker = tmp_path / "started"
    body = (
        "d = scene.driver()\n"
        "d.step()\n"
        "open('started', 'w').close()\n"
        "try:\n"
        "    d.run()\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted at', d.event_count, 'events; next', d.step().index)\n"
        "    sys.exit(3)\n"
    )
    done = _interrupt(body, tmp_path, marker.is_file)
    assert done.returncode == 3, done.stderr
    assert "interrupted at" in done.stdout


def test_ctrl_c_stops_a_run_with_checkpoints_that_resume(tmp_path):
    # run(checkpoint=, every=) writes checkpoints as the program's `run --checkpoint`;
    # the one stopped by Ctrl-C resumes the scene where it was taken.
    out = tmp_path / "out"
    checkpoint = tmp_path / "cp.bin"
    done = _interrupt(
        "precursors.run(scene, 'out', checkpoint='cp.bin', every=2)",
        tmp_path,
        checkpoint.is_file,
    )
    assert "KeyboardInterrupt" in done.stderr
    assert (out / "events.csv.partial").is_file() and not (out / "events.csv").exists()
    cp = precursors.Checkpoint.read_from(checkpoint)
    assert cp.event_count > 0
    driver = cp.scene().resume(cp)
    assert driver.event_count == cp.event_count


def test_ctrl_c_stops_a_sweep_leaving_only_complete_runs_done(tmp_path):
    # Two long runs on two jobs; Ctrl-C once both are under way stops both at their next
    # event: KeyboardInterrupt within seconds, and no run marked done.
    base = {"cells": {"kind": "size", "dx": 0.00025, "dy": 0.00025},
            "solver": {"backend": "spectral"}}
    sweep = {"base": base, "axes": [{"key": "normal_load", "values": [3000.0, 3500.0]}]}
    (tmp_path / "s.json").write_text(json.dumps(sweep))
    out = tmp_path / "sw"

    def under_way() -> bool:
        partials = list(out.glob("*/events.csv.partial"))
        return len(partials) == 2 and all(p.stat().st_size > 200 for p in partials)

    done = _interrupt("precursors.sweep('s.json', 'sw', jobs=2)", tmp_path, under_way)
    assert done.returncode != 0
    assert "KeyboardInterrupt" in done.stderr
    assert not list(out.glob("*/done"))
    assert len(list(out.glob("*/events.csv.partial"))) == 2

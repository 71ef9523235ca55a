"""Ctrl-C: SIGINT to a process running a long run stops it between events with
KeyboardInterrupt, and leaves no table under its complete name."""

import signal
import subprocess
import sys
import time
from pathlib import Path

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

"""Shared fixtures: the calibration scene, the `precursors` program and its run of it.

The program is the independent side of several tests: `.ci/run` passes the one the Rust
tests built (`PRECURSORS_BIN=target/release/precursors`, the README's build); without the
variable the tests use that path and build the program there first if it is missing."""

import os
import subprocess
from pathlib import Path

import pytest

import precursors

ROOT = Path(__file__).resolve().parents[2]
CALIBRATION = ROOT / "examples" / "scenes" / "calibration.json"


def program() -> Path:
    given = os.environ.get("PRECURSORS_BIN")
    path = Path(given) if given else ROOT / "target" / "release" / "precursors"
    if not given and not path.is_file():
        subprocess.run(
            ["cargo", "build", "--quiet", "--release", "--all-features", "--bin", "precursors"],
            cwd=ROOT, check=True, env={**os.environ, "CARGO_TARGET_DIR": str(ROOT / "target")},
        )
    if not path.is_file():
        raise FileNotFoundError(
            f"the precursors program is not at {path}: build it with "
            "`cargo build --release --all-features --bin precursors` or set PRECURSORS_BIN"
        )
    return path


def run_program(*args: str) -> subprocess.CompletedProcess:
    done = subprocess.run(
        [str(program()), *args], capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr
    return done


@pytest.fixture(scope="session")
def calibration() -> precursors.Scene:
    return precursors.Scene.from_file(CALIBRATION)


@pytest.fixture(scope="session")
def program_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The program's run of the calibration scene to global slip (its directory)."""
    out = tmp_path_factory.mktemp("program-run")
    run_program("run", str(CALIBRATION), "--out", str(out), "--quiet")
    return out

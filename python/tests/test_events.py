"""The events of the calibration scene from Python are the `precursors run` tables'."""

import math
from pathlib import Path
from typing import List, Optional

import precursors


def _optional(cell: str, kind: type) -> Optional[float]:
    return None if cell == "" else kind(cell)


def _events_csv(path: Path) -> List[tuple]:
    lines = path.read_text().splitlines()
    assert lines[0].startswith("index,kind,ix,iy,force_N,drive_displacement_m,energy_J,ruptures")
    rows = []
    for line in lines[1:]:
        index, kind, ix, iy, force, drive, energy, ruptures, _exceeds = line.split(",")
        rows.append(
            (
                int(index),
                kind,
                _optional(ix, int),
                _optional(iy, int),
                _optional(force, float),
                _optional(drive, float),
                _optional(energy, float),
                _optional(ruptures, int),
            )
        )
    return rows


def table_value(x: Optional[float]) -> Optional[float]:
    """`x` as the tables write it (`{:.12e}`, 13 significant digits: output.rs), read back."""
    return None if x is None else float(f"{x:.12e}")


def _as_row(event: precursors.Event) -> tuple:
    return (
        event.index,
        event.kind,
        event.ix,
        event.iy,
        table_value(event.force),
        table_value(event.drive_displacement),
        table_value(event.energy),
        event.ruptures,
    )


def test_iterating_the_driver_gives_the_programs_events(calibration, program_run):
    expected = _events_csv(program_run / "events.csv")
    events = [_as_row(e) for e in calibration.driver()]
    # Floats compare at the tables' 13 significant digits (every digit they hold); the
    # tables Python's `run` writes equal the program's byte for byte (below).
    assert len(events) == len(expected)
    for got, want in zip(events, expected):
        assert got == want
    assert events[-1][1] == "global_slip"
    assert len(events) > 1000


def test_step_and_run_until_give_the_same_events(calibration, program_run):
    expected = _events_csv(program_run / "events.csv")
    driver = calibration.driver()
    first = driver.step()
    assert _as_row(first) == expected[0]
    stable = driver.run(until="stable")
    assert stable.kind == "stable"
    assert _as_row(stable) == expected[stable.index - 1]
    half = 0.5 * driver.friction_coefficient * driver.normal_load
    reached = driver.run(until=half)
    assert reached.force >= half
    assert _as_row(reached) == expected[reached.index - 1]
    last = driver.run()
    assert _as_row(last) == expected[-1]
    assert driver.step() is None
    assert driver.run() is None


def test_run_writes_the_programs_tables(calibration, program_run, tmp_path):
    paths = precursors.run(calibration, tmp_path / "out")
    names = [Path(p).name for p in paths]
    assert names == ["events.csv", "curve.csv", "contact_map.csv"]
    for name in names:
        assert (tmp_path / "out" / name).read_bytes() == (program_run / name).read_bytes(), name
    assert not list((tmp_path / "out").glob("*.partial"))


def test_events_have_the_attributes_of_their_kind(calibration):
    driver = calibration.driver()
    seen = {}
    for event in driver:
        seen.setdefault(event.kind, event)
    rupture = seen["rupture"]
    assert rupture.site == rupture.iy * driver.shape[1] + rupture.ix
    assert rupture.energy > 0 and math.isfinite(rupture.force)
    assert seen["stable"].ruptures is not None and seen["stable"].site is None
    assert seen["global_slip"].force > 0
    assert "kind='rupture'" in repr(rupture) and "ix=" in repr(rupture)
    assert rupture == rupture and rupture != seen["stable"]

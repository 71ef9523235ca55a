"""A driver's state: running, at global slip, or failed (issue 45 item 1)."""

import pytest

import precursors
from precursors import NotConvergedError, PrecursorsError

# One conjugate-gradient iteration per linear solve cannot reach the solver's tolerance:
# the first equilibrium fails (the scene of tests/driver.rs `failing_scene`).
FAILING = {
    "block": {"lx": 0.020, "ly": 0.004, "lz": 0.010},
    "normal_load": 100.0,
    "solver": {"backend": "spectral", "max_linear_iterations": 1},
}

SMALL = {"block": {"lx": 0.010, "ly": 0.004, "lz": 0.010}, "normal_load": 100.0}


def test_a_new_driver_is_running():
    driver = precursors.Scene.from_dict(SMALL).driver()
    assert driver.state == "running"
    assert driver.event_count == 0


def test_a_driver_at_global_slip_says_so_and_steps_give_none():
    driver = precursors.Scene.from_dict(SMALL).driver()
    kinds = []
    for event in driver:
        kinds.append(event.kind)
        expected = "global_slip" if event.kind == "global_slip" else "running"
        assert driver.state == expected, event.index
    assert kinds[0] == "stable" and kinds[-1] == "global_slip"
    assert driver.step() is None
    assert driver.state == "global_slip"


def test_a_failed_driver_says_so_and_raises_again():
    driver = precursors.Scene.from_dict(FAILING).driver()
    assert driver.state == "running"
    with pytest.raises(NotConvergedError) as first:
        driver.step()
    assert first.value.kind == "SolverNotConverged"
    assert driver.state == "failed"
    for _ in range(2):
        with pytest.raises(PrecursorsError) as again:
            driver.step()
        assert again.value.kind == "DriverFailed"
        assert str(first.value) in str(again.value)
    # Iteration raises too: a failed driver never ends as a finished one does.
    with pytest.raises(PrecursorsError) as iterated:
        next(iter(driver))
    assert iterated.value.kind == "DriverFailed"
    assert driver.state == "failed"

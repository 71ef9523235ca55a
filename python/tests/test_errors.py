"""Errors: the crate's typed errors as the package's exceptions, with its messages."""

import errno
import json

import pytest

import precursors
from precursors import (
    NotConvergedError,
    PrecursorsError,
    PrecursorsOSError,
    PrecursorsValueError,
)


def test_classes():
    assert issubclass(PrecursorsValueError, PrecursorsError)
    assert issubclass(PrecursorsValueError, ValueError)
    assert issubclass(PrecursorsOSError, PrecursorsError)
    assert issubclass(PrecursorsOSError, OSError)
    assert issubclass(NotConvergedError, PrecursorsError)


def test_value_out_of_range_names_its_key():
    with pytest.raises(ValueError) as raised:
        precursors.Scene(block=(1e308, 0.007, 0.075))
    error = raised.value
    assert isinstance(error, PrecursorsValueError)
    assert error.kind == "OutOfRange"
    assert "block.lx" in str(error) and "valid range" in str(error)


def test_negative_length():
    with pytest.raises(PrecursorsValueError) as raised:
        precursors.Scene(block=(-0.14, 0.007, 0.075))
    assert "0.14" in str(raised.value)


def test_unknown_key_of_a_dict_is_refused():
    with pytest.raises(PrecursorsValueError) as raised:
        precursors.Scene.from_dict({"normal_lod": 10.0})
    assert raised.value.kind == "SceneFile"
    assert "normal_lod" in str(raised.value)


def test_unknown_keyword_is_a_type_error():
    with pytest.raises(TypeError):
        precursors.Scene(normal_lod=10.0)


def test_missing_file_is_an_os_error_with_its_cause():
    with pytest.raises(OSError) as raised:
        precursors.Scene.from_file("/nonexistent/scene.json")
    error = raised.value
    assert isinstance(error, PrecursorsOSError) and error.kind == "Io"
    assert "/nonexistent/scene.json" in str(error)
    assert "No such file" in str(error)  # the cause, from source()


def test_checkpoint_of_garbage_bytes():
    with pytest.raises(PrecursorsValueError):
        precursors.Checkpoint.from_bytes(b"\xff\xfe not json")
    with pytest.raises(PrecursorsValueError):
        precursors.Checkpoint.from_bytes(b"{}")


def test_checkpoint_of_another_scene(calibration):
    other = precursors.Scene(
        block=(0.010, 0.004, 0.010), cells=(10, 4), normal_load=40.0, seed=2
    )
    checkpoint = other.driver().checkpoint()
    with pytest.raises(PrecursorsValueError) as raised:
        calibration.resume(checkpoint)
    assert raised.value.kind == "CheckpointSceneMismatch"


def test_run_into_a_file_is_an_os_error(calibration, tmp_path):
    target = tmp_path / "a-file"
    target.write_text("x")
    with pytest.raises(OSError) as raised:
        precursors.run(calibration, target)
    assert isinstance(raised.value, PrecursorsError)
    assert "a-file" in str(raised.value)


def test_bad_until_and_threads(calibration):
    driver = calibration.driver()
    with pytest.raises(ValueError):
        driver.run(until="slip")
    with pytest.raises(ValueError):
        driver.run(until=float("nan"))
    with pytest.raises(PrecursorsValueError) as raised:
        precursors.Scene(cells=(10, 4), block=(0.010, 0.004, 0.010), normal_load=40.0,
                         backend="dense").driver(threads=2)
    assert raised.value.kind == "DenseThreads"


def test_sweep_file_errors(tmp_path):
    bad = tmp_path / "sweep.json"
    bad.write_text(json.dumps({"base": {}, "axes": [{"key": "no.such.key", "values": [1]}]}))
    with pytest.raises(PrecursorsValueError):
        precursors.sweep(bad, tmp_path / "out")
    with pytest.raises(PrecursorsOSError) as raised:
        precursors.sweep(tmp_path / "missing.json", tmp_path / "out")
    assert raised.value.errno is None or raised.value.errno == errno.ENOENT

"""Errors: the crate's typed errors as the package's exceptions, with its messages."""

import errno
import json

import numpy as np
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


def test_a_block_in_millimetres_is_refused_unless_confirmed():
    # 140 x 7 x 75 typed for millimetres: a 140 m block under 3.6 Pa (issue 56).
    for keywords in ({"cell_size": (1, 1)}, {"cells": (140, 7)}):
        with pytest.raises(PrecursorsValueError) as raised:
            precursors.Scene(block=(140, 7, 75), **keywords)
        assert raised.value.kind == "LikelyMillimetres"
        message = str(raised.value)
        assert "140 x 7 x 75 mm" in message and "confirm_metres" in message
    scene = precursors.Scene(block=(140, 7, 75), cells=(140, 7), confirm_metres=True)
    assert scene.to_dict()["confirm_metres"] is True
    with pytest.raises(TypeError):
        precursors.Scene(block=(140, 7, 75), cells=(140, 7), confirm_metres="yes")


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


# Issue 45, item 10: first contact. Messages in Python's terms, arrays of the wrong shape
# refused with the shape expected.

SMALL = dict(block=(0.010, 0.004, 0.010), normal_load=10.0)


def test_transposed_heights_are_refused_with_the_expected_shape():
    with pytest.raises(PrecursorsValueError) as raised:
        precursors.Scene(cells=(50, 10), heights=np.full((50, 10), 1e-6), **SMALL)
    assert raised.value.kind == "ShapeMismatch"
    message = str(raised.value)
    assert "(Ny, Nx) = (10, 50)" in message and "(50, 10)" in message


def test_flat_heights_are_refused_with_the_expected_shape():
    # The grid from cell_size: known only to the crate.
    with pytest.raises(PrecursorsValueError) as raised:
        precursors.Scene(cell_size=(0.001, 0.001), heights=np.full(40, 1e-6), **SMALL)
    assert "(Ny, Nx) = (4, 10)" in str(raised.value) and "(40,)" in str(raised.value)


def test_heights_of_the_right_shape_are_accepted():
    scene = precursors.Scene(cells=(10, 4), heights=np.full((4, 10), 1e-6), **SMALL)
    assert scene.shape == (4, 10)


def test_nan_heights_name_their_row_and_column():
    heights = np.full((4, 10), 1e-6)
    heights[2, 3] = np.nan
    with pytest.raises(PrecursorsValueError) as raised:
        precursors.Scene(cells=(10, 4), heights=heights, **SMALL)
    message = str(raised.value)
    assert "heights[2, 3] = nan" in message
    assert "line" not in message and "column" not in message


@pytest.mark.parametrize(
    "keywords, words",
    [
        (dict(normal_load="3500"), "normal_load must be a number (float), not str"),
        (dict(cells=(10.5, 2)), "cells[0] must be an int, not float"),
        (dict(block=(0.01, 0.004)), "block must be (lx, ly, lz)"),
        (dict(seed=1.5), "seed must be an int, not float"),
    ],
)
def test_keyword_types_are_named_in_python_terms(keywords, words):
    with pytest.raises(TypeError) as raised:
        precursors.Scene(**keywords)
    message = str(raised.value)
    assert words in message
    assert "scene file" not in message and "usize" not in message and "f64" not in message


@pytest.mark.parametrize(
    "keywords, words",
    [
        (dict(normal_load=float("nan")), "normal_load = nan is not a finite number"),
        (dict(backend="gpu"), "backend = 'gpu' is not one of"),
        (dict(drive="sideways"), "drive = 'sideways' is not one of"),
        (dict(cells=(-1, 2)), "cells[0] = -1 is invalid"),
    ],
)
def test_keyword_values_are_named_in_python_terms(keywords, words):
    with pytest.raises(PrecursorsValueError) as raised:
        precursors.Scene(**keywords)
    message = str(raised.value)
    assert words in message
    assert "scene file" not in message and "line 1" not in message


def test_millimetres_ask_whether_metres_were_meant():
    with pytest.raises(PrecursorsValueError) as raised:
        precursors.Scene(block=(140, 7, 75))
    assert raised.value.kind == "LengthInMillimetres"
    assert "did you mean 0.14 m?" in str(raised.value)


def test_stresses_without_probes_name_the_python_keywords(calibration):
    driver = calibration.driver()
    driver.step()
    with pytest.raises(PrecursorsValueError) as raised:
        driver.stresses()
    message = str(raised.value)
    assert "probe_planes" in message and "add_probes" in message
    assert "SceneBuilder" not in message


def test_plot_of_a_missing_directory_is_an_os_error(tmp_path):
    missing = tmp_path / "nosuchdir"
    with pytest.raises(PrecursorsOSError) as raised:
        precursors.plot(missing)
    assert raised.value.kind == "Io"
    assert "nosuchdir" in str(raised.value) and "No such file" in str(raised.value)


def test_help_lists_the_scene_keywords():
    signature = precursors.Scene.__text_signature__ or ""
    for keyword in ("block", "cells", "normal_load", "heights", "seed", "probe_planes"):
        assert keyword in signature
    assert "heights=array of shape (Ny, Nx)" in (precursors.Scene.__doc__ or "")


# Issue 42: the CUDA backend. The package is built without it (python/Cargo.toml), so a
# scene asking for it is refused, typed, with what to do instead.


def test_cuda_backend_reaches_the_crate_and_is_refused_typed():
    from precursors import CudaUnavailableError

    assert issubclass(CudaUnavailableError, PrecursorsError)
    assert issubclass(CudaUnavailableError, RuntimeError)
    scene = precursors.Scene(cells=(10, 4), block=(0.010, 0.004, 0.010), normal_load=40.0,
                             backend="cuda")
    assert scene.to_dict()["solver"]["backend"] == "cuda"
    with pytest.raises(CudaUnavailableError) as raised:
        scene.driver()
    error = raised.value
    assert error.kind == "CudaUnavailable"
    message = str(error)
    assert "CUDA backend is unavailable" in message
    assert "feature `cuda`" in message and "--features cli,cuda" in message
    assert "Python package is built without the CUDA backend" in message


def test_an_unknown_backend_lists_cuda():
    with pytest.raises(PrecursorsValueError) as raised:
        precursors.Scene(backend="gpu")
    assert "'cuda'" in str(raised.value)


def test_a_recording_above_its_output_limit_is_refused_unless_raised():
    # Profiles at 1000 loads on 1000 planes of the calibration block: about 10 GB of
    # profiles.csv, above the default limit of 1e10 B (issue 53).
    loads = [k / 1000 for k in range(1000)]
    planes = [0.01 + 0.06 * k / 1000 for k in range(1000)]
    with pytest.raises(PrecursorsValueError) as raised:
        precursors.Scene(profile_loads=loads, profile_planes=planes)
    assert raised.value.kind == "OutputTooLarge"
    assert "max_output_bytes" in str(raised.value)
    scene = precursors.Scene(profile_loads=loads, profile_planes=planes, max_output_bytes=1e11)
    assert scene.to_dict()["max_output_bytes"] == 1e11
    with pytest.raises(TypeError):
        precursors.Scene(max_output_bytes="10 GB")

"""Random surfaces from keywords (issue 28): `Scene(surface=SurfaceSpectrum..., seed=n,
height_distribution=(mean, std_dev))` mirrors the crate's `Heights::random_surface`.

The keywords must give the scene file's `gaussian_surface` / `self_affine_surface` kinds
(the crate parses and validates them; the heights' values are tested in Rust against an
independent computation, tests/surfaces.rs): checked here through the crate's own
round trip, `Scene.to_dict()` of the keyword scene against that of the dict written by
hand from docs/scene-format.md."""

import pytest

import precursors
from precursors import SurfaceSpectrum

# An 8 x 4 x 5 mm block of 2 mm cells, sheared on its top (the default rod does not fit).
SMALL = dict(block=(0.008, 0.004, 0.005), cells=(4, 2), normal_load=10.0, drive="top")
SMALL_DICT = {
    "block": {"lx": 0.008, "ly": 0.004, "lz": 0.005},
    "cells": {"kind": "count", "nx": 4, "ny": 2},
    "normal_load": 10.0,
    "drive": {"kind": "top"},
}


def test_gaussian_surface_keywords_are_the_scene_files_kind() -> None:
    scene = precursors.Scene(**SMALL, surface=SurfaceSpectrum.gaussian(2e-3), seed=7)
    heights = scene.to_dict()["heights"]
    assert heights == {"kind": "gaussian_surface", "correlation_length": 2e-3,
                       "mean": 1e-6, "std_dev": 1e-6, "seed": 7}
    by_dict = precursors.Scene.from_dict(
        {**SMALL_DICT, "heights": {"kind": "gaussian_surface", "correlation_length": 2e-3,
                                   "seed": 7}})
    assert scene.to_dict() == by_dict.to_dict()


def test_self_affine_surface_and_distribution_keywords_are_the_scene_files_kind() -> None:
    spectrum = SurfaceSpectrum.self_affine(0.7, 3e-3, 0.6e-3, 5e-3)
    scene = precursors.Scene(**SMALL, surface=spectrum, height_distribution=(2e-6, 5e-7),
                             seed=11)
    heights = scene.to_dict()["heights"]
    assert heights == {"kind": "self_affine_surface", "hurst": 0.7, "roll_off": 3e-3,
                       "short_cutoff": 0.6e-3, "long_cutoff": 5e-3, "mean": 2e-6,
                       "std_dev": 5e-7, "seed": 11}
    assert spectrum == SurfaceSpectrum.self_affine(0.7, 3e-3, 0.6e-3, 5e-3)
    assert spectrum != SurfaceSpectrum.gaussian(3e-3)
    assert repr(SurfaceSpectrum.gaussian(3e-3)) == (
        "SurfaceSpectrum.gaussian(correlation_length=0.003)")
    # The paper's white noise takes the distribution keyword too.
    white = precursors.Scene(**SMALL, seed=1, height_distribution=(5e-6, 2e-6))
    assert white.to_dict()["heights"] == {"kind": "gaussian", "mean": 5e-6, "std_dev": 2e-6,
                                          "seed": 1}


def test_bad_surface_keywords_are_refused() -> None:
    with pytest.raises(precursors.PrecursorsValueError, match="correlation_length"):
        precursors.Scene(**SMALL, surface=SurfaceSpectrum.gaussian(-1e-3), seed=1)
    with pytest.raises(precursors.PrecursorsValueError, match="hurst"):
        precursors.Scene(**SMALL, surface=SurfaceSpectrum.self_affine(1.5, 3e-3, 1e-3, 5e-3))
    with pytest.raises(TypeError, match="SurfaceSpectrum"):
        precursors.Scene(**SMALL, surface={"kind": "gaussian_surface"})  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="heights=array"):
        precursors.Scene(**SMALL, heights=[[1e-6] * 4] * 2,
                         surface=SurfaceSpectrum.gaussian(2e-3))

"""Maps of μ, c_x and c_z from keywords (issue 55): `Scene(friction_map=..., c_x_map=...,
c_z_map=...)` gives the scene file's `maps` (an array as `values` in cell order, a dict as
written). The maps' physics is tested in Rust (tests/maps.rs); here the keywords' form,
the refusals and one run: a uniform friction map gives the scalar scene's events."""

import numpy as np
import pytest

import precursors
from precursors import PrecursorsValueError

# An 8 x 4 x 5 mm block of 2 mm cells, sheared on its top (the default rod does not fit).
SMALL = dict(block=(0.008, 0.004, 0.005), cells=(4, 2), normal_load=10.0, drive="top")


def test_an_array_is_the_maps_values_in_cell_order() -> None:
    mu = np.array([[0.4, 0.5, 0.6, 0.7], [0.3, 0.35, 0.45, 0.55]])
    scene = precursors.Scene(**SMALL, friction_map=mu)
    maps = scene.to_dict()["maps"]
    assert maps == {"friction_coefficient": {"kind": "values", "values": list(mu.ravel())}}


def test_a_dict_is_the_scene_files_map() -> None:
    surface = {"kind": "gaussian_surface", "correlation_length": 2e-3, "mean": 1.65e12,
               "std_dev": 3e11, "seed": 5}
    scene = precursors.Scene(**SMALL, c_x_map=surface)
    assert scene.to_dict()["maps"] == {"c_x": surface}


def test_a_uniform_friction_map_gives_the_scalar_scenes_events() -> None:
    def events(scene: precursors.Scene) -> list:
        return [(e.kind, e.site, e.force) for e in scene.driver()]

    scalar = precursors.Scene(**SMALL, seed=3)
    mapped = precursors.Scene(**SMALL, seed=3, friction_map=np.full((2, 4), 0.5),
                              c_z_map=np.full((2, 4), 1.65e8))
    assert events(scalar) == events(mapped)


def test_bad_maps_are_refused() -> None:
    with pytest.raises(PrecursorsValueError) as raised:
        precursors.Scene(**SMALL, c_z_map=np.full((4, 2), 1.65e8))
    assert raised.value.kind == "ShapeMismatch"
    assert "c_z_map" in str(raised.value) and "(Ny, Nx) = (2, 4)" in str(raised.value)
    with pytest.raises(PrecursorsValueError) as raised:
        precursors.Scene(**SMALL, friction_map=np.array([[0.5, 0.5, -1.0, 0.5]] * 2))
    assert raised.value.kind == "MapValue"
    with pytest.raises(PrecursorsValueError) as raised:
        precursors.Scene(**SMALL, c_x_map=np.full((2, 4), 1e30))
    assert raised.value.kind == "MapValue" and "maps.c_x[0]" in str(raised.value)
    with pytest.raises(TypeError):
        precursors.Scene(**SMALL, c_x_map="uniform")


def test_the_friction_limit_is_the_largest_friction_coefficient() -> None:
    assert precursors.Scene(**SMALL).driver().friction_limit == 0.5 * 10.0
    mu = np.full((2, 4), 0.3)
    mu[1, 2] = 0.8
    driver = precursors.Scene(**SMALL, friction_map=mu).driver()
    assert driver.friction_limit == 0.8 * 10.0 and driver.friction_coefficient == 0.5

"""The state between events as arrays: shape (Ny, Nx), row iy and column ix, values.

Independent sides: the program's `contact_map.csv` and `curve.csv` (the column contact
areas and A_R, ℓ of each stable state), the events' sites, the scene file's heights in
the cell order i = iy*Nx + ix, and the normal equilibrium (the tractions carry F_N)."""

import numpy as np

import precursors
from precursors import read_table
from test_events import table_value

_table = np.vectorize(table_value, otypes=[np.float64])


def test_arrays_are_float64_copies_shaped_ny_nx(calibration):
    driver = calibration.driver()
    driver.run(until="stable")
    ny, nx = driver.shape
    assert (ny, nx) == calibration.shape == (7, 140)
    for name in (
        "normal_traction",
        "shear_traction",
        "normal_displacement",
        "shear_displacement",
        "cell_contact_area",
        "breaking_loads",
    ):
        a = getattr(driver, name)
        assert a.shape == (ny, nx) and a.dtype == np.float64, name
        a[...] = np.nan  # a copy: the driver's state does not change
        assert not np.isnan(getattr(driver, name)).any(), name  # (inf: a site that cannot break)
    assert driver.column_contact_area.shape == (nx,)
    assert driver.site_states.shape == (ny, nx) and driver.site_states.dtype == np.uint8


def test_column_areas_and_curve_match_the_program(calibration, program_run):
    driver = calibration.driver()
    nx = driver.shape[1]
    columns, cells, curve = {}, {}, {}
    for event in driver:
        if event.kind == "stable":
            columns[event.index] = driver.column_contact_area
            cells[event.index] = driver.cell_contact_area
            curve[event.index] = (driver.real_contact_area, driver.precursor_length)
    table = read_table(program_run / "contact_map.csv")
    assert len(table["event"]) > 100
    for row, index in enumerate(table["event"].astype(int)):
        want = np.array([table[f"area_m2_ix{ix}"][row] for ix in range(nx)])
        # Every digit the table holds (13 significant).
        assert np.array_equal(_table(columns[index]), want)
        # Summing the (Ny, Nx) map over its rows (y) gives the columns: orientation.
        np.testing.assert_allclose(cells[index].sum(axis=0), want, rtol=1e-11, atol=0)
    table = read_table(program_run / "curve.csv")
    for row, index in enumerate(table["event"].astype(int)):
        want = (table["real_contact_area_m2"][row], table["precursor_length_m"][row])
        assert tuple(table_value(v) for v in curve[index]) == want


def test_ruptured_site_is_broken_at_row_iy_column_ix(calibration):
    driver = calibration.driver()
    ruptures = 0
    for event in driver:
        if event.kind == "rupture":
            states = driver.site_states
            assert states[event.iy, event.ix] == precursors.BROKEN
            assert states.ravel()[event.site] == precursors.BROKEN
            ruptures += 1
            if ruptures == 50:
                break
    assert ruptures == 50


def test_tractions_carry_the_normal_load(calibration):
    driver = calibration.driver()
    driver.run(until="stable")
    dx, dy = calibration.cell_size
    total = driver.normal_traction.sum() * dx * dy
    np.testing.assert_allclose(total, calibration.normal_load, rtol=1e-8)
    np.testing.assert_allclose(
        driver.cell_contact_area.sum(), driver.real_contact_area, rtol=1e-12
    )


def test_heights_array_is_row_iy_column_ix():
    ny, nx = 3, 10
    heights = 1e-6 * (1.0 + np.arange(ny * nx, dtype=np.float64).reshape(ny, nx) / 30.0)
    scene = precursors.Scene(
        block=(0.010, 0.003, 0.010), cells=(nx, ny), normal_load=10.0, heights=heights
    )
    assert scene.shape == (ny, nx)
    values = np.array(scene.to_dict()["heights"]["values"])
    # The file's cell order i = iy*Nx + ix (docs/scene-format.md).
    for iy in range(ny):
        for ix in range(nx):
            assert values[iy * nx + ix] == heights[iy, ix]


def test_stress_probes_on_planes_and_points(calibration):
    driver = calibration.driver()
    driver.run(until="stable")
    lx, ly, lz = calibration.block
    driver.add_probes(planes=[0.0, 0.004], points=[(0.07, 0.0035, 0.004)])
    stresses = driver.stresses()
    z0, z4 = stresses["planes"]
    assert (z0.z, z4.z) == (0.0, 0.004)
    assert z0.shear.shape == z0.normal.shape == z0.coulomb.shape == driver.shape
    profile = z4.profile()
    assert profile["shear"].shape == (driver.shape[1],)
    nx = driver.shape[1]
    np.testing.assert_allclose(profile["x"], (np.arange(nx) + 0.5) * lx / nx, rtol=1e-12)
    np.testing.assert_allclose(profile["normal"], z4.normal.mean(axis=0), rtol=1e-12, atol=1e-9)
    (point,) = stresses["points"]
    assert point.point == (0.07, 0.0035, 0.004)
    # At the interface the plane's normal stress is the normal traction (sign aside).
    scale = np.abs(driver.normal_traction).max()
    np.testing.assert_allclose(np.abs(z0.normal), np.abs(driver.normal_traction), atol=1e-6 * scale)

"""Avalanches, the damage front and their statistics from Python: the same tables and fits
as the program's (`precursors stats`), and the fit recovering known exponents."""

import numpy as np
import pytest

import precursors

from conftest import run_program


def test_a_run_derives_its_avalanches_and_fronts(calibration, tmp_path):
    precursors.run(calibration, tmp_path)
    tables = precursors.read_tables(tmp_path)
    avalanches, fronts = tables["per_avalanche"], tables["fronts"]
    # Every spring breaks once, in some avalanche; the last ends in global slip.
    assert avalanches["ruptures"].sum() == 140 * 7
    assert avalanches["global_slip"][-1] == 1 and avalanches["global_slip"][:-1].sum() == 0
    # One front per stable state; beyond F/(μF_N) = 0.1 never behind ℓ in this run (the
    # area law lifts ℓ's columns, not their count of contacts; below, ℓ's first column
    # falls under its zero-shear area before half its contacts are gone).
    curve = tables["curve"]
    assert np.array_equal(fronts["event"], curve["event"])
    late = fronts["force_over_mu_FN"] > 0.1
    assert np.all(fronts["damage_front_over_Lx"][late] >= fronts["precursor_over_Lx"][late])


def test_stats_are_the_programs(program_run, tmp_path):
    # The program's run, copied: stats writes its tables beside the run's.
    import shutil

    run = tmp_path / "run"
    shutil.copytree(program_run, run)
    ours = precursors.stats(run, bootstrap=20, goodness=20, seed=3)
    fits = ours["power_laws"]
    assert list(fits["observable"][:1]) == ["avalanche_ruptures"]
    theirs = tmp_path / "theirs"
    shutil.copytree(program_run, theirs)
    run_program(
        "stats", str(theirs), "--bootstrap", "20", "--goodness", "20", "--seed", "3", "--quiet"
    )
    for name in ("power_laws.csv", "distributions.csv"):
        assert (run / name).read_bytes() == (theirs / name).read_bytes(), name


def test_the_fit_recovers_a_known_exponent():
    # Inverse-transform samples of p(x) ∝ x^-2.5 on x >= 1, drawn by numpy (independent
    # of the crate's own sampler).
    rng = np.random.default_rng(7)
    samples = (1.0 - rng.random(3000)) ** (-1.0 / 1.5)
    fit = precursors.fit_power_law(samples, discrete=False, bootstrap=50, goodness=0)
    assert fit["alpha_low"] <= 2.5 <= fit["alpha_high"]
    assert abs(fit["alpha"] - 2.5) < 4 * fit["alpha_std_error"]
    assert fit["p_value"] is None
    with pytest.raises(precursors.PrecursorsValueError, match="samples"):
        precursors.fit_power_law([1.0, 2.0], discrete=True)


def test_profiles_at_requested_loads(tmp_path):
    # Keywords map onto the scene file's key `profiles`; the run writes profiles.csv and
    # read_tables reads it: per load passed, 3 interface rows and 4 per plane.
    scene = precursors.Scene(
        block=(0.02, 0.004, 0.01),
        cell_size=(1e-3, 1e-3),
        normal_load=300.0,
        seed=5,
        profile_loads=[0.8, 0.2, 0.5],
        profile_planes=[0.002],
    )
    # The loads kept in increasing order.
    assert scene.to_dict()["profiles"] == {"loads": [0.2, 0.5, 0.8], "planes": [0.002]}
    precursors.run(scene, tmp_path)
    profiles = precursors.read_tables(tmp_path)["profiles"]
    levels = list(dict.fromkeys(profiles["level"]))
    assert levels == [0.2, 0.5, 0.8]
    assert len(profiles["field"]) == 3 * 7
    assert list(profiles["field"][:7]) == [
        "slip_m",
        "shear_traction_Pa",
        "normal_traction_Pa",
        "shear_Pa",
        "normal_Pa",
        "coulomb_of_means_Pa",
        "mean_coulomb_Pa",
    ]
    # The mean slip grows with the load.
    slip = np.array([[profiles[f"value_ix{ix}"][7 * k] for ix in range(20)] for k in range(3)])
    assert np.all(np.diff(slip.mean(axis=1)) > 0)
    with pytest.raises(TypeError, match="profile_loads"):
        precursors.Scene(profile_planes=[0.002])

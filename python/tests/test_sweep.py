"""run, sweep, merge and plot from Python: the program's directories and tables."""

import json

import numpy as np

import precursors

SMALL = {
    "block": {"lx": 0.010, "ly": 0.004, "lz": 0.010},
    "cells": {"kind": "count", "nx": 10, "ny": 4},
    "normal_load": 40.0,
}


def test_sweep_merge_and_plot(tmp_path):
    study = tmp_path / "study.json"
    study.write_text(
        json.dumps(
            {
                "base": SMALL,
                "axes": [{"key": "normal_load", "values": [30.0, 40.0]}],
                "realizations": 2,
                "seed": 1,
            }
        )
    )
    out = tmp_path / "out"
    summary = precursors.sweep(study, out, jobs=2)
    assert summary["runs"] == 4 and summary["completed"] == 4
    tables = precursors.merge(out)
    assert {"curves", "slip", "runs"} <= set(tables)
    runs = tables["runs"]
    assert all(isinstance(v, np.ndarray) for v in runs.values())
    assert len(next(iter(runs.values()))) == 4
    figures = precursors.plot(out, formats=["png", "svg"])
    assert figures and all(f.is_file() for f in figures)
    assert {f.suffix for f in figures} == {".png", ".svg"}


def test_run_directory_tables_and_figures(tmp_path):
    scene = precursors.Scene.from_dict(SMALL)
    precursors.run(scene, tmp_path)
    tables = precursors.read_tables(tmp_path)
    assert set(tables) == {"events", "curve", "contact_map", "per_avalanche", "fronts"}
    assert tables["events"]["kind"][-1] == "global_slip"
    assert tables["curve"]["force_over_mu_FN"].dtype == np.float64
    figures = precursors.plot(tmp_path)
    assert [f.suffix for f in figures] == [".png"] * len(figures) and figures


def test_keywords_and_dict_give_the_same_scene():
    a = precursors.Scene(block=(0.010, 0.004, 0.010), cells=(10, 4), normal_load=40.0, seed=3,
                         friction_coefficient=0.4, c_z=2e8, drive="side", threads=1)
    b = precursors.Scene.from_dict(
        {
            **SMALL,
            "heights": {"kind": "gaussian", "seed": 3},
            "material": {"friction_coefficient": 0.4},
            "springs": {"c_z": 2e8},
            "drive": {"kind": "side"},
        }
    )
    assert a.to_json() == b.to_json()
    assert precursors.Scene.from_json(a.to_json()).to_json() == a.to_json()
    info = a.info()
    assert (info["nx"], info["ny"], info["cells"]) == (10, 4, 40)
    assert info["memory_bytes"] > 0 and info["plan_seconds"] > 0
    assert "10 x 4 cells" in repr(a)
    assert "Driver(10 x 4 cells" in repr(a.driver())

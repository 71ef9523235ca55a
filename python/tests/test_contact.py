"""The contact rules as scene keywords (issue 55): the scene file's key `contact`, the
rules' events (the paper's sites break once, re-formed ones break again), and refusals in
Python's terms or naming the key."""

import pytest

import precursors
from precursors import PrecursorsValueError

# 16 x 4 cells: a run to global slip takes well under a second.
SMALL = dict(block=(0.016, 0.004, 0.010), cells=(16, 4), normal_load=60.0, seed=1)


def ruptures(scene: precursors.Scene) -> int:
    return sum(event.kind == "rupture" for event in scene.driver())


def test_the_keywords_are_the_scene_files_contact_key():
    assert "contact" not in precursors.Scene(**SMALL).to_dict()
    assert "contact" not in precursors.Scene(**SMALL, contact_rule="paper").to_dict()
    anchored = precursors.Scene(**SMALL, contact_rule="anchored")
    assert anchored.to_dict()["contact"] == {"rule": "anchored"}
    assert anchored.info()["contact_rule"] == "anchored"
    assert precursors.Scene(**SMALL).info()["contact_rule"] == "paper"
    rejuvenation = precursors.Scene(
        **SMALL, contact_rule="rejuvenation", delay_stable_states=3, delay_load=0.02
    )
    assert rejuvenation.to_dict()["contact"] == {
        "rule": "rejuvenation",
        "delay": {"stable_states": 3, "load": 0.02},
    }
    # The defaults of the delay: one stable state and no load.
    default = precursors.Scene(**SMALL, contact_rule="rejuvenation").to_dict()
    assert default["contact"]["delay"] == {"stable_states": 1, "load": 0.01}


def test_only_re_formed_sites_break_again():
    sites = 16 * 4
    # The paper's and the anchored rule: every spring breaks once, at global slip the last.
    assert ruptures(precursors.Scene(**SMALL)) == sites
    assert ruptures(precursors.Scene(**SMALL, contact_rule="anchored")) == sites
    # Re-formed sites break again.
    scene = precursors.Scene(
        **SMALL, contact_rule="rejuvenation", delay_stable_states=3, delay_load=0.02
    )
    assert ruptures(scene) > sites


def test_bad_rules_and_delays_are_refused():
    with pytest.raises(PrecursorsValueError) as raised:
        precursors.Scene(**SMALL, contact_rule="custom")
    assert raised.value.kind == "InvalidChoice"
    with pytest.raises(TypeError):
        precursors.Scene(**SMALL, contact_rule=1)
    with pytest.raises(TypeError):
        precursors.Scene(**SMALL, contact_rule="anchored", delay_stable_states=2)
    with pytest.raises(TypeError):
        precursors.Scene(**SMALL, delay_load=0.1)
    with pytest.raises(PrecursorsValueError) as raised:
        precursors.Scene(**SMALL, contact_rule="rejuvenation", delay_stable_states=0)
    assert raised.value.kind == "InvalidCount"
    assert "contact.delay.stable_states" in str(raised.value)
    with pytest.raises(PrecursorsValueError) as raised:
        precursors.Scene(**SMALL, contact_rule="rejuvenation", delay_load=-0.5)
    assert "contact.delay.load" in str(raised.value)
    # Under a spring drive sites could re-form for ever: refused, naming the key.
    with pytest.raises(PrecursorsValueError) as raised:
        precursors.Scene(
            **SMALL,
            contact_rule="rejuvenation",
            drive={"kind": "spring", "stiffness": 4e6, "lateral": {"kind": "side"}},
        )
    assert "contact.rule" in str(raised.value)

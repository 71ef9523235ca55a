"""The package's namespace: its own names only (issue 56 found ``Any``, ``Dict``,
``Path``, ``Union`` and ``np`` in ``dir(precursors)``)."""

import precursors


def test_dir_lists_the_public_names_only():
    public = sorted(n for n in dir(precursors) if not n.startswith("_"))
    assert public == sorted(n for n in precursors.__all__ if not n.startswith("_"))
    for name in precursors.__all__:
        assert hasattr(precursors, name), name

"""Figure size and movies from Python: the program's `plot --width/--height` and `movie`."""

import struct

import pytest

import precursors

SMALL = {
    "block": {"lx": 0.010, "ly": 0.004, "lz": 0.010},
    "cells": {"kind": "count", "nx": 10, "ny": 4},
    "normal_load": 40.0,
}


def png_size(path):
    """(width, height) from a PNG's IHDR chunk (bytes 16..24, big-endian)."""
    data = path.read_bytes()
    assert data[1:4] == b"PNG"
    return struct.unpack(">II", data[16:24])


def gif_frames(path):
    """(width, height, frames) of a GIF, by walking its blocks (GIF89a specification)."""
    data = path.read_bytes()
    assert data[:6] == b"GIF89a"
    width, height, flags = struct.unpack("<HHB", data[6:11])
    at = 13 + (3 << ((flags & 7) + 1) if flags & 0x80 else 0)

    def skip_sub_blocks(at):
        while data[at] != 0:
            at += data[at] + 1
        return at + 1

    frames = 0
    while data[at] != 0x3B:
        if data[at] == 0x21:  # extension: label, then sub-blocks
            at = skip_sub_blocks(at + 2)
        elif data[at] == 0x2C:  # image: descriptor, local table, LZW code size, data
            local = data[at + 9]
            at += 10 + (3 << ((local & 7) + 1) if local & 0x80 else 0)
            at = skip_sub_blocks(at + 1)
            frames += 1
        else:
            raise AssertionError(f"unknown GIF block {data[at]:#x} at {at}")
    return width, height, frames


def test_plot_takes_the_size_asked_for_within_the_programs_limits(tmp_path):
    precursors.run(precursors.Scene.from_dict(SMALL), tmp_path)
    figures = precursors.plot(tmp_path, width=640, height=480)
    assert figures and all(png_size(f) == (640, 480) for f in figures)
    assert all(png_size(f) == (800, 560) for f in precursors.plot(tmp_path))
    # The program's limits (plot::draw_with_size): each side from 200 to 16384.
    for width, height in [(199, 480), (640, 16385), (20000, 480)]:
        with pytest.raises(precursors.PrecursorsError, match=r"must lie in \[200, 16384\]"):
            precursors.plot(tmp_path, width=width, height=height)
    assert all(png_size(f) == (200, 200) for f in precursors.plot(tmp_path, width=200, height=200))


def test_movie_draws_the_recorded_fields_as_the_program_does(tmp_path):
    scene = precursors.Scene.from_dict(
        {**SMALL, "fields": {"every": 1, "planes": [0.002, 0.006]}}
    )
    precursors.run(scene, tmp_path)
    movies = precursors.movie(tmp_path, max_frames=3, width=400, height=300)
    assert [m.name for m in movies] == ["contact_area.gif", "coulomb_stress.gif"]
    for m in movies:
        # At most 3 frames: every k-th recorded state, k the smallest that fits, and the last.
        width, height, frames = gif_frames(m)
        assert (width, height) == (400, 300) and 2 <= frames <= 3
    out = tmp_path / "s1.gif"
    assert precursors.movie(
        tmp_path, field="contact-area", every=1, max_frames=2, frame_duration=0.5, out=out
    ) == [out]
    assert gif_frames(out) == (900, 560, 2)


def test_movie_writes_its_frames_as_pngs_too(tmp_path):
    scene = precursors.Scene.from_dict(
        {**SMALL, "fields": {"every": 1, "planes": [0.002, 0.006]}}
    )
    precursors.run(scene, tmp_path)
    frames = tmp_path / "frames"
    movies = precursors.movie(
        tmp_path, max_frames=3, width=400, height=300, png_frames=frames
    )
    for m in movies:
        _, _, count = gif_frames(m)
        # One PNG per GIF frame, numbered from 0 after the GIF's stem, of the frame's size.
        pngs = sorted(frames.glob(m.stem + "_*.png"))
        assert [p.name for p in pngs] == [f"{m.stem}_{k:04d}.png" for k in range(count)]
        assert all(png_size(p) == (400, 300) for p in pngs)


def test_movie_refusals(tmp_path):
    precursors.run(precursors.Scene.from_dict(SMALL), tmp_path)
    # No fields recorded: the error says which key records them.
    with pytest.raises(precursors.PrecursorsError, match="fields"):
        precursors.movie(tmp_path)
    with pytest.raises(ValueError, match="not one of"):
        precursors.movie(tmp_path, field="area")
    with pytest.raises(ValueError, match="one movie"):
        precursors.movie(tmp_path, out=tmp_path / "a.gif")
    for keywords, words in [
        ({"every": 0}, "not 0"),
        ({"max_frames": 1}, "at least 2 frames"),
        ({"frame_duration": 0.0}, "duration"),
    ]:
        with pytest.raises(precursors.PrecursorsError, match=words):
            precursors.movie(tmp_path, field="contact-area", **keywords)


def test_plot_draws_the_figures_named(tmp_path):
    precursors.run(precursors.Scene.from_dict(SMALL), tmp_path)
    assert precursors.plot(tmp_path, formats=["svg"], figures=["contact_area"]) == [
        tmp_path / "contact_area.svg"
    ]
    with pytest.raises(precursors.PrecursorsError, match="no figure is named \"fig4\""):
        precursors.plot(tmp_path, figures=["fig4"])
    with pytest.raises(precursors.PrecursorsError, match="no stick_slip figure"):
        precursors.plot(tmp_path, figures=["stick_slip"])


def test_plot_draws_pngs_at_the_resolution_asked_for(tmp_path):
    # A figure's size is in 1/150 inch: at 300 dpi the default 800 x 560 is 1600 x 1120
    # pixels (docs/cli.md, `--dpi`); outside 50 to 1200 dpi it is refused.
    precursors.run(precursors.Scene.from_dict(SMALL), tmp_path)
    figures = precursors.plot(tmp_path, figures=["contact_area"], dpi=300)
    assert figures and all(png_size(f) == (1600, 1120) for f in figures)
    with pytest.raises(precursors.PrecursorsError, match=r"a resolution of 10 dpi"):
        precursors.plot(tmp_path, dpi=10)

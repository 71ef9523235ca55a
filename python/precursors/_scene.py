"""The keyword form of a scene, mapped onto the scene-file format (one schema: the
crate's, docs/scene-format.md), and the JSON text of a scene dict."""

import json
from typing import Any, Dict, Optional, Sequence, Tuple, Union

import numpy as np


def _plain(value: Any) -> Any:
    # numpy scalars and arrays as JSON numbers and lists.
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not a scene-file value")


def dumps(scene: Any) -> str:
    """A dict in the scene-file format as its JSON text."""
    return json.dumps(scene, default=_plain, allow_nan=True)


class SurfaceSpectrum:
    """The power spectrum of a Gaussian random surface (the crate's ``SurfaceSpectrum``;
    docs/model.md section 3.1): heights with a length scale, the same surface at every
    cell size. Give it to a scene as ``Scene(surface=SurfaceSpectrum.gaussian(3e-3),
    seed=n)``; the heights keep the truncated-Gaussian marginal (``height_distribution``).

    The values are checked when the scene is built (the crate's checks: a bad value
    raises ``PrecursorsValueError`` naming its key)."""

    __slots__ = ("_keys",)

    def __init__(self, keys: Dict[str, Any]) -> None:
        self._keys = dict(keys)

    @staticmethod
    def gaussian(correlation_length: float) -> "SurfaceSpectrum":
        """Gaussian correlation ``C(r) = exp(-r²/ξ²)`` with ``ξ = correlation_length`` (m)."""
        return SurfaceSpectrum(
            {"kind": "gaussian_surface", "correlation_length": correlation_length}
        )

    @staticmethod
    def self_affine(
        hurst: float, roll_off: float, short_cutoff: float, long_cutoff: float
    ) -> "SurfaceSpectrum":
        """Self-affine with Hurst exponent ``H`` (``S(k) ∝ k^(-2(1+H))``) between the
        roll-off wavelength ``λ_r`` and the short cut-off ``λ_s``, flat from the long
        cut-off ``λ_l`` to ``λ_r`` (wavelengths in m, ``λ_s < λ_r ≤ λ_l``)."""
        return SurfaceSpectrum(
            {
                "kind": "self_affine_surface",
                "hurst": hurst,
                "roll_off": roll_off,
                "short_cutoff": short_cutoff,
                "long_cutoff": long_cutoff,
            }
        )

    def to_dict(self) -> Dict[str, Any]:
        """The scene file's ``heights`` keys of this spectrum (without seed and
        distribution)."""
        return dict(self._keys)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, SurfaceSpectrum) and self._keys == other._keys

    def __hash__(self) -> int:
        return hash(tuple(sorted(self._keys.items())))

    def __repr__(self) -> str:
        keys = {k: v for k, v in self._keys.items() if k != "kind"}
        name = "gaussian" if self._keys["kind"] == "gaussian_surface" else "self_affine"
        args = ", ".join(f"{k}={v!r}" for k, v in keys.items())
        return f"SurfaceSpectrum.{name}({args})"


def scene_dict(
    *,
    block: Optional[Tuple[float, float, float]] = None,
    cells: Optional[Tuple[int, int]] = None,
    cell_size: Optional[Tuple[float, float]] = None,
    normal_load: Optional[float] = None,
    seed: Optional[int] = None,
    heights: Any = None,
    surface: Optional[SurfaceSpectrum] = None,
    height_distribution: Optional[Tuple[float, float]] = None,
    young_modulus: Optional[float] = None,
    poisson_ratio: Optional[float] = None,
    friction_coefficient: Optional[float] = None,
    c_x: Optional[float] = None,
    c_z: Optional[float] = None,
    drive: Union[str, Dict[str, Any], None] = None,
    rod: Optional[Tuple[float, float]] = None,
    backend: Optional[str] = None,
    threads: Union[int, str, None] = None,
    probe_planes: Optional[Sequence[float]] = None,
    probe_points: Optional[Sequence[Tuple[float, float, float]]] = None,
    profile_loads: Optional[Sequence[float]] = None,
    profile_planes: Optional[Sequence[float]] = None,
) -> Dict[str, Any]:
    """The scene-file dict of the keywords of ``precursors.Scene(...)``; a keyword left
    out is a key left out (the calibration scene's value)."""
    scene: Dict[str, Any] = {}
    if block is not None:
        lx, ly, lz = block
        scene["block"] = {"lx": lx, "ly": ly, "lz": lz}
    if cells is not None and cell_size is not None:
        raise TypeError("give cells=(nx, ny) or cell_size=(dx, dy), not both")
    if cells is not None:
        nx, ny = cells
        scene["cells"] = {"kind": "count", "nx": nx, "ny": ny}
    if cell_size is not None:
        dx, dy = cell_size
        scene["cells"] = {"kind": "size", "dx": dx, "dy": dy}
    if normal_load is not None:
        scene["normal_load"] = normal_load
    if heights is not None and seed is not None:
        raise TypeError("give heights=array or seed=n, not both")
    if heights is not None and (surface is not None or height_distribution is not None):
        raise TypeError(
            "heights=array gives the heights themselves: surface= and "
            "height_distribution= go with random heights (seed=n)"
        )
    if surface is not None and not isinstance(surface, SurfaceSpectrum):
        raise TypeError(
            f"surface= takes a SurfaceSpectrum (SurfaceSpectrum.gaussian(ξ), "
            f"SurfaceSpectrum.self_affine(H, λ_r, λ_s, λ_l)), not {type(surface).__name__}"
        )
    if seed is not None or surface is not None or height_distribution is not None:
        # Random heights: the paper's white noise, or a surface; the seed and the
        # distribution default as in a scene file.
        random: Dict[str, Any] = (
            surface.to_dict() if surface is not None else {"kind": "gaussian"}
        )
        if seed is not None:
            random["seed"] = seed
        if height_distribution is not None:
            mean, std_dev = height_distribution
            random["mean"] = mean
            random["std_dev"] = std_dev
        scene["heights"] = random
    if heights is not None:
        # (Ny, Nx), row iy and column ix: C order is the crate's cell order iy*Nx + ix.
        values = np.asarray(heights, dtype=np.float64)
        scene["heights"] = {"kind": "values", "values": values.ravel(order="C")}
    material = {
        k: v
        for k, v in (
            ("young_modulus", young_modulus),
            ("poisson_ratio", poisson_ratio),
            ("friction_coefficient", friction_coefficient),
        )
        if v is not None
    }
    if material:
        scene["material"] = material
    springs = {k: v for k, v in (("c_x", c_x), ("c_z", c_z)) if v is not None}
    if springs:
        scene["springs"] = springs
    if rod is not None and drive not in (None, "rod"):
        raise TypeError("rod=(height, half_width) goes with drive='rod'")
    if isinstance(drive, dict):
        scene["drive"] = drive
    elif rod is not None:
        height, half_width = rod
        scene["drive"] = {"kind": "rod", "height": height, "half_width": half_width}
    elif drive == "rod":
        pass  # the default drive: the paper's rod
    elif drive is not None:
        scene["drive"] = {"kind": drive}
    solver = {k: v for k, v in (("backend", backend), ("threads", threads)) if v is not None}
    if solver:
        scene["solver"] = solver
    probes: Dict[str, Any] = {}
    if probe_planes is not None:
        probes["planes"] = list(probe_planes)
    if probe_points is not None:
        probes["points"] = [list(p) for p in probe_points]
    if probes:
        scene["probes"] = probes
    if profile_planes is not None and profile_loads is None:
        raise TypeError("profile_planes= goes with profile_loads=[F/(μF_N), ...]")
    if profile_loads is not None:
        scene["profiles"] = {
            "loads": [float(x) for x in profile_loads],
            "planes": [float(z) for z in (profile_planes or [])],
        }
    return scene

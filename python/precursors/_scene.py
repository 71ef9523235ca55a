"""The keyword form of a scene, mapped onto the scene-file format (one schema: the
crate's, docs/scene-format.md), and the JSON text of a scene dict."""

import json
import math
import numbers
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from ._errors import PrecursorsValueError


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


# Keyword checks: a wrong type or a non-finite number is refused here, in the keywords'
# terms (the scene file's JSON parser would name a line and column of text the caller never
# wrote).


def _value_error(kind: str, message: str) -> PrecursorsValueError:
    error = PrecursorsValueError(message)
    error.kind = kind
    return error


def _number(name: str, value: Any) -> float:
    """A finite real number (int, float or numpy scalar)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a number (float), not {type(value).__name__}")
    number = float(value)
    if not math.isfinite(number):
        raise _value_error("NonFinite", f"{name} = {number} is not a finite number")
    return number


def _count(name: str, value: Any) -> int:
    """A whole number >= 0 (int or numpy integer)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an int, not {type(value).__name__}")
    count = int(value)
    if count < 0:
        raise _value_error("InvalidCount", f"{name} = {count} is invalid: it must be >= 0")
    return count


def _items(name: str, value: Any, size: Optional[int], what: str) -> List[Any]:
    """The items of a tuple or list (of `size` items when given)."""
    if isinstance(value, (str, bytes, dict)) or not hasattr(value, "__iter__"):
        raise TypeError(f"{name} must be {what}, not {type(value).__name__}")
    items = list(value)
    if size is not None and len(items) != size:
        raise TypeError(f"{name} must be {what}, not {len(items)} values")
    return items


def _numbers(name: str, value: Any, size: Optional[int], what: str) -> List[float]:
    items = _items(name, value, size, what)
    return [_number(f"{name}[{i}]", v) for i, v in enumerate(items)]


def _choice(name: str, value: Any, choices: Sequence[str]) -> str:
    options = ", ".join(repr(c) for c in choices)
    if not isinstance(value, str):
        raise TypeError(
            f"{name} must be a str (one of {options}), not {type(value).__name__}"
        )
    if value not in choices:
        raise _value_error("InvalidChoice", f"{name} = {value!r} is not one of {options}")
    return value


def _heights(value: Any) -> np.ndarray:
    """The heights array: numbers, each finite and > 0 (its shape is checked against the
    grid by ``Scene``)."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(
            "heights must be an array of numbers (float, m) of shape (Ny, Nx), not "
            f"{type(value).__name__}"
        ) from None
    bad = np.argwhere(~(np.isfinite(array) & (array > 0.0)))
    if len(bad):
        at = tuple(int(i) for i in bad[0])
        place = ", ".join(str(i) for i in at)
        height = array[at]
        kind = "NonFinite" if not math.isfinite(height) else "NonPositiveHeight"
        raise _value_error(
            kind,
            f"heights[{place}] = {height} is invalid: heights (m) must be finite and > 0",
        )
    return array


def _map(name: str, value: Any) -> Dict[str, Any]:
    """A map's scene-file object: a dict as given (the scene file's ``maps.KEY``), or an
    array of numbers of shape (Ny, Nx), each finite and > 0, as ``values`` in cell order
    (its shape is checked against the grid by ``Scene``, its ranges by the crate)."""
    if isinstance(value, dict):
        return value
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(
            f"{name} must be an array of numbers (float) of shape (Ny, Nx) or a dict in "
            f"the scene-file form (maps), not {type(value).__name__}"
        ) from None
    bad = np.argwhere(~(np.isfinite(array) & (array > 0.0)))
    if len(bad):
        at = tuple(int(i) for i in bad[0])
        place = ", ".join(str(i) for i in at)
        raise _value_error(
            "MapValue", f"{name}[{place}] = {array[at]} is invalid: it must be finite and > 0"
        )
    return {"kind": "values", "values": array.ravel(order="C")}


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


# The drives a string names (the others are dicts in the scene-file format).
_DRIVES = ("rod", "top", "side")

# The built-in contact rules (the scene file's `contact.rule`; a custom rule is Rust only).
_CONTACT_RULES = ("paper", "anchored", "rejuvenation")


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
    friction_map: Any = None,
    c_x_map: Any = None,
    c_z_map: Any = None,
    drive: Union[str, Dict[str, Any], None] = None,
    rod: Optional[Tuple[float, float]] = None,
    backend: Optional[str] = None,
    threads: Union[int, str, None] = None,
    probe_planes: Optional[Sequence[float]] = None,
    probe_points: Optional[Sequence[Tuple[float, float, float]]] = None,
    profile_loads: Optional[Sequence[float]] = None,
    profile_planes: Optional[Sequence[float]] = None,
    confirm_metres: Optional[bool] = None,
    max_output_bytes: Optional[float] = None,
    contact_rule: Optional[str] = None,
    delay_stable_states: Optional[int] = None,
    delay_load: Optional[float] = None,
) -> Dict[str, Any]:
    """The scene-file dict of the keywords of ``precursors.Scene(...)``; a keyword left
    out is a key left out (the calibration scene's value)."""
    scene: Dict[str, Any] = {}
    if block is not None:
        lx, ly, lz = _numbers("block", block, 3, "(lx, ly, lz): three lengths (float, m)")
        scene["block"] = {"lx": lx, "ly": ly, "lz": lz}
    if cells is not None and cell_size is not None:
        raise TypeError("give cells=(nx, ny) or cell_size=(dx, dy), not both")
    if cells is not None:
        items = _items("cells", cells, 2, "(nx, ny): two counts (int)")
        nx, ny = (_count(f"cells[{i}]", v) for i, v in enumerate(items))
        scene["cells"] = {"kind": "count", "nx": nx, "ny": ny}
    if cell_size is not None:
        dx, dy = _numbers("cell_size", cell_size, 2, "(dx, dy): two lengths (float, m)")
        scene["cells"] = {"kind": "size", "dx": dx, "dy": dy}
    if normal_load is not None:
        scene["normal_load"] = _number("normal_load", normal_load)
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
    if seed is not None:
        seed = _count("seed", seed)
        if seed >= 2**64:
            raise _value_error(
                "InvalidCount", f"seed = {seed} is invalid: it must be < 2**64"
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
            mean, std_dev = _numbers(
                "height_distribution", height_distribution, 2, "(mean, std_dev) (float, m)"
            )
            random["mean"] = mean
            random["std_dev"] = std_dev
        scene["heights"] = random
    if heights is not None:
        # (Ny, Nx), row iy and column ix: C order is the crate's cell order iy*Nx + ix.
        # Scene checks the shape against the grid.
        values = _heights(heights)
        scene["heights"] = {"kind": "values", "values": values.ravel(order="C")}
    young_modulus, poisson_ratio, friction_coefficient, c_x, c_z = (
        None if v is None else _number(k, v)
        for k, v in (
            ("young_modulus", young_modulus),
            ("poisson_ratio", poisson_ratio),
            ("friction_coefficient", friction_coefficient),
            ("c_x", c_x),
            ("c_z", c_z),
        )
    )
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
    maps = {
        key: _map(name, value)
        for key, name, value in (
            ("friction_coefficient", "friction_map", friction_map),
            ("c_x", "c_x_map", c_x_map),
            ("c_z", "c_z_map", c_z_map),
        )
        if value is not None
    }
    if maps:
        scene["maps"] = maps
    if isinstance(drive, str) and drive not in _DRIVES:
        raise _value_error(
            "InvalidChoice",
            f"drive = {drive!r} is not one of 'rod', 'top', 'side'; give the other drives "
            "as a dict in the scene-file format (drive={'kind': 'mixed', 'ratio': n})",
        )
    if drive is not None and not isinstance(drive, (str, dict)):
        raise TypeError(f"drive must be a str or a dict, not {type(drive).__name__}")
    if rod is not None and drive not in (None, "rod"):
        raise TypeError("rod=(height, half_width) goes with drive='rod'")
    if isinstance(drive, dict):
        scene["drive"] = drive
    elif rod is not None:
        height, half_width = _numbers("rod", rod, 2, "(height, half_width) (float, m)")
        scene["drive"] = {"kind": "rod", "height": height, "half_width": half_width}
    elif drive == "rod":
        pass  # the default drive: the paper's rod
    elif drive is not None:
        scene["drive"] = {"kind": drive}
    if backend is not None:
        _choice("backend", backend, ("auto", "dense", "spectral", "cuda"))
    if isinstance(threads, str):
        _choice("threads", threads, ("all", "current"))
    elif threads is not None:
        threads = _count("threads", threads)
    solver = {k: v for k, v in (("backend", backend), ("threads", threads)) if v is not None}
    if solver:
        scene["solver"] = solver
    probes: Dict[str, Any] = {}
    if probe_planes is not None:
        probes["planes"] = _numbers(
            "probe_planes", probe_planes, None, "a list of heights z (float, m)"
        )
    if probe_points is not None:
        points = _items("probe_points", probe_points, None, "a list of points (x, y, z)")
        probes["points"] = [
            _numbers(f"probe_points[{i}]", p, 3, "a point (x, y, z) (float, m)")
            for i, p in enumerate(points)
        ]
    if probes:
        scene["probes"] = probes
    if profile_planes is not None and profile_loads is None:
        raise TypeError("profile_planes= goes with profile_loads=[F/(μF_N), ...]")
    if profile_loads is not None:
        scene["profiles"] = {
            "loads": _numbers(
                "profile_loads", profile_loads, None, "a list of loads F/(μF_N) (float)"
            ),
            "planes": _numbers(
                "profile_planes", profile_planes or [], None, "a list of heights z (float, m)"
            ),
        }
    if confirm_metres is not None:
        if not isinstance(confirm_metres, bool):
            raise TypeError(f"confirm_metres= takes True or False, not {confirm_metres!r}")
        scene["confirm_metres"] = confirm_metres
    if max_output_bytes is not None:
        scene["max_output_bytes"] = _number("max_output_bytes", max_output_bytes)
    if contact_rule is not None:
        _choice("contact_rule", contact_rule, _CONTACT_RULES)
    delay: Dict[str, Any] = {}
    if delay_stable_states is not None:
        delay["stable_states"] = _count("delay_stable_states", delay_stable_states)
    if delay_load is not None:
        delay["load"] = _number("delay_load", delay_load)
    if delay and contact_rule != "rejuvenation":
        raise TypeError(
            "delay_stable_states= and delay_load= go with contact_rule='rejuvenation' "
            "(the only rule whose broken sites re-form)"
        )
    if contact_rule is not None:
        contact: Dict[str, Any] = {"rule": contact_rule}
        if delay:
            contact["delay"] = delay
        scene["contact"] = contact
    return scene

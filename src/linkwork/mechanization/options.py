"""What a designer may ask of a mechanization, and where its fixed pivots may go.

:class:`MechanizeOptions` is the API form (radians); :func:`options_from_values` reads the same options in file
units (degrees) from a problem file's keys or the command line's flags, checking each one, so that both say the
same thing and report a mistake the same way (a :class:`~linkwork.errors.SpecError` naming the key).
:class:`GroundRegion` is the region fixed pivots on the ground must lie in: a box, a polygon, or ``"inside"``
(inside every target profile, e.g. fixed pivots inside a wing in every shape).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.errors import SpecError
from linkwork.geometry.polygon import contains, is_simple
from linkwork.limits import MAX_MAGNITUDE, plain_number
from linkwork.limits import MECHANIZE as MECHANIZE_LIMITS
from linkwork.messages import show
from linkwork.progress import Progress

Array = NDArray[np.float64]

#: Mechanization keys of a problem file (and flags of ``linkwork mechanize`` / ``linkwork synth``).
OPTION_KEYS = (
    "dof",
    "drive",
    "actuator",
    "ground_region",
    "link_offset",
    "max_link",
    "max_link_fraction",
    "max_structural_error",
    "min_transmission",
    "anchors",
    "attempts",
    "time_limit",
    "root",
    "binary_links",
    "designs",
)

#: The values ``actuator``, ``anchors`` and ``binary_links`` may take.
ACTUATORS = ("revolute", "prismatic")
ANCHORS = ("ground", "any", "auto")
BINARY_LINKS = ("revolute", "prismatic", "both")

#: Longest link, times the profiles' largest extent, when neither ``max_link`` nor ``max_link_fraction`` is given.
DEFAULT_LINK_FRACTION = 1.5

#: Least-squares links whose structural error exceeds this fraction of the profiles' size are never kept
#: (without ``max_structural_error``).
DEFAULT_STRUCTURAL_FRACTION = 0.05

ProgressCallback = Progress
"""The one progress protocol (:class:`linkwork.progress.Progress`): ``progress(done, total)``, designs traced so far
and the most the search will trace."""


@dataclass(frozen=True)
class GroundRegion:
    """Where fixed pivots on the ground may go: a box, a polygon, or inside every target profile.

    Attributes
    ----------
    polygons
        The point must lie inside every one of these ``(k, 2)`` polygons (one for a box or a polygon; one per
        target profile for ``"inside"``, each open profile closed by the straight line from its end to its
        start).
    kind
        ``"box"``, ``"polygon"`` or ``"inside"`` (for reports).
    """

    polygons: tuple[Array, ...]
    kind: str

    @classmethod
    def from_box(cls, xmin: float, ymin: float, xmax: float, ymax: float) -> GroundRegion:
        """The box ``xmin <= x <= xmax``, ``ymin <= y <= ymax``."""
        box = np.array([[xmin, ymin], [xmax, ymin], [xmax, ymax], [xmin, ymax]], dtype=float)
        return cls((box,), "box")

    @classmethod
    def from_polygon(cls, vertices: ArrayLike) -> GroundRegion:
        """A polygon ``(k >= 3, 2)`` (closed from its last vertex to its first)."""
        poly = np.asarray(vertices, dtype=float)
        if poly.ndim != 2 or poly.shape[1] != 2 or len(poly) < 3:
            raise ValueError(f"Expected a polygon of shape (k >= 3, 2), got {poly.shape}")
        return cls((poly,), "polygon")

    @classmethod
    def inside(cls, profiles: tuple[Array, ...]) -> GroundRegion:
        """The region inside every profile (each closed by the line from its last point to its first)."""
        return cls(tuple(np.asarray(p, dtype=float) for p in profiles), "inside")

    def contains(self, points: ArrayLike) -> NDArray[np.bool_]:
        """``(n,)`` True where ``points`` ``(n, 2)`` lie in the region."""
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        ok = np.ones(len(pts), dtype=bool)
        for poly in self.polygons:
            ok &= contains(poly, pts)
        return ok

    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the region (the box of its smallest polygon)."""
        lo = np.max([p.min(axis=0) for p in self.polygons], axis=0)
        hi = np.min([p.max(axis=0) for p in self.polygons], axis=0)
        return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))

    def samples(self, count: int) -> Array:
        """About ``count`` points of a grid over the region's box that lie in the region, ``(k, 2)``."""
        xmin, ymin, xmax, ymax = self.bounds()
        side = max(2, math.ceil(math.sqrt(count)))
        if self.kind == "inside":  # thin regions (a wing): more rows across the thickness
            xs = np.linspace(xmin, xmax, 2 * side + 2)[1:-1]
            ys = np.linspace(ymin, ymax, side + 2)[1:-1]
        else:
            xs, ys = np.linspace(xmin, xmax, side), np.linspace(ymin, ymax, side)
        grid = np.array([(x, y) for x in xs for y in ys])
        return grid[self.contains(grid)] if len(grid) else grid.reshape(0, 2)

    def describe(self) -> str:
        """One phrase for messages: ``box (x0, y0)-(x1, y1)``, ``polygon of 5 vertices``, ``inside every profile``."""
        if self.kind == "inside":
            return "inside every profile"
        if self.kind == "box":
            xmin, ymin, xmax, ymax = self.bounds()
            return f"box ({xmin:.4g}, {ymin:.4g})-({xmax:.4g}, {ymax:.4g})"
        return f"polygon of {len(self.polygons[0])} vertices"


@dataclass(frozen=True)
class MechanizeOptions:
    """What the designer may choose (all optional).

    Attributes
    ----------
    dof
        Degrees of freedom (number of actuators) of the mechanism; 1 by default.
    ground_region
        Where fixed pivots on the ground may lie: ``(xmin, ymin, xmax, ymax)``, a :class:`GroundRegion`, a
        polygon ``(k, 2)``, or ``"inside"`` (inside every target profile). Default: the box of the profiles
        grown by ``margin`` of their size on every side.
    margin
        See ``ground_region``.
    link_offset
        Moving pivots may sit off the chain, along its normal, up to this multiple of the body's length.
    anchors
        ``"ground"``: every dyad to the ground; ``"any"``: also between links (to a body already placed);
        ``"auto"``: for each root, try ``"any"`` first, then ``"ground"`` (its top candidates differ).
    min_transmission
        Radians: dyads whose transmission angle drops below this on a profile are dropped.
    max_link
        Longest link, a length in the profiles' units (``None``: see ``max_link_fraction``). Before 0.3 this was
        a multiple of the profiles' largest extent; that is now ``max_link_fraction``.
    max_link_fraction
        Longest link as a multiple of the profiles' largest extent (the largest chord of a wing), used when
        ``max_link`` is ``None``; ``None`` means :data:`DEFAULT_LINK_FRACTION`.
    max_structural_error
        Largest structural error of a least-squares link (more than five profiles): the spread ``max_j |
        |W_j - c| - r|`` of the length it would need across the profiles, a length in the profiles' units;
        ``None``: no bound (the error is reported).
    root
        The body guided first (default: the body with the longest outline).
    drive
        The driven joint (default: the crank of the root, else a chain joint that moves monotonically).
    actuator
        ``"revolute"``: the drive is a revolute joint; ``"prismatic"``: add a linear actuator (RPR) between the
        ground (``ground_region``) and the root and drive its slider.
    candidates
        Moving-pivot candidates along each body (times 7 offsets).
    binary_links
        ``"revolute"``: RR dyads; ``"prismatic"``: PR sliders (a slider on a straight guide of the frame or of a
        body, pivoted to the moving body; its prismatic joint can drive); ``"both"``.
    attempts
        Designs traced at most per root and anchor choice.
    designs
        Passing designs to find and rank by quality factor before stopping (the best is kept); 1 stops at the
        first design that passes.
    time_limit
        Seconds after which the search stops with the best reason it has.
    """

    dof: int = 1
    ground_region: Any = None
    margin: float = 0.25
    link_offset: float = 1.5
    anchors: str = "auto"
    min_transmission: float = math.radians(15.0)
    max_link: float | None = None
    max_link_fraction: float | None = None
    max_structural_error: float | None = None
    root: str | None = None
    drive: str | None = None
    actuator: str = "revolute"
    binary_links: str = "revolute"
    candidates: int = 9
    attempts: int = 6
    designs: int = 5
    time_limit: float = 60.0

    def link_limit(self, size: float) -> float:
        """The longest link allowed, a length, for profiles of largest extent ``size``."""
        if self.max_link is not None:
            return self.max_link
        fraction = self.max_link_fraction if self.max_link_fraction is not None else DEFAULT_LINK_FRACTION
        return fraction * size

    def structural_limit(self, size: float) -> float:
        """The largest structural error allowed, a length: ``max_structural_error``, else
        :data:`DEFAULT_STRUCTURAL_FRACTION` of ``size`` (the search's own cut-off)."""
        if self.max_structural_error is not None:
            return self.max_structural_error
        return DEFAULT_STRUCTURAL_FRACTION * size

    def region_of(self, targets: tuple[Array, ...], size: float) -> GroundRegion:
        """The ground region in use for profiles ``targets`` of largest extent ``size``."""
        g = self.ground_region
        if isinstance(g, GroundRegion):
            return g
        if isinstance(g, str):
            if g != "inside":
                raise SpecError(
                    f'ground_region "{g}": expected a box, a polygon or "inside"', key="ground_region"
                )
            return GroundRegion.inside(targets)
        if g is None:
            pts = np.vstack(targets)
            lo, hi = pts.min(axis=0), pts.max(axis=0)
            pad = self.margin * size
            return GroundRegion.from_box(lo[0] - pad, lo[1] - pad, hi[0] + pad, hi[1] + pad)
        arr = np.asarray(g, dtype=float)
        if arr.shape == (4,):
            return GroundRegion.from_box(*(float(v) for v in arr))
        return GroundRegion.from_polygon(arr)


# ------------------------------------------------------------------------------------- file units -> options
class _Bad(ValueError):
    """A bad option value (the caller names the key or the flag)."""


def _error(expected: str, value: Any) -> _Bad:
    shown = f'"{value}"' if isinstance(value, str) else repr(value)
    return _Bad(f"expected {expected}, got {shown}")


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        return None
    return float(value)


def _whole(value: Any, low: int, high: float = math.inf) -> int | None:
    """``value`` when it is a whole number (not a bool) from ``low`` to ``high``, else ``None``."""
    return value if isinstance(value, int) and not isinstance(value, bool) and low <= value <= high else None


def _one_of(choices: tuple[str, ...]) -> tuple[Callable[[Any], Any], str]:
    """The check of a value that must be one of ``choices``, and what it expects (``"a", "b" or "c"``)."""
    quoted = [f'"{c}"' for c in choices]
    return (lambda v: v if v in choices else None), f"{', '.join(quoted[:-1])} or {quoted[-1]}"


def _region(value: Any) -> Any:
    expected = '"inside", a box [xmin, ymin, xmax, ymax] or a polygon [[x, y], ...] of at least 3 vertices'
    if isinstance(value, str):
        if value.strip().lower() == "inside":
            return "inside"
        raise _error(expected, value)
    if isinstance(value, list) and len(value) == 4 and all(_number(v) is not None for v in value):
        x0, y0, x1, y1 = (float(v) for v in value)
        _within_magnitude(value)
        if x0 < x1 and y0 < y1:
            return (x0, y0, x1, y1)
        raise _Bad("a box needs xmin < xmax and ymin < ymax")
    if (
        isinstance(value, list)
        and len(value) >= 3
        and all(isinstance(v, list) and len(v) == 2 and all(_number(c) is not None for c in v) for v in value)
    ):
        _within_magnitude([c for v in value for c in v])
        polygon = np.array(value, dtype=float)
        if not is_simple(polygon):
            raise _Bad(
                "a polygon's edges must not cross or touch but at their shared corners (which side is inside?)"
            )
        return polygon
    raise _error(expected, value)


def _within_magnitude(numbers: list[Any]) -> None:
    """Refuse a coordinate beyond :data:`linkwork.limits.MAX_MAGNITUDE` (as every length of a problem)."""
    for v in numbers:
        if abs(float(v)) > MAX_MAGNITUDE:
            raise _Bad(f"expected coordinates within +-{MAX_MAGNITUDE:g}, got {show(v)}")


_CHECKS: dict[str, tuple[Callable[[Any], Any], str]] = {
    "dof": (lambda v: _whole(v, 1, 20), "a whole number of degrees of freedom, 1 to 20 (as --dof)"),
    "drive": (lambda v: v.strip() if isinstance(v, str) and v.strip() else None, "a joint name"),
    "root": (lambda v: v.strip() if isinstance(v, str) and v.strip() else None, "a body name"),
    "actuator": _one_of(ACTUATORS),
    "anchors": _one_of(ANCHORS),
    "binary_links": _one_of(BINARY_LINKS),
    "link_offset": (lambda v: n if (n := _number(v)) is not None and n >= 0 else None, "a number >= 0"),
    "max_link": (
        lambda v: n if (n := _number(v)) is not None and n > 0 else None,
        "a positive length (profile units)",
    ),
    "max_link_fraction": (
        lambda v: n if (n := _number(v)) is not None and n > 0 else None,
        "a positive multiple of the profiles' largest extent",
    ),
    "max_structural_error": (
        lambda v: n if (n := _number(v)) is not None and n >= 0 else None,
        "a length >= 0 (profile units)",
    ),
    "min_transmission": (
        lambda v: math.radians(n) if (n := _number(v)) is not None and 0 <= n < 90 else None,
        "an angle in degrees, 0 <= min_transmission < 90",
    ),
    "attempts": (lambda v: _whole(v, 1), "a whole number >= 1"),
    "designs": (lambda v: _whole(v, 1, 20), "a whole number of designs, 1 to 20"),
    "time_limit": (
        lambda v: n if (n := _number(v)) is not None and n > 0 else None,
        "a positive number of seconds",
    ),
}


def options_from_values(
    values: Mapping[str, Any],
    *,
    source: str | None = None,
    base: MechanizeOptions | None = None,
    flags: bool = False,
) -> MechanizeOptions:
    """Options from file units (``min_transmission`` in degrees), checked; ``base`` gives the rest.

    ``values`` holds problem-file keys or command-line flags (``None`` values are left at ``base``'s; with
    ``flags`` a mistake names the flag, ``--max-link``, instead of the key). Unknown keys are not allowed.

    Raises
    ------
    SpecError
        Naming the key (and ``source``) and what was expected.
    """
    out: dict[str, Any] = {}
    for key, value in values.items():
        if value is None:
            continue
        try:
            out[key] = _checked(key, value)
        except _Bad as bad:
            shown = "--" + key.replace("_", "-") if flags else key
            raise SpecError(str(bad), source=source, key=shown) from None
    # the longest link is one limit: a length or a fraction, and the one given here replaces the base's
    if "max_link" in out and "max_link_fraction" in out:
        shown = "--max-link-fraction" if flags else "max_link_fraction"
        raise SpecError(
            "give max_link (a length) or max_link_fraction (a multiple of the largest extent), not both",
            source=source,
            key=shown,
        )
    if "max_link" in out:
        out["max_link_fraction"] = None
    elif "max_link_fraction" in out:
        out["max_link"] = None
    names = {f.name for f in fields(MechanizeOptions)}
    assert set(out) <= names
    base = base or MechanizeOptions()
    return MechanizeOptions(**{**{f.name: getattr(base, f.name) for f in fields(base)}, **out})


def _checked(key: str, value: Any) -> Any:
    """One option's value in API units, or :class:`_Bad`."""
    if key == "ground_region":
        return _region(value)
    if key not in _CHECKS:
        raise _Bad(f"unknown mechanization option; expected one of {', '.join(OPTION_KEYS)}")
    check, expected = _CHECKS[key]
    checked = check(value)
    if checked is None:
        raise _error(expected, value)
    limit = MECHANIZE_LIMITS.get(key)  # the flag's upper bound (linkwork.limits.MECHANIZE), for the key too
    if limit is not None and float(value) > limit.upper:
        raise _error(f"{expected}, at most {limit.upper:g} (as --{key.replace('_', '-')})", value)
    return checked


def _typed(text: str) -> float:
    """A coordinate of ``--ground-region`` as :data:`linkwork.limits.PLAIN_NUMBER` reads it (spaces around it
    allowed), else ``ValueError``."""
    number = plain_number(text.strip())
    if number is None:
        raise ValueError(text)
    return number


def parse_region_flag(text: str | None) -> Any:
    """``--ground-region``: ``inside``, ``XMIN,YMIN,XMAX,YMAX`` or a polygon ``X1,Y1;X2,Y2;X3,Y3;...`` (file value)."""
    if text is None:
        return None
    t = text.strip()
    if t.lower() == "inside":
        return "inside"
    try:  # numbers as a person types them (limits.PLAIN_NUMBER, as --until): not 1_0 or other scripts' digits
        if ";" in t:
            return [[_typed(c) for c in vertex.split(",")] for vertex in t.split(";") if vertex.strip()]
        return [_typed(v) for v in t.split(",")]
    except ValueError:
        raise SpecError(
            f"{text!r}: expected inside, XMIN,YMIN,XMAX,YMAX or X1,Y1;X2,Y2;X3,Y3 (a polygon)",
            key="--ground-region",
        ) from None

"""Generate linkwork's five shape-change synthesis example sets, reproducibly, from closed-form curves.

Run from anywhere: ``python examples/make_examples.py``. Every set is written twice, to
``examples/<name>/`` (to read and edit) and to ``src/linkwork/data/examples/<name>/`` (bundled with the
package, so ``linkwork demo`` finds it after ``pip install``). Each folder holds a ``problem.toml`` and the
profile files it names.

* ``wing``: a morphing wing, NACA 2412 -> 4412 -> 6412 with the chord growing 1 -> 1.18 -> 1.36 (camber and
  chord grow together, as for cruise, climb and landing), as Selig ``.dat`` files. The profile is the full
  airfoil outline, an open curve from the upper trailing edge round the nose to the lower trailing edge: the
  chain is the wing's skin, so every point of the outline must be matched, and the two trailing-edge ends stay
  free (the standard NACA thickness has a small open trailing edge). The camber line alone would give a chain
  with no thickness to carry the skin.
* ``closed``: a circle of radius 1 -> a rounded square (superellipse, exponent 4) -> an ellipse, closed CSV
  curves of growing perimeter.
* ``fixed-end``: three arches pinned at (0, 0) and (4, 0): a cubic Bézier (SVG), a circular arc (SVG ``A``
  command) and a spline through fit points (DXF), to exercise the curve readers.
* ``seat``: a driver's seat in the spirit of Shamsudin et al. (2013) Sec. 8.2: cushion and back rest for a
  small, an average and a large driver, built from straight runs and circular arcs with the paper's arc
  lengths 44.42, 51.98 and 54.39 (about 127, 149 and 155 pieces at ``s_d = 0.35``), as CSV.
* ``wing-six``: six profiles end to end, NACA 1412 -> 2412 -> ... -> 6412 with the chord growing 1 -> 1.3 in
  equal steps, as Selig ``.dat`` files (its ``mechanize.toml`` mechanizes it to one DOF).
"""

from __future__ import annotations

import math
import shutil
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT / "src") not in sys.path:
    sys.path.insert(0, str(ROOT / "src"))  # run from a clone without installing

from linkwork.io.profiles import save_profile, write_profile_dat  # noqa: E402

Array = NDArray[np.float64]

# NACA 4-digit thickness coefficients (Abbott & von Doenhoff, Theory of Wing Sections, Eq. 6.2); the last one
# leaves a small open trailing edge of thickness 0.02 t.
NACA_THICKNESS = (0.2969, -0.1260, -0.3516, 0.2843, -0.1015)


# ------------------------------------------------------------------------------------------- NACA 4-digit


def naca4_thickness(x: Array, t: float) -> Array:
    """Half thickness ``y_t(x)`` of a NACA 4-digit section of unit chord and thickness ratio ``t``."""
    a0, a1, a2, a3, a4 = NACA_THICKNESS
    x = np.asarray(x, dtype=float)
    return 5.0 * t * (a0 * np.sqrt(x) + a1 * x + a2 * x**2 + a3 * x**3 + a4 * x**4)


def naca4_camber(x: Array, m: float, p: float) -> tuple[Array, Array]:
    """Mean camber line ``y_c(x)`` and its slope of a NACA 4-digit section (max camber ``m`` at ``x = p``)."""
    x = np.asarray(x, dtype=float)
    if m == 0.0:
        return np.zeros_like(x), np.zeros_like(x)
    front = x < p
    yc = np.where(front, m / p**2 * (2 * p * x - x**2), m / (1 - p) ** 2 * ((1 - 2 * p) + 2 * p * x - x**2))
    slope = np.where(front, 2 * m / p**2 * (p - x), 2 * m / (1 - p) ** 2 * (p - x))
    return yc, slope


def naca4_outline(code: str, chord: float = 1.0, points: int = 81) -> Array:
    """A NACA 4-digit airfoil outline in Selig order (upper trailing edge -> nose -> lower trailing edge).

    Parameters
    ----------
    code
        Four digits ``"mptt"``: max camber ``m`` % of chord at ``p`` tenths of chord, thickness ``tt`` %.
    chord
        Chord length; the nose sits at the origin.
    points
        Points per surface, cosine-spaced (dense at the nose and the trailing edge).

    Returns
    -------
    numpy.ndarray
        ``(2 * points - 1, 2)``, the nose point shared by both surfaces.
    """
    m, p, t = int(code[0]) / 100.0, int(code[1]) / 10.0, int(code[2:]) / 100.0
    x = 0.5 * (1.0 - np.cos(np.linspace(0.0, math.pi, points)))
    yt = naca4_thickness(x, t)
    yc, slope = naca4_camber(x, m, p)
    theta = np.arctan(slope)
    upper = np.column_stack([x - yt * np.sin(theta), yc + yt * np.cos(theta)])
    lower = np.column_stack([x + yt * np.sin(theta), yc - yt * np.cos(theta)])
    outline = np.vstack([upper[::-1], lower[1:]])
    return chord * outline


# ---------------------------------------------------------------------------------------------- helpers


def arc_length(points: Array) -> float:
    """Length of a polyline ``(N, 2)``."""
    return float(np.sum(np.hypot(*np.diff(points, axis=0).T)))


def turtle(
    start: Sequence[float], heading_deg: float, moves: Sequence[tuple[float, float]], step: float
) -> tuple[Array, list[int]]:
    """A smooth curve of straight runs and circular arcs: ``moves`` are ``(length, turn in degrees)``.

    A move with turn 0 is a straight run; otherwise a circular arc turning by ``turn`` (positive
    counter-clockwise) over ``length``. Points are spaced at most ``step`` along the curve.

    Returns
    -------
    points, ends
        The ``(N, 2)`` curve and the index of the last point of every move.
    """
    ends = []
    points = [np.asarray(start, dtype=float)]
    heading = math.radians(heading_deg)
    for length, turn_deg in moves:
        turn = math.radians(turn_deg)
        count = max(1, math.ceil(length / step))
        for k in range(1, count + 1):
            # Each step is a chord of length ds along the mean heading of its sub-arc, so the polyline is
            # exactly as long as the moves (its corners lie within ds * dphi / 8 of the true arc).
            ds, dphi = length / count, turn / count
            chord = ds
            mid = heading + dphi / 2.0
            points.append(points[-1] + chord * np.array([math.cos(mid), math.sin(mid)]))
            heading += dphi
            del k
        ends.append(len(points) - 1)
    return np.array(points), ends


# -------------------------------------------------------------------------------------------- the sets


def _naca_sections(folder: Path, sections: list[tuple[str, str, float]]) -> dict[str, float]:
    """Write each ``(name, NACA code, chord)`` section as ``name.dat`` (Selig) and return their arc lengths."""
    lengths = {}
    for name, code, chord in sections:
        outline = naca4_outline(code, chord)
        write_profile_dat(folder / f"{name}.dat", outline, name=f"NACA {code} chord {chord:g} ({name})")
        lengths[name] = arc_length(outline)
    return lengths


def wing(folder: Path) -> dict[str, float]:
    """The morphing-wing set: NACA 2412 (chord 1), 4412 (1.18), 6412 (1.36) as Selig files."""
    sections = [("cruise", "2412", 1.0), ("climb", "4412", 1.18), ("landing", "6412", 1.36)]
    lengths = _naca_sections(folder, sections)
    _problem(
        folder,
        description="Morphing wing: NACA 2412 -> 4412 -> 6412, chord 1 -> 1.36 (full outline, open profile)",
        kind="open",
        profiles=[f"{name}.dat" for name, _, _ in sections],
        piece_length=0.02,
        min_pieces=4,
        design="auto",
        segments=5,
        starts=4,
        merge_below=0.0,
    )
    return lengths


def wing_six(folder: Path) -> dict[str, float]:
    """Six profiles end to end: NACA 1412 -> 6412 with the chord growing 1 -> 1.3 in equal steps (Selig files)."""
    sections = [(f"camber{k}", f"{k}412", 1.0 + 0.06 * (k - 1)) for k in range(1, 7)]
    lengths = _naca_sections(folder, sections)
    _problem(
        folder,
        description="Six-profile morphing wing: NACA 1412 -> 6412, chord 1 -> 1.3 (full outline, open profile)",
        kind="open",
        profiles=[f"{name}.dat" for name, _, _ in sections],
        piece_length=0.02,
        min_pieces=4,
        design="MCMC",
        starts=4,
        merge_below=0.0,
    )
    return lengths


def closed(folder: Path) -> dict[str, float]:
    """The closed set: circle, rounded square, ellipse; counter-clockwise from the rightmost point."""
    phi = np.linspace(0.0, 2.0 * math.pi, 361)
    shapes = {
        "circle": np.column_stack([np.cos(phi), np.sin(phi)]),
        # superellipse |x/a|^4 + |y/a|^4 = 1 of half-size a = 1.1
        "rounded_square": 1.1
        * np.column_stack(
            [
                np.sign(np.cos(phi)) * np.abs(np.cos(phi)) ** 0.5,
                np.sign(np.sin(phi)) * np.abs(np.sin(phi)) ** 0.5,
            ]
        ),
        "ellipse": np.column_stack([1.7 * np.cos(phi), 1.1 * np.sin(phi)]),
    }
    lengths = {}
    for name, points in shapes.items():
        points[-1] = points[0]  # exactly closed
        save_profile(folder / f"{name}.csv", points)
        lengths[name] = arc_length(points)
    _problem(
        folder,
        description="Closed curves of growing perimeter: circle -> rounded square -> ellipse",
        kind="closed",
        profiles=[f"{name}.csv" for name in shapes],
        piece_length=0.1,
        min_pieces=4,
        design="CCMMCM",
        starts=4,
        merge_below=0.0,
    )
    return lengths


def fixed_end(folder: Path) -> dict[str, float]:
    """The fixed-end set: three arches from (0, 0) to (4, 0) as SVG (Bézier, arc) and DXF (spline)."""
    import ezdxf

    from linkwork.io.profiles import load_profile

    header = '<?xml version="1.0" encoding="UTF-8"?>\n<svg xmlns="http://www.w3.org/2000/svg" '
    view = 'width="500" height="300" viewBox="-0.5 -2.5 5 3">\n'
    # SVG's y axis points down, so the arches rise to negative y in the file (linkwork flips y when reading).
    (folder / "low_arch.svg").write_text(
        header
        + view
        + '  <path d="M 0,0 C 1.2,-1 2.8,-1 4,0" fill="none" stroke="black" stroke-width="0.02"/>\n'
        "</svg>\n",
        encoding="utf-8",
    )
    sagitta = 1.2
    radius = (4.0 + sagitta**2) / (2.0 * sagitta)  # circle through (0,0), (2, sagitta), (4,0)
    (folder / "round_arch.svg").write_text(
        header
        + view
        + f'  <path d="M 0,0 A {radius:.12g},{radius:.12g} 0 0 1 4,0" fill="none" stroke="black" '
        'stroke-width="0.02"/>\n</svg>\n',
        encoding="utf-8",
    )
    document = ezdxf.new("R2010")
    fit = [(0.0, 0.0), (0.5, 1.1), (1.4, 1.85), (2.6, 1.9), (3.5, 1.15), (4.0, 0.0)]
    document.modelspace().add_spline(fit_points=fit)
    document.saveas(str(folder / "high_arch.dxf"))
    files = ["low_arch.svg", "round_arch.svg", "high_arch.dxf"]
    lengths = {Path(name).stem: arc_length(load_profile(folder / name)) for name in files}
    _problem(
        folder,
        description="Fixed-end arches pinned at (0, 0) and (4, 0): Bezier (SVG), arc (SVG), spline (DXF)",
        kind="fixed-end",
        profiles=files,
        piece_length=0.05,
        min_pieces=4,
        design="auto",
        segments=4,
        starts=4,
        merge_below=0.0,
    )
    return lengths


def seat_profile(total: float, cushion: float, lumbar_turn: float, recline: float) -> Array:
    """One seat profile: front roll, cushion, bight, lumbar bulge, back rest, head roll (inches).

    The curve starts at the front edge of the cushion and ends at the top of the back rest; the back rest's
    straight run takes whatever length makes the whole curve ``total`` long. The bight (where cushion meets
    back rest) starts at the origin.
    """
    tilt = 185.0  # the cushion falls 5 degrees towards the back
    back = 90.0 + recline  # heading of the back rest (recline from vertical)
    moves = [
        (2.5, tilt - 120.0),  # front roll: from heading 120 (up and back) to the cushion's heading
        (cushion, 0.0),
        (5.0, back - tilt),  # the bight, concave
        (3.0, 0.0),
        (3.0, -lumbar_turn),  # lumbar bulge towards the driver, and back
        (6.0, 2.0 * lumbar_turn),
        (3.0, -lumbar_turn),
    ]
    head = (2.5, 40.0)  # the head roll curls backwards
    rest = total - sum(length for length, _ in moves) - head[0]
    points, ends = turtle((0.0, 0.0), 120.0, [*moves, (rest, 0.0), head], step=0.05)
    return points - points[ends[1]]  # the start of the bight at the origin


def seat(folder: Path) -> dict[str, float]:
    """The seat set: small, average and large driver (Sec. 8.2 of the paper), as CSV."""
    drivers = {
        "small": seat_profile(44.42, cushion=14.5, lumbar_turn=12.0, recline=12.0),
        "average": seat_profile(51.98, cushion=16.5, lumbar_turn=10.0, recline=15.0),
        "large": seat_profile(54.39, cushion=18.0, lumbar_turn=8.0, recline=18.0),
    }
    lengths = {}
    for name, points in drivers.items():
        save_profile(folder / f"{name}.csv", points)
        lengths[name] = arc_length(points)
    _problem(
        folder,
        description="Driver's seat for a small, an average and a large driver (Shamsudin et al. 2013, 8.2)",
        kind="open",
        profiles=[f"{name}.csv" for name in drivers],
        piece_length=0.35,
        min_pieces=8,
        design="auto",
        segments=5,
        starts=4,
        merge_below=22.0,
    )
    return lengths


def _merge_on(merge_below: float) -> str:
    """The seat's threshold is a joint range on the joined chain, not on the targets (the paper's default)."""
    if not merge_below:
        return ""
    return (
        '\nmerge_on = "chain"   # Eq. 34 ranges on the joined chain (the paper measures them on the targets)'
    )


def _problem(
    folder: Path,
    *,
    description: str,
    kind: str,
    profiles: list[str],
    piece_length: float,
    min_pieces: int,
    design: str,
    starts: int,
    merge_below: float,
    segments: int | None = None,
) -> None:
    listed = ", ".join(f'"{name}"' for name in profiles)
    names = ", ".join(f'"{Path(name).stem}"' for name in profiles)
    text = f"""# linkwork synth problem, written by examples/make_examples.py (edit the script, not this file)
description = "{description}"
type = "{kind}"
profiles = [{listed}]
names = [{names}]
piece_length = {piece_length}
min_pieces = {min_pieces}
design = "{design}"{f"{chr(10)}segments = {segments}" if segments else ""}
starts = {starts}
merge_below = {merge_below}   # degrees{_merge_on(merge_below)}
seed = 1
"""
    (folder / "problem.toml").write_text(text, encoding="utf-8")


SETS = {"wing": wing, "closed": closed, "fixed-end": fixed_end, "seat": seat, "wing-six": wing_six}

# Sets that also get a ``mechanize.toml`` (the problem with ``mechanize = true``), and the design they fix if any:
# the wing's best 5-segment design CCCMC has 9 bodies and no dyad set passes; MCMC mechanizes in under a second.
MECHANIZE = {
    "wing": 'design = "MCMC"           # the best 5-segment design CCCMC has 9 bodies; MCMC mechanizes in under a second',
    "seat": None,
    "wing-six": None,
}

# Mechanization keys added to ``mechanize.toml`` (after ``mechanize = true``): six profiles need least-squares
# dyads, and the trailing edge (whose arc slide lengthens the chord) is guided by a dyad to another body.
MECHANIZE_KEYS = {
    "seat": [
        'binary_links = "prismatic"   # sliders on the frame and between segments; a slider drives (paper, Fig. 14)'
    ],
    "wing-six": [
        'anchors = "any"          # dyads between bodies too (the trailing edge moves 0.3 chords)',
        "attempts = 3             # designs traced per root: the first passing ones are ranked",
    ],
}


def write_mechanize(folder: Path, name: str, design_line: str | None) -> None:
    """Write ``mechanize.toml``: ``problem.toml`` with ``mechanize = true`` (and, for some sets, a fixed design)."""
    lines = (folder / "problem.toml").read_text(encoding="utf-8").splitlines()
    header = [
        f"# linkwork synth problem with mechanization: `linkwork synth examples/{name}/mechanize.toml` adds the binary links",
        f"# that bring the chain to one degree of freedom (see docs/examples/{name}-mechanism.md).",
    ]
    body = []
    for line in lines[1:]:
        if design_line is not None and line.startswith("design = "):
            body.append(design_line)
            continue
        if design_line is not None and line.startswith("segments = "):
            continue
        body.append(line)
        if line.startswith("seed = "):
            body.append("mechanize = true")
            body += MECHANIZE_KEYS.get(name, [])
    (folder / "mechanize.toml").write_text("\n".join(header + body) + "\n", encoding="utf-8")


def main(root: Path = ROOT) -> None:
    """Write every example set into ``root/src/linkwork/data/examples/``, the one bundled copy (reached with
    ``linkwork.data.example(name)``; ``linkwork synth NAME`` runs it)."""
    bundled = root / "src" / "linkwork" / "data" / "examples"
    for name, make in SETS.items():
        folder = bundled / name
        if folder.exists():
            shutil.rmtree(folder)
        folder.mkdir(parents=True)
        lengths = make(folder)
        if name in MECHANIZE:
            write_mechanize(folder, name, MECHANIZE[name])
        summary = ", ".join(f"{key} {value:.4f}" for key, value in lengths.items())
        print(f"{name:10s} arc lengths: {summary}")


if __name__ == "__main__":
    main()

"""Manufacturing imperfections of hinge lines: the tolerance model, seeded noise, and the perturbed twists.

Every hinge line of the reference (start) configuration is moved: its direction tilts by about ``direction_tol``,
about the hinge itself (the point written for it, or the joint point linkwork draws:
:func:`linkwork.studies.scale.hinge_pivots`), and its position shifts normal to the line by about ``position_tol``
(a standard deviation per component, or a hard bound: see :class:`ImperfectionModel`). The imperfect
structure is thus assembled, free of strain, in the start configuration; the misfit measures what it must take up
as it moves away from there. Four numbers per joint say how: ``(t1, t2, s1, s2)``, the tilt (radians) about and
the shift (length) along the two unit vectors ``e1, e2`` normal to the line. A planar mechanism gets in-plane
errors (shifts in the plane; a slider's direction turns in the plane) unless spatial errors are asked for. A prismatic joint's line has no
position: only its direction tilts.

Distributions: ``normal`` draws every component with standard deviation equal to the tolerance; ``uniform`` draws
the tilt vector uniformly in the disc of radius ``direction_tol`` and the shift uniformly in the disc of radius
``position_tol``.

Seeds: sample ``i`` of a study with seed ``S`` has its own 64-bit seed, a hash of ``i`` and the study key that
``numpy.random.SeedSequence(S)`` gives; its numbers are a splitmix64 stream of that seed (normal variates by Box-Muller), computed in a
compiled kernel. A sample's numbers therefore depend only on ``(S, i)``: never on chunking or on which worker ran
it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from linkwork.errors import SpecError
from linkwork.kernel_cache import kernel
from linkwork.kinematics.mechanism import Mechanism
from linkwork.studies.scale import hinge_pivots

Array = NDArray[np.float64]

DISTRIBUTIONS = ("normal", "uniform")


@dataclass(frozen=True)
class ImperfectionModel:
    """Hinge tolerances (length units and radians), their distribution and whether errors leave the plane.

    What a tolerance means depends on the distribution (:attr:`meaning`): ``normal`` (the default) makes it the
    standard deviation of each of the two error components normal to the hinge line, so the error's size exceeds
    it for ``exp(-1/2)``, 61 %, of the hinges (:attr:`fraction_beyond`); ``uniform`` makes it a hard bound, the
    error uniform in the disc (shift) or cone (tilt) of that radius.

    ``spatial``: whether the hinges of a mechanism that moves in a plane also tilt and shift out of it. ``None``
    (the default) decides by the mechanism, as ``linkwork robustness`` does without ``--spatial-errors``: in-plane
    errors for a planar mechanism (however it is written, :meth:`Mechanism.plane_normal`), spatial ones otherwise.
    """

    position_tol: float
    direction_tol: float
    distribution: str = "normal"
    spatial: bool | None = None

    def __post_init__(self) -> None:
        if not (np.isfinite(self.position_tol) and self.position_tol >= 0.0):
            raise SpecError(f"hinge position tolerance must be >= 0, got {self.position_tol}")
        if not (np.isfinite(self.direction_tol) and 0.0 <= self.direction_tol < np.pi / 2):
            raise SpecError(
                f"hinge direction tolerance must be >= 0 and below 90 deg, got {np.degrees(self.direction_tol)}"
            )
        if self.distribution not in DISTRIBUTIONS:
            raise SpecError(
                f"distribution must be one of {', '.join(DISTRIBUTIONS)}, got {self.distribution!r}"
            )

    @property
    def meaning(self) -> str:
        """What a tolerance is under this distribution, in one line (robustness.json ``tolerances.meaning``)."""
        if self.distribution == "uniform":
            return "hard bound: each hinge's shift is uniform in a disc, its tilt in a cone, of the tolerance's radius"
        return (
            "standard deviation of each of the two components normal to the hinge line: a hinge's shift or tilt "
            "exceeds the tolerance with probability exp(-1/2) = 61 %"
        )

    @property
    def fraction_beyond(self) -> float:
        """The expected fraction of hinges whose shift (or tilt) is larger than its tolerance."""
        return 0.0 if self.distribution == "uniform" else float(np.exp(-0.5))


@dataclass(frozen=True)
class HingeLines:
    """The nominal hinge lines: per joint a point, the unit direction, and the normal basis ``e1, e2``."""

    points: Array
    directions: Array
    e1: Array
    e2: Array
    revolute: NDArray[np.bool_]

    @classmethod
    def of(cls, mech: Mechanism, centre: Array) -> HingeLines:
        """The hinge lines of ``mech`` at its reference, each with the point where the hinge physically is
        (:func:`linkwork.studies.scale.hinge_pivots`): a direction error tilts the hinge about that point.

        ``e1`` points from the line towards ``centre`` (along their common normal) and ``e2 = direction x e1``,
        so that errors drawn in this basis do not depend on where the linkage stands or how it is turned; a line
        through the centre (or a prismatic joint) takes ``e1`` normal to it towards the direction of its nearest
        non-parallel neighbour in the joints' order (:func:`_normal_towards_neighbours`), which turns with it too.
        """
        w = mech.twists[:, :3]
        revolute = np.einsum("ij,ij->i", w, w) > 0.5
        directions = np.where(revolute[:, None], w, mech.twists[:, 3:])
        points = hinge_pivots(mech)
        radial = np.asarray(centre, dtype=float)[None, :] - points
        radial -= np.einsum("ij,ij->i", radial, directions)[:, None] * directions
        size = np.linalg.norm(radial, axis=1)
        fallback = _normal_towards_neighbours(directions)
        ok = revolute & (size > 1e-9 * max(1.0, float(size.max(initial=0.0))))
        e1 = np.where(ok[:, None], radial, fallback)
        e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
        e2 = np.cross(directions, e1)
        return cls(points, directions, e1, e2, revolute)


def _normal_towards_neighbours(directions: Array) -> Array:
    """``(n, 3)`` per joint a vector normal to its direction, built from the linkage itself: the part normal to
    it of the direction of the nearest joint in the order the joints are written (the next, the one before, then
    further, round the list as round a loop) that is not parallel to it; the coordinate axis the direction is
    most nearly normal to only if every joint is parallel.

    This is the basis of the lines through the centre (a spherical linkage's) and of prismatic joints, so that
    their errors, too, turn with the linkage when it is moved or turned (a coordinate axis does not: a turned
    spherical 4R's or slider-crank's samples changed by up to 1.5 times before).
    """
    n = len(directions)
    out = np.empty_like(directions)
    order = [k for step in range(1, n) for k in (step, -step)]
    for i in range(n):
        d = directions[i]
        for k in order:
            other = directions[(i + k) % n]
            normal = other - (other @ d) * d
            if np.linalg.norm(normal) > 1e-6:
                out[i] = normal
                break
        else:
            axis = np.eye(3)[int(np.argmin(np.abs(d)))]
            out[i] = np.cross(np.cross(d, axis), d)
    return out


def sample_seeds(seed: int, start: int, stop: int) -> NDArray[np.uint64]:
    """The 64-bit seeds of samples ``start .. stop - 1`` of a study seeded with ``seed``.

    The study's 128-bit key comes from ``numpy.random.SeedSequence(seed)``; sample ``i``'s seed is the splitmix64
    hash of that key and ``i``, so it depends on ``(seed, i)`` alone.
    """
    key = np.random.SeedSequence(seed).generate_state(2, dtype=np.uint64)
    return _sample_seeds(key, start, stop)


@kernel()
def _sample_seeds(key: np.ndarray, start: int, stop: int) -> np.ndarray:
    out = np.empty(stop - start, dtype=np.uint64)
    for i in range(start, stop):
        out[i - start] = _splitmix64(_splitmix64(key[0] ^ np.uint64(i)) ^ key[1])
    return out


@kernel()
def _splitmix64(state: np.uint64) -> np.uint64:
    z = state + np.uint64(0x9E3779B97F4A7C15)
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@kernel()
def _uniform(seed: np.uint64, counter: int) -> float:
    """A uniform number in (0, 1) from the ``counter``-th splitmix64 output of ``seed``."""
    x = _splitmix64(seed + np.uint64(counter) * np.uint64(0x9E3779B97F4A7C15))
    return (float(x >> np.uint64(11)) + 0.5) * (1.0 / 9007199254740992.0)


@kernel()
def unit_noise(seeds: np.ndarray, n_joints: int, uniform: bool) -> np.ndarray:
    """``(S, n, 4)`` noise of unit size per sample seed: ``(t1, t2, s1, s2)`` per joint, standard normal
    components, or two points uniform in the unit disc."""
    out = np.empty((seeds.shape[0], n_joints, 4))
    for s in range(seeds.shape[0]):
        c = 0
        for j in range(n_joints):
            for pair in range(2):
                u1 = _uniform(seeds[s], c)
                u2 = _uniform(seeds[s], c + 1)
                c += 2
                if uniform:
                    r = np.sqrt(u1)
                else:
                    r = np.sqrt(-2.0 * np.log(u1))
                out[s, j, 2 * pair] = r * np.cos(2.0 * np.pi * u2)
                out[s, j, 2 * pair + 1] = r * np.sin(2.0 * np.pi * u2)
    return out


def component_scale(mech: Mechanism, model: ImperfectionModel, lines: HingeLines) -> Array:
    """``(n, 4)`` tolerance per noise component: tilts ``direction_tol``, shifts ``position_tol``; for in-plane
    errors of a planar mechanism (however it is written: :meth:`Mechanism.plane_normal`) no tilt out of the plane
    (a revolute axis stays normal to it; a prismatic direction turns only about the plane's normal), and zero
    shift for a prismatic joint."""
    scale = np.empty((mech.n_joints, 4))
    normal = mech.plane_normal()
    scale[:, :2] = model.direction_tol
    if normal is not None and not model.spatial:
        about_normal = np.abs(np.stack([lines.e1 @ normal, lines.e2 @ normal], axis=1)) > 0.999
        scale[:, :2] = np.where(about_normal & ~lines.revolute[:, None], model.direction_tol, 0.0)
    scale[:, 2:] = np.where(lines.revolute, model.position_tol, 0.0)[:, None]
    return scale


def hinge_errors(
    seeds: NDArray[np.uint64], mech: Mechanism, model: ImperfectionModel, lines: HingeLines
) -> Array:
    """``(S, n, 4)`` hinge errors ``(t1, t2, s1, s2)`` of the samples with these seeds."""
    noise = unit_noise(seeds, mech.n_joints, model.distribution == "uniform")
    return noise * component_scale(mech, model, lines)[None, :, :]


def perturbed_twists(errors: Array, lines: HingeLines) -> Array:
    """``(S, n, 6)`` unit twists of the imperfect hinge lines: each direction tilted by the rotation vector
    ``t1 e1 + t2 e2`` (exactly, Rodrigues), each point shifted by ``s1 e1 + s2 e2``."""
    tilt = errors[..., 0:1] * lines.e1 + errors[..., 1:2] * lines.e2
    angle = np.linalg.norm(tilt, axis=-1, keepdims=True)
    safe = np.where(angle > 0.0, angle, 1.0)
    axis = tilt / safe
    d = lines.directions
    tilted = np.cos(angle) * d + np.sin(angle) * np.cross(axis, d)
    points = lines.points + errors[..., 2:3] * lines.e1 + errors[..., 3:4] * lines.e2
    rev = lines.revolute[None, :, None]
    omega = np.where(rev, tilted, 0.0)
    v = np.where(rev, np.cross(points, tilted), tilted)
    return np.ascontiguousarray(np.concatenate([omega, v], axis=-1))

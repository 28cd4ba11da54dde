"""Linkage spec files: read a TOML description of a linkage into a :class:`Mechanism`, and write one back.

A spec file is data, never code: it is parsed with :mod:`tomllib` and every key is checked for its type,
length and range. Angles are in degrees in the file (``angles = "rad"`` switches the whole file to radians)
and in radians in the returned mechanism. A mistake is one :class:`~linkwork.errors.SpecError` line naming the
file, the key path and what was expected, for example
``bennett.toml: loop.joints[2].alpha: expected a number, got "abc"``; joints are counted from 0, so
``joints[2]`` is the third ``[[loop.joints]]`` block (joint ``C`` by default).

Two forms (see ``docs/spec-format.md`` for every key):

* ``[loop]``: one closed loop of revolute joints in loop order, in the ``dh``, ``hinge-lines`` or ``rods``
  convention (docs/spec-format.md; docs/architecture.md, "Contracts");
* ``[mechanism]``: joints between named bodies, each a revolute (``R``) or prismatic (``P``) joint on a
  line in the start configuration; the loops are a cycle basis of the body graph, ``planar = true`` keeps
  the three planar closure equations per loop.

Example
-------
.. code-block:: toml

    name = "Bennett 45/75"
    angles = "deg"

    [loop]
    convention = "dh"
    couple = [["A", "C"], ["B", "D"]]

    [[loop.joints]]
    theta = 90.0
    a = 1.0
    alpha = 45.0
"""

from __future__ import annotations

import importlib
import math
import pkgutil
import re
from collections import deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from linkwork.errors import AssemblyError, SpecError
from linkwork.geometry import line_twist
from linkwork.geometry.names import default_joint_name
from linkwork.io.toml_reader import MAX_NAME_CHARS, TomlReader, closest, key_path, read_toml, show
from linkwork.kinematics.chains import Assembly, from_dh, from_rods
from linkwork.kinematics.mechanism import Array, Mechanism
from linkwork.kinematics.normalization import near_mobility

__all__ = ["CONVENTIONS", "LoadedSpec", "dump_spec", "load_spec", "resolve_spec"]

CONVENTIONS = ("dh", "hinge-lines", "rods")
"""The values of ``loop.convention``."""

ANGLE_UNITS = ("deg", "rad")
"""The values of ``angles``."""

TOP_KEYS = ("name", "angles", "description", "loop", "mechanism", "points")
POINT_KEYS = ("name", "body", "position")
LOOP_KEYS = ("convention", "couple", "fixed", "joints")
MECHANISM_KEYS = ("planar", "couple", "fixed", "joints")
JOINT_KEYS = {
    "dh": ("name", "theta", "d", "a", "alpha"),
    "hinge-lines": ("name", "point", "direction", "theta"),
    "rods": ("name", "rod", "theta"),
}
ROD_KEYS = ("phi", "omega", "psi", "v")
MECHANISM_JOINT_KEYS = ("name", "type", "bodies", "point", "direction", "value")

MAX_JOINTS = 500
"""The most joints a spec file may declare (a bound on the work of assembling and tracing)."""

MIN_LOOP_JOINTS = 4
"""A closed loop needs at least this many joints to move (a loop of three is a rigid triangle)."""

#: Where a key that is unknown at one place belongs instead, for a more helpful message.
_ELSEWHERE = {
    "convention": "[loop]",
    "couple": "[loop] or [mechanism]",
    "fixed": "[loop] or [mechanism]",
    "planar": "[mechanism]",
    "joints": "[loop] or [mechanism]",
    "theta": '[[loop.joints]] (conventions "dh", "hinge-lines", "rods")',
    "d": '[[loop.joints]] (convention "dh")',
    "a": '[[loop.joints]] (convention "dh")',
    "alpha": '[[loop.joints]] (convention "dh")',
    "point": '[[loop.joints]] (convention "hinge-lines") or [[mechanism.joints]]',
    "direction": '[[loop.joints]] (convention "hinge-lines") or [[mechanism.joints]]',
    "rod": '[[loop.joints]] (convention "rods")',
    "type": "[[mechanism.joints]]",
    "bodies": "[[mechanism.joints]]",
    "value": "[[mechanism.joints]]",
    "name": "the top level or a joint",
    "angles": "the top level",
}

#: Joint names end up in CSV headers and in flags such as ``--until A=30`` and ``--couple A=C``.
_JOINT_NAME = re.compile(r"[^\s=,\"'\x00-\x1f\x7f]+")


@dataclass(frozen=True)
class LoadedSpec:
    """A linkage read from a spec file or built from a built-in name.

    Attributes
    ----------
    mechanism
        The assembled mechanism, couplings and fixed joints applied.
    assembly
        For the ``dh`` and ``rods`` conventions, how the start was closed onto the loop (residual before and
        after, correction per joint in radians); ``None`` when the start is exact by construction
        (``hinge-lines``, ``[mechanism]``, built-ins).
    source
        The file read, or ``None`` for a built-in linkage.
    """

    mechanism: Mechanism
    assembly: Assembly | None
    source: Path | None

    @property
    def max_correction(self) -> float:
        """Largest correction of a joint (radians) applied to close the start; 0 when none was needed."""
        if self.assembly is None or self.assembly.correction.size == 0:
            return 0.0
        return float(np.max(np.abs(self.assembly.correction)))


# ----------------------------------------------------------------------------------------------------------
# reading
def load_spec(path: str | Path, *, closure_tol: float = 1e-12) -> LoadedSpec:
    """Read a linkage spec file (TOML) into an assembled mechanism.

    Parameters
    ----------
    path
        The spec file.
    closure_tol
        The largest least-squares closure misfit accepted when a ``dh`` or ``rods`` loop is assembled (play in
        the hinges); it is recorded in :attr:`LoadedSpec.assembly`.

    Returns
    -------
    LoadedSpec
        The mechanism (radians inside), how its start was corrected onto the loop, and the file.

    Raises
    ------
    SpecError
        One line ``file: key: what was expected`` for invalid TOML (with its line), an unknown key (with the
        closest valid one), a value of the wrong type, length or range, a zero direction, too few joints,
        duplicate joint names, an unknown joint in ``couple``/``fixed``, both or neither of ``[loop]`` and
        ``[mechanism]``, a joint connecting a body to itself, or bodies not connected to the rest.
    AssemblyError
        The start configuration of a ``dh`` or ``rods`` loop cannot be closed, or its link parameters close no
        loop within ``closure_tol`` (misfit, smallest singular value and joints named); the message starts with
        the file.
    """
    path = Path(path)
    source = str(path)
    table = _read_toml(path)
    reader = _Reader(source)
    reader.check_keys(table, "", TOP_KEYS)
    name = reader.string(table, "name", "", default=path.stem, limit=MAX_NAME_CHARS)
    if re.search(r"[\x00-\x08\x0a-\x1f\x7f\u2028\u2029]", name):  # a tab is fine (and valid XML)
        raise reader.error(
            "name", f"expected a name without line breaks or control characters, got {_show(name)}"
        )
    reader.string(table, "description", "", default="")  # free text for the reader
    unit = reader.choice(table, "angles", "", ANGLE_UNITS, default="deg")
    reader.degrees = unit == "deg"
    has_loop, has_mech = "loop" in table, "mechanism" in table
    if has_loop and has_mech:
        raise reader.error("mechanism", "expected exactly one of [loop] and [mechanism], got both")
    if not (has_loop or has_mech):
        raise reader.error(
            "loop",
            "missing; expected a [loop] table (one closed loop) or a [mechanism] table "
            "(joints between bodies)",
        )
    meta = {"source": source}
    try:
        if has_loop:
            mech, assembly, couplings = _read_loop(reader, table["loop"], name, meta, closure_tol)
        else:
            mech, couplings = _read_mechanism(reader, table["mechanism"], name, meta)
            assembly = None
    except AssemblyError as exc:
        raise AssemblyError(f"{source}: {exc}", residual=exc.residual) from None
    couple, fixed = couplings
    if couple or fixed:
        mech = mech.with_couplings(couple, fixed)
    if assembly is None:
        _check_not_near_mobile(mech, source, closure_tol)
    if "points" in table:
        mech = replace(mech, meta={**mech.meta, "points": _read_points(reader, table["points"], mech)})
    return LoadedSpec(mechanism=mech, assembly=assembly, source=path)


def _check_not_near_mobile(mech: Mechanism, source: str, closure_tol: float) -> None:
    """Hinge lines a rounding away from a mobile linkage: one line with the numbers, unless within tolerance."""
    near = near_mobility(mech)
    if near is None or near.misfit <= closure_tol:
        return
    raise AssemblyError(
        f"{source}: {mech.name}: the joint lines are rigid by a hair, not mobile: smallest singular value "
        f"{near.relative:.3g} of the largest (normalised Jacobian), a closure misfit of {near.misfit:.3g} per "
        f"radian of the near-motion of joints {', '.join(near.joints)} > closure tolerance {closure_tol:.3g}; "
        "an over-constrained linkage typed with rounded coordinates? Give them to full precision, or accept the "
        "misfit as play in the hinges with a closure tolerance above it (closure_tol / --closure-tol)",
        residual=near.misfit,
    )


def resolve_spec(
    spec: str | Path, params: Mapping[str, Any] | None = None, *, closure_tol: float = 1e-12
) -> LoadedSpec:
    """A spec file or a built-in linkage by name, as the CLI's ``SPEC [--set KEY=VALUE ...]`` takes it.

    Parameters
    ----------
    spec
        A path ending in ``.toml``, containing a slash or naming an existing file is read with
        :func:`load_spec`; anything else is the name of a built-in linkage (``linkwork linkages`` lists them).
    params
        Parameters of a built-in in file units (degrees for angles); must be empty for a file.
    closure_tol
        For a file: the largest least-squares closure misfit accepted at assembly (see :func:`load_spec`).

    Returns
    -------
    LoadedSpec
        With ``assembly`` and ``source`` set to ``None`` for a built-in.

    Raises
    ------
    SpecError
        ``--set`` given with a file, an unknown built-in or parameter, or any error of :func:`load_spec`.
    """
    params = dict(params or {})
    path = Path(spec)
    looks_like_file = isinstance(spec, Path) or path.suffix.lower() == ".toml" or path.is_file()
    if looks_like_file or "/" in str(spec) or "\\" in str(spec):
        if params:
            given = ", ".join(sorted(params))
            raise SpecError(
                f"--set applies to built-in linkages only (got {given}); edit the file instead",
                source=str(path),
                key="--set",
            )
        return load_spec(path, closure_tol=closure_tol)
    from linkwork.linkages.registry import get

    _import_builtins()
    return LoadedSpec(mechanism=get(str(spec)).make(**params), assembly=None, source=None)


def _import_builtins() -> None:
    """Import every module of :mod:`linkwork.linkages` so that each registers its built-ins."""
    import linkwork.linkages as package

    for module in pkgutil.iter_modules(package.__path__):
        importlib.import_module(f"{package.__name__}.{module.name}")


def _read_toml(path: Path) -> dict[str, Any]:
    """The parsed file; a syntax error becomes a SpecError naming its line."""
    return read_toml(path, "a linkage spec file (TOML)")


_show = show
_closest = closest
_key = key_path


class _Reader(TomlReader):
    """The spec file's reader: :class:`TomlReader` plus joints, joint names and couplings."""

    def __init__(self, source: str) -> None:
        super().__init__(source, elsewhere=_ELSEWHERE)

    def joint_list(self, section: Mapping[str, Any], path: str) -> list[Any]:
        """The ``[[path.joints]]`` array of tables."""
        joints = self.require(section, "joints", path, f"one [[{path}.joints]] table per joint")
        if not isinstance(joints, list) or not all(isinstance(j, dict) for j in joints):
            raise self.error(
                _key(path, "joints"), f"expected an array of tables [[{path}.joints]], got {_show(joints)}"
            )
        if len(joints) > MAX_JOINTS:
            raise self.error(_key(path, "joints"), f"expected at most {MAX_JOINTS} joints, got {len(joints)}")
        return joints

    def joint_names(self, joints: Sequence[Mapping[str, Any]], path: str) -> list[str]:
        """Each joint's ``name`` (default A, B, C, ...), checked to be unique."""
        names: list[str] = []
        seen: dict[str, int] = {}
        for i, joint in enumerate(joints):
            key = _key(_key(path, i), "name")
            name = joint.get("name", default_joint_name(i))
            if isinstance(name, str) and len(name) > MAX_NAME_CHARS:
                raise self.error(
                    key, f"expected a joint name of at most {MAX_NAME_CHARS} characters, got {len(name)}"
                )
            if not isinstance(name, str) or not _JOINT_NAME.fullmatch(name):
                raise self.error(
                    key, f"expected a joint name without spaces, quotes, '=' or ',', got {_show(name)}"
                )
            if name in seen:
                raise self.error(key, f'duplicate joint name "{name}" (also {_key(path, seen[name])})')
            seen[name] = i
            names.append(name)
        return names

    def couplings(
        self, section: Mapping[str, Any], path: str, names: Sequence[str], types: Sequence[str]
    ) -> tuple[list[list[str]], list[str]]:
        """``couple`` (lists of at least two joint names of one type) and ``fixed`` (joint names)."""
        known = ", ".join(names)

        def joint(value: Any, key: str) -> str:
            if not isinstance(value, str):
                raise self.error(key, f"expected a joint name, got {_show(value)}")
            if value not in names:
                close = _closest(value, names)
                hint = f'did you mean "{close}"? ' if close else ""
                raise self.error(key, f'unknown joint "{value}"; {hint}joints are {known}')
            return value

        couple_key = _key(path, "couple")
        raw = section.get("couple", [])
        example = 'a list of lists of joint names such as [["A", "C"], ["B", "D"]]'
        if not isinstance(raw, list):
            raise self.error(couple_key, f"expected {example}, got {_show(raw)}")
        couple: list[list[str]] = []
        for g, group in enumerate(raw):
            key = _key(couple_key, g)
            if not isinstance(group, list):
                raise self.error(
                    key, f'expected a list of joint names such as ["A", "C"], got {_show(group)}'
                )
            if len(group) < 2:
                raise self.error(key, f"expected at least two joints to couple, got {_show(group)}")
            members = [joint(item, _key(key, i)) for i, item in enumerate(group)]
            kinds = {types[names.index(m)] for m in members}
            if len(kinds) > 1:
                raise self.error(key, f"cannot couple revolute and prismatic joints: {_show(group)}")
            couple.append(members)
        fixed_key = _key(path, "fixed")
        raw_fixed = section.get("fixed", [])
        if not isinstance(raw_fixed, list):
            raise self.error(
                fixed_key, f'expected a list of joint names such as ["A"], got {_show(raw_fixed)}'
            )
        fixed = [joint(item, _key(fixed_key, i)) for i, item in enumerate(raw_fixed)]
        return couple, fixed


Couplings = tuple[list[list[str]], list[str]]


def _read_loop(
    reader: _Reader, value: Any, name: str, meta: Mapping[str, Any], closure_tol: float = 1e-12
) -> tuple[Mechanism, Assembly | None, Couplings]:
    """The ``[loop]`` table: one closed loop of revolute joints in one of :data:`CONVENTIONS`."""
    section = reader.table(value, "loop", LOOP_KEYS)
    convention = reader.require(section, "convention", "loop", 'one of "dh", "hinge-lines", "rods"')
    convention = reader.choice(section, "convention", "loop", CONVENTIONS, default=convention)
    joints = reader.joint_list(section, "loop")
    path = "loop.joints"
    for i, joint in enumerate(joints):
        reader.check_keys(joint, _key(path, i), JOINT_KEYS[convention])
    if len(joints) < MIN_LOOP_JOINTS:
        raise reader.error(
            path,
            f"expected at least {MIN_LOOP_JOINTS} joints in a closed loop "
            "(a loop of 3 revolute joints is rigid), "
            f"got {len(joints)}",
        )
    names = reader.joint_names(joints, path)
    couplings = reader.couplings(section, "loop", names, ["R"] * len(names))
    info = {**meta, "convention": convention}
    assembly: Assembly | None = None
    if convention == "dh":
        params = [
            {
                key: reader.number(joint, key, _key(path, i), default=0.0, angle=key in ("theta", "alpha"))
                for key in ("theta", "d", "a", "alpha")
            }
            for i, joint in enumerate(joints)
        ]
        mech, assembly = from_dh(name, params, joint_names=names, meta=info, closure_tol=closure_tol)
    elif convention == "rods":
        rods, thetas = [], []
        for i, joint in enumerate(joints):
            here = _key(path, i)
            rod_value = reader.require(joint, "rod", here, "a rod table { phi, omega, psi, v = [a, 0, d] }")
            rod = reader.table(
                rod_value, _key(here, "rod"), ROD_KEYS, form="{ phi, omega, psi, v = [a, 0, d] }"
            )
            rod_path = _key(here, "rod")
            rods.append(
                {
                    **{
                        key: reader.number(rod, key, rod_path, angle=True, required="an angle")
                        for key in ("phi", "omega", "psi")
                    },
                    "v": reader.vector(rod, "v", rod_path),
                }
            )
            thetas.append(reader.number(joint, "theta", here, default=0.0, angle=True))
        mech, assembly = from_rods(name, rods, thetas, joint_names=names, meta=info, closure_tol=closure_tol)
    else:
        twists, offsets = [], []
        for i, joint in enumerate(joints):
            here = _key(path, i)
            point = reader.vector(joint, "point", here)
            direction = reader.vector(joint, "direction", here, nonzero=True)
            twists.append(line_twist(point, direction, "R"))
            offsets.append(reader.number(joint, "theta", here, default=0.0, angle=True))
        mech = Mechanism.single_loop(name, names, np.array(twists), offsets=np.array(offsets), meta=info)
    return mech, assembly, couplings


def _read_mechanism(
    reader: _Reader, value: Any, name: str, meta: Mapping[str, Any]
) -> tuple[Mechanism, Couplings]:
    """The ``[mechanism]`` table: revolute and prismatic joints between named bodies."""
    section = reader.table(value, "mechanism", MECHANISM_KEYS)
    planar = reader.boolean(section, "planar", "mechanism", default=False)
    joints = reader.joint_list(section, "mechanism")
    path = "mechanism.joints"
    for i, joint in enumerate(joints):
        reader.check_keys(joint, _key(path, i), MECHANISM_JOINT_KEYS)
    if not joints:
        raise reader.error(path, "expected at least one joint, got none")
    names = reader.joint_names(joints, path)
    entries: list[dict[str, Any]] = []
    for i, joint in enumerate(joints):
        here = _key(path, i)
        kind = reader.choice(joint, "type", here, ("R", "P"), default="R")
        bodies = reader.require(joint, "bodies", here, 'the two bodies it joins, e.g. ["ground", "crank"]')
        if (
            not isinstance(bodies, list)
            or len(bodies) != 2
            or not all(isinstance(b, str) and b.strip() for b in bodies)
        ):
            raise reader.error(
                _key(here, "bodies"),
                f'expected the two bodies it joins, e.g. ["ground", "crank"], got {_show(bodies)}',
            )
        if bodies[0] == bodies[1]:
            raise reader.error(
                _key(here, "bodies"), f'expected two different bodies, got "{bodies[0]}" joined to itself'
            )
        point, direction = _joint_line(reader, joint, here, kind, planar)
        value_ = reader.number(joint, "value", here, default=0.0, angle=kind == "R")
        entries.append(
            {
                "name": names[i],
                "type": kind,
                "bodies": list(bodies),
                "point": point,
                "direction": direction,
                "value": value_,
            }
        )
    _check_connected(reader, [tuple(e["bodies"]) for e in entries], path)
    couplings = reader.couplings(section, "mechanism", names, [e["type"] for e in entries])
    mech = Mechanism.from_joints(name, entries, planar=planar, meta={**meta, "form": "mechanism"})
    if not mech.loops:
        raise reader.error(
            path,
            "the joints form no closed loop (the bodies are joined as a tree); expected at least one loop",
        )
    if len(mech.loops) == 1 and len(mech.loops[0].joints) < MIN_LOOP_JOINTS:
        members = ", ".join(names[j] for j in mech.loops[0].joints)
        raise reader.error(
            path,
            f"the only loop ({members}) has {len(mech.loops[0].joints)} joints; a closed loop needs at least "
            f"{MIN_LOOP_JOINTS} to move",
        )
    return mech, couplings


def _read_points(reader: _Reader, value: Any, mech: Mechanism) -> list[dict[str, Any]]:
    """The optional ``[[points]]`` tables: named points (``name``, ``body``, ``position`` in the start
    configuration) whose world coordinates ``points.csv`` follows along the path."""
    if not isinstance(value, list):
        raise reader.error("points", f"expected [[points]] tables, got {_show(value)}")
    out: list[dict[str, Any]] = []
    taken = set(mech.joint_names)
    for i, entry in enumerate(value):
        here = _key("points", i)
        entry = reader.table(entry, here, POINT_KEYS)
        name = reader.string(entry, "name", here, default=f"P{i + 1}")
        if name in taken or not _JOINT_NAME.fullmatch(name):
            raise reader.error(_key(here, "name"), f"expected a new name without spaces, got {_show(name)}")
        taken.add(name)
        body = reader.require(entry, "body", here, f"one of the bodies {', '.join(mech.bodies)}")
        if body not in mech.bodies:
            raise reader.error(
                _key(here, "body"), f"expected one of {', '.join(mech.bodies)}, got {_show(body)}"
            )
        position = reader.vector(entry, "position", here, sizes=(2, 3))
        position = np.append(position, 0.0) if position.size == 2 else position
        out.append({"name": name, "body": body, "position": [float(x) for x in position]})
    return out


def _joint_line(
    reader: _Reader, joint: Mapping[str, Any], here: str, kind: str, planar: bool
) -> tuple[Array, Array]:
    """Point and direction of a ``[[mechanism.joints]]`` entry as 3-vectors.

    In a planar mechanism a revolute joint turns about z (``direction`` may be omitted, or ``[0, 0, +-1]``)
    and a prismatic joint slides in the plane; points and prismatic directions may be 2-vectors.
    """
    if not planar:
        point = reader.vector(joint, "point", here, default=(0.0, 0.0, 0.0) if kind == "P" else None)
        return point, reader.vector(joint, "direction", here, nonzero=True)
    point = reader.vector(joint, "point", here, sizes=(2, 3), default=(0.0, 0.0) if kind == "P" else None)
    point = np.append(point, 0.0) if point.size == 2 else point
    if kind == "R":
        direction = reader.vector(joint, "direction", here, nonzero=True, default=(0.0, 0.0, 1.0))
        if np.linalg.norm(direction[:2]) > 1e-12 * np.linalg.norm(direction):
            raise reader.error(
                _key(here, "direction"),
                f"expected [0, 0, 1] or [0, 0, -1]: a revolute joint of a planar mechanism turns about z, "
                f"got {_show(joint['direction'])}",
            )
        return point, direction
    direction = reader.vector(joint, "direction", here, sizes=(2, 3), nonzero=True)
    direction = np.append(direction, 0.0) if direction.size == 2 else direction
    if abs(direction[2]) > 1e-12 * np.linalg.norm(direction):
        raise reader.error(
            _key(here, "direction"),
            f"expected a direction in the plane (z = 0) for a prismatic joint of a planar mechanism, "
            f"got {_show(joint['direction'])}",
        )
    return point, direction


def _check_connected(reader: _Reader, pairs: Sequence[tuple[str, str]], path: str) -> None:
    """Every body must be reached from the ground (or the first body) through joints."""
    bodies = list(dict.fromkeys(b for pair in pairs for b in pair))
    root = "ground" if "ground" in bodies else bodies[0]
    adjacency: dict[str, list[str]] = {b: [] for b in bodies}
    for a, b in pairs:
        adjacency[a].append(b)
        adjacency[b].append(a)
    reached = {root}
    queue = deque([root])
    while queue:
        for other in adjacency[queue.popleft()]:
            if other not in reached:
                reached.add(other)
                queue.append(other)
    lost = [b for b in bodies if b not in reached]
    if lost:
        first = next(i for i, pair in enumerate(pairs) if pair[0] in lost or pair[1] in lost)
        shown = ", ".join(f'"{b}"' for b in lost)
        raise reader.error(
            _key(_key(path, first), "bodies"),
            f'bodies {shown} are not connected to "{root}" through any joint; '
            "expected one connected mechanism",
        )


# ----------------------------------------------------------------------------------------------------------
# writing
def dump_spec(mech: Mechanism) -> str:
    """A spec file (TOML text) describing ``mech`` in its current reference configuration, angles in degrees.

    A single loop of revolute joints in loop order is written in the ``[loop]`` ``hinge-lines`` form, anything
    else in the ``[mechanism]`` form; couplings and fixed joints are written as ``couple`` and ``fixed``.
    :func:`load_spec` of the text gives back the same joints, twists (to rounding), offsets, bodies, loops and
    couplings, and the named points ``meta["points"]`` as ``[[points]]``; the rest of ``meta`` is not
    written.

    Parameters
    ----------
    mech
        The mechanism to describe.

    Returns
    -------
    str
        The TOML text, starting with a header comment.
    """
    n = mech.n_joints
    lines = [
        f"# {' '.join(mech.name.split())}: linkage spec written by linkwork.io.spec.dump_spec.",
        "# Joint lines are given in the start configuration, where every joint is at displacement 0",
        "# and reads `theta` / `value` (degrees for a revolute joint, length for a prismatic one).",
        "# See docs/spec-format.md.",
        f"name = {_toml_string(mech.name)}",
        'angles = "deg"',
        "",
    ]
    single = _is_single_loop(mech)
    section = "loop" if single else "mechanism"
    lines.append(f"[{section}]")
    if single:
        lines.append('convention = "hinge-lines"')
    else:
        lines.append(f"planar = {'true' if mech.planar else 'false'}")
    members = [m for m in mech.group_members() if len(m) > 1]
    if members:
        groups = ", ".join(
            "[" + ", ".join(_toml_string(mech.joint_names[j]) for j in m) + "]" for m in members
        )
        lines.append(f"couple = [{groups}]")
    fixed = np.flatnonzero(mech.groups < 0)
    if fixed.size:
        lines.append("fixed = [" + ", ".join(_toml_string(mech.joint_names[j]) for j in fixed) + "]")
    for j in range(n):
        omega, v = mech.twists[j, :3], mech.twists[j, 3:]
        kind = mech.joint_types[j]
        if kind == "R":
            point, direction = np.cross(omega, v) / float(omega @ omega), omega
        else:
            point, direction = np.zeros(3), v
        lines += ["", f"[[{section}.joints]]", f"name = {_toml_string(mech.joint_names[j])}"]
        reading = math.degrees(mech.offsets[j]) if kind == "R" else float(mech.offsets[j])
        if single:
            lines += [f"point = {_toml_vector(point)}", f"direction = {_toml_vector(direction)}"]
            lines.append(f"theta = {_toml_float(reading)}")
            continue
        a, b = mech.joint_bodies[j]
        lines += [f'type = "{kind}"', f"bodies = [{_toml_string(a)}, {_toml_string(b)}]"]
        flat = mech.planar and abs(point[2]) == 0.0
        lines.append(f"point = {_toml_vector(point[:2] if flat else point)}")
        if mech.planar and kind == "R" and direction[0] == direction[1] == 0.0:
            if direction[2] < 0.0:
                lines.append("direction = [0.0, 0.0, -1.0]")
        elif mech.planar and kind == "P" and direction[2] == 0.0:
            lines.append(f"direction = {_toml_vector(direction[:2])}")
        else:
            lines.append(f"direction = {_toml_vector(direction)}")
        lines.append(f"value = {_toml_float(reading)}")
    for point in mech.meta.get("points", ()):
        lines += ["", "[[points]]", f"name = {_toml_string(str(point['name']))}"]
        lines += [
            f"body = {_toml_string(str(point['body']))}",
            f"position = {_toml_vector(point['position'])}",
        ]
    return "\n".join(lines) + "\n"


def _is_single_loop(mech: Mechanism) -> bool:
    """True when ``mech`` is exactly what :meth:`Mechanism.single_loop` builds from revolute joints."""
    n = mech.n_joints
    if mech.planar or len(mech.loops) != 1 or any(t != "R" for t in mech.joint_types):
        return False
    loop = mech.loops[0]
    if loop.joints != tuple(range(n)) or any(s != 1 for s in loop.signs):
        return False
    bodies = tuple(f"link{i}" for i in range(n))
    return not mech.joint_bodies or mech.joint_bodies == tuple((bodies[i - 1], bodies[i]) for i in range(n))


def _toml_float(value: float) -> str:
    """A TOML float that reads back to the same double (``repr`` precision); round-off below 1e-15 is 0."""
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"cannot write the non-finite number {value} to a spec file")
    if abs(value) < 1e-15:
        value = 0.0
    return repr(value)


def _toml_vector(values: Array) -> str:
    return "[" + ", ".join(_toml_float(x) for x in values) + "]"


def _toml_string(text: str) -> str:
    """A TOML basic string with the characters TOML requires escaped."""
    out = ['"']
    for ch in text:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ch == "\n":
            out.append("\\n")
        elif ch == "\t":
            out.append("\\t")
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04x}")
        else:
            out.append(ch)
    out.append('"')
    return "".join(out)

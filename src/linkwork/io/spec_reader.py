"""Reading a spec file's tables: the key tables, the spec reader (joints, joint names, couplings) and the
``[loop]``, ``[mechanism]`` and ``[[points]]`` sections, each into the pieces of a :class:`Mechanism`.

:func:`linkwork.io.spec.load_spec` is the entry point; this module holds its steps. Key paths count array items
from 0 (``loop.joints[2]`` is the third joint), as every reader of :mod:`linkwork.io.toml_reader` does.
"""

from __future__ import annotations

import re
from collections import deque
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from linkwork.geometry import line_twist
from linkwork.geometry.names import default_joint_name
from linkwork.io.toml_reader import MAX_NAME_CHARS, TomlReader, closest, key_path, show
from linkwork.kinematics.chains import Assembly, from_dh, from_rods
from linkwork.kinematics.mechanism import Array, Mechanism
from linkwork.names import canonical, name_problem

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

#: Joint names end up in CSV headers and in flags such as ``--until A=30`` and ``--couple A=C``: no spaces,
#: quotes, ``=`` or ``,``, and none of the characters the name policy refuses in every name
#: (:func:`linkwork.names.name_problem`: control characters, bidirectional controls).
_JOINT_NAME = re.compile(r"[^\s=,\"'\x00-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]+")

_show = show
_closest = closest
_key = key_path


class SpecReader(TomlReader):
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
            name = canonical(name)  # "é" typed two ways is one name (names.canonical)
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
            value = canonical(value)
            if value not in names:
                close = _closest(value, names)
                hint = f'did you mean "{close}"? ' if close else ""
                raise self.error(key, f"unknown joint {_show(value)}; {hint}joints are {known}")
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
            if len(set(members)) != len(members):  # the words of --couple A=A
                raise self.error(key, f"names a joint twice; expected distinct joints, got {_show(group)}")
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


def read_loop_table(
    reader: SpecReader, value: Any, name: str, meta: Mapping[str, Any], closure_tol: float = 1e-12
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
        twists, offsets, points = [], [], []
        for i, joint in enumerate(joints):
            here = _key(path, i)
            point = reader.vector(joint, "point", here)
            direction = reader.vector(joint, "direction", here, nonzero=True)
            twists.append(line_twist(point, direction, "R"))
            points.append(point)
            offsets.append(reader.number(joint, "theta", here, default=0.0, angle=True))
        mech = Mechanism.single_loop(
            name, names, np.array(twists), offsets=np.array(offsets), meta=info, hinge_points=np.array(points)
        )
    return mech, assembly, couplings


def read_mechanism_table(
    reader: SpecReader, value: Any, name: str, meta: Mapping[str, Any]
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
        for b, body in enumerate(bodies):
            if len(body) > MAX_NAME_CHARS:
                raise reader.error(
                    _key(_key(here, "bodies"), b),
                    f"expected a body name of at most {MAX_NAME_CHARS} characters, got {len(body)}: {_show(body)}",
                )
            if name_problem(body, tab=True) is not None:
                raise reader.error(
                    _key(_key(here, "bodies"), b),
                    f"expected {name_problem(body, tab=True)}, got {_show(body)}",
                )
        bodies = [canonical(b) for b in bodies]  # one body however its name's accents were typed
        if bodies[0] == bodies[1]:
            raise reader.error(
                _key(here, "bodies"),
                f"expected two different bodies, got {_show(bodies[0])} joined to itself",
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


def read_points_table(reader: SpecReader, value: Any, mech: Mechanism) -> list[dict[str, Any]]:
    """The optional ``[[points]]`` tables: named points (``name``, ``body``, ``position`` in the start
    configuration) whose world coordinates ``points.csv`` follows along the path."""
    if not isinstance(value, list):
        raise reader.error("points", f"expected [[points]] tables, got {_show(value)}")
    out: list[dict[str, Any]] = []
    taken = set(mech.joint_names)
    for i, entry in enumerate(value):
        here = _key("points", i)
        entry = reader.table(entry, here, POINT_KEYS)
        name = canonical(reader.string(entry, "name", here, default=f"P{i + 1}", limit=MAX_NAME_CHARS))
        if name in taken or not _JOINT_NAME.fullmatch(name):
            raise reader.error(_key(here, "name"), f"expected a new name without spaces, got {_show(name)}")
        taken.add(name)
        body = reader.require(entry, "body", here, f"one of the bodies {', '.join(mech.bodies)}")
        body = canonical(body) if isinstance(body, str) else body
        if body not in mech.bodies:
            raise reader.error(
                _key(here, "body"), f"expected one of {', '.join(mech.bodies)}, got {_show(body)}"
            )
        position = reader.vector(entry, "position", here, sizes=(2, 3))
        position = np.append(position, 0.0) if position.size == 2 else position
        out.append({"name": name, "body": body, "position": [float(x) for x in position]})
    return out


def _joint_line(
    reader: SpecReader, joint: Mapping[str, Any], here: str, kind: str, planar: bool
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


def _check_connected(reader: SpecReader, pairs: Sequence[tuple[str, str]], path: str) -> None:
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

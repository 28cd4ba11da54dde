"""Writing a spec file: the TOML text of a :class:`~linkwork.kinematics.mechanism.Mechanism` (the inverse of
:func:`linkwork.io.spec.load_spec`).

A single loop of revolute joints in loop order is written in the ``[loop]`` ``hinge-lines`` form, anything else in
the ``[mechanism]`` form (``docs/spec-format.md``). Numbers are written with ``repr`` precision, so the file reads
back to the same doubles.
"""

from __future__ import annotations

import math

import numpy as np

from linkwork.kinematics.mechanism import Array, Mechanism

__all__ = ["dump_spec"]


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
    single = _is_single_loop(mech)
    lines = _header_lines(mech) + _section_lines(mech, single)
    for j in range(mech.n_joints):
        lines += _joint_lines(mech, j, single)
    lines += _point_lines(mech)
    return "\n".join(lines) + "\n"


def _header_lines(mech: Mechanism) -> list[str]:
    """The comment saying what the file is, then ``name`` and ``angles``."""
    return [
        f"# {' '.join(mech.name.split())}: linkage spec written by linkwork.io.spec.dump_spec.",
        "# Joint lines are given in the start configuration, where every joint is at displacement 0",
        "# and reads `theta` / `value` (degrees for a revolute joint, length for a prismatic one).",
        "# See docs/spec-format.md.",
        f"name = {_toml_string(mech.name)}",
        'angles = "deg"',
        "",
    ]


def _section_lines(mech: Mechanism, single: bool) -> list[str]:
    """The ``[loop]`` or ``[mechanism]`` table's own keys: the convention or ``planar``, ``couple``, ``fixed``."""
    lines = ["[loop]", 'convention = "hinge-lines"'] if single else ["[mechanism]"]
    if not single:
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
    return lines


def _joint_lines(mech: Mechanism, j: int, single: bool) -> list[str]:
    """Joint ``j``'s ``[[loop.joints]]`` (point, direction, theta) or ``[[mechanism.joints]]`` table (type, bodies,
    point, direction, value; a planar mechanism's points and directions in 2-D where they can be)."""
    omega, v = mech.twists[j, :3], mech.twists[j, 3:]
    kind = mech.joint_types[j]
    if kind == "R":
        point, direction = np.cross(omega, v) / float(omega @ omega), omega
    else:
        point, direction = np.zeros(3), v
    section = "loop" if single else "mechanism"
    lines = ["", f"[[{section}.joints]]", f"name = {_toml_string(mech.joint_names[j])}"]
    reading = math.degrees(mech.offsets[j]) if kind == "R" else float(mech.offsets[j])
    if single:
        lines += [f"point = {_toml_vector(point)}", f"direction = {_toml_vector(direction)}"]
        lines.append(f"theta = {_toml_float(reading)}")
        return lines
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
    return lines


def _point_lines(mech: Mechanism) -> list[str]:
    """One ``[[points]]`` table per named point of ``mech.meta["points"]``."""
    lines: list[str] = []
    for point in mech.meta.get("points", ()):
        lines += ["", "[[points]]", f"name = {_toml_string(str(point['name']))}"]
        lines += [
            f"body = {_toml_string(str(point['body']))}",
            f"position = {_toml_vector(point['position'])}",
        ]
    return lines


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

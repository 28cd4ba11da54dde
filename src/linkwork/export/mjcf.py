"""The mechanism as a MuJoCo model (MJCF): one body per link, a hinge (slide) joint named after each of our joints,
and one ``weld`` equality constraint closing each loop (plus a ``joint`` equality for every coupled or fixed
joint).

Every body's frame is the world frame in the mechanism's reference configuration, so a joint's ``pos`` and
``axis`` are its axis line there and its ``qpos`` is our displacement ``q = value - offset`` (MuJoCo's ``qpos0 =
0`` is the reference). The bodies form a spanning tree of the body graph rooted at ``ground`` (or the first body),
fixed to the world. A joint that closes a loop (not in the tree) is cut: its hinge goes on an extra body
``<before>__cut_<joint>`` hung from the body before it, and a ``weld`` holds that body on the body after it, in
the relative pose the two have at ``qpos0`` (``relpose`` with a zero quaternion). That is the one spelling MuJoCo
and pinocchio read alike: an explicit ``relpose`` is body2's pose in body1's *body* frame for MuJoCo, but in the
frame of body1's *joint* (placed at the hinge) for ``pinocchio.buildModelAndConstraintsFromMJCF``, so the identity
``relpose`` welded the two hinge points together there (a violation of 2.0 for the four-bar at the start). A
position actuator named ``drive`` turns the drive joint. Links are drawn as capsules between their joints (no
contacts), which also gives the bodies mass.
"""

from __future__ import annotations

from collections import deque

import numpy as np

from linkwork.io.writer import require_finite
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.positions import joint_points
from linkwork.names import MJCF_RESERVED, NameMap, xml_attribute, xml_names

#: A weld's ``relpose`` that means "as at qpos0" to MuJoCo and pinocchio alike (the quaternion part all zeros).
QPOS0_RELPOSE = "0 0 0 0 0 0 0"

#: Capsule radius and pin length as fractions of the median distance between a body's joints.
CAPSULE_RADIUS = 0.03


def cut_body(before: str, joint: str) -> str:
    """Name of the extra body that carries the hinge of a loop-closing joint."""
    return f"{before}__cut_{joint}"


def spanning_tree(mech: Mechanism) -> tuple[str, dict[str, list[tuple[int, str]]], list[int]]:
    """Root body, children of every body as ``(joint, child)`` and the loop-closing joints (breadth first)."""
    root = mech.ground
    if root is None:
        raise ValueError(f"{mech.name}: no bodies to export (a loop given by its twists alone)")
    children: dict[str, list[tuple[int, str]]] = {b: [] for b in mech.bodies}
    seen = {root}
    used: set[int] = set()
    queue = deque([root])
    while queue:
        body = queue.popleft()
        for j, (a, b) in enumerate(mech.joint_bodies):
            other = b if a == body else a if b == body else None
            if other is None or other in seen:
                continue
            seen.add(other)
            used.add(j)
            children[body].append((j, other))
            queue.append(other)
    return root, children, [j for j in range(mech.n_joints) if j not in used]


def _vec(x: np.ndarray) -> str:
    return " ".join(f"{v:.12g}" for v in x)


def mjcf_names(mech: Mechanism) -> tuple[NameMap, NameMap]:
    """The MJCF names of the bodies (the cut bodies of :func:`cut_body` included) and of the joints: the name
    policy's :func:`linkwork.names.xml_names` (MuJoCo's reserved ``world`` is mapped, characters XML forbids
    replaced, every name unique); :func:`linkwork.names.describe` reports the changes."""
    cuts = spanning_tree(mech)[2]
    cut_names = [cut_body(mech.joint_bodies[j][0], mech.joint_names[j]) for j in cuts]
    bodies = xml_names("MJCF body", [*mech.bodies, *cut_names], MJCF_RESERVED)
    return bodies, xml_names("MJCF joint", mech.joint_names)


def _joint_xml(mech: Mechanism, j: int, points: np.ndarray, flip: bool, joints: NameMap) -> str:
    """The MJCF joint of our joint ``j``; ``flip`` when the body it moves is the one *before* it."""
    sign = -1.0 if flip else 1.0
    name = xml_attribute(joints[mech.joint_names[j]])
    w, v = mech.twists[j, :3], mech.twists[j, 3:]
    if mech.joint_types[j] == "P":
        return f'<joint name={name} type="slide" pos="{_vec(points[j])}" axis="{_vec(sign * v)}"/>'
    return f'<joint name={name} type="hinge" pos="{_vec(points[j])}" axis="{_vec(sign * w)}"/>'


def _capsules(mech: Mechanism, body: str, points: np.ndarray, radius: float) -> list[str]:
    """Capsules between consecutive joints of ``body`` (a sphere for a body with one joint)."""
    joints = [j for j, pair in enumerate(mech.joint_bodies) if body in pair]
    ends = [points[j] for j in joints]
    out = []
    for a, b in zip(ends, ends[1:] + ends[:1] if len(ends) > 2 else ends[1:], strict=False):
        if np.linalg.norm(b - a) > 1e-9:
            out.append(f'<geom type="capsule" fromto="{_vec(a)} {_vec(b)}" size="{radius:.6g}"/>')
    if not out:
        out.append(f'<geom type="sphere" pos="{_vec(ends[0])}" size="{2 * radius:.6g}"/>')
    return out


def mjcf(mech: Mechanism, drive: str | int | None = None) -> str:
    """The MJCF text of ``mech`` (see the module docstring); ``drive`` (default: the first joint) gets a position
    actuator."""
    points = require_finite(joint_points(mech), f"{mech.name}: the joints' positions")
    require_finite(mech.twists, f"{mech.name}: the joints' axes")
    spread = np.linalg.norm(points - points.mean(axis=0), axis=1)
    radius = CAPSULE_RADIUS * float(np.median(spread[spread > 0])) if np.any(spread > 0) else 0.03
    root, children, cuts = spanning_tree(mech)
    bodies, joints = mjcf_names(mech)
    lines: list[str] = []

    def emit(body: str, joint: int | None, depth: int) -> None:
        pad = " " * depth
        lines.append(f'{pad}<body name={xml_attribute(bodies[body])} pos="0 0 0">')
        if joint is not None:
            flip = mech.joint_bodies[joint][1] != body
            lines.append(pad + " " + _joint_xml(mech, joint, points, flip, joints))
        lines.extend(pad + " " + g for g in _capsules(mech, body, points, radius))
        for j in cuts:
            if mech.joint_bodies[j][0] == body:
                lines.append(
                    f'{pad} <body name={xml_attribute(bodies[cut_body(body, mech.joint_names[j])])} pos="0 0 0">'
                )
                lines.append(pad + "  " + _joint_xml(mech, j, points, False, joints))
                lines.append(f'{pad}  <geom type="sphere" pos="{_vec(points[j])}" size="{radius:.6g}"/>')
                lines.append(f"{pad} </body>")
        for j, child in children[body]:
            emit(child, j, depth + 1)
        lines.append(f"{pad}</body>")

    emit(root, None, 4)
    welds = [
        f"    <weld name={xml_attribute('loop_' + joints[mech.joint_names[j]])} "
        f"body1={xml_attribute(bodies[cut_body(mech.joint_bodies[j][0], mech.joint_names[j])])} "
        f'body2={xml_attribute(bodies[mech.joint_bodies[j][1]])} relpose="{QPOS0_RELPOSE}"/>'
        for j in cuts
    ]
    welds += _coupling_constraints(mech, joints)
    d = mech.index(drive if drive is not None else 0)
    head = [
        f"<mujoco model={xml_attribute(mech.name)}>",
        "  <!-- written by linkwork: bodies at the world frame in the reference configuration; joint qpos is the",
        "       displacement from it (value - offset); one weld per loop closes it at a cut joint -->",
        '  <compiler angle="radian" autolimits="true"/>',
        '  <option gravity="0 0 0" timestep="0.001" integrator="implicitfast"/>',
        '  <default><joint damping="1" armature="0.01"/><geom contype="0" conaffinity="0" density="1000"/>',
        '    <equality solref="0.002 1" solimp="0.9999 0.9999 0.001"/></default>',
        "  <worldbody>",
    ]
    tail = [
        "  </worldbody>",
        "  <equality>",
        *welds,
        "  </equality>",
        "  <actuator>",
        f'    <position name="drive" joint={xml_attribute(joints[mech.joint_names[d]])} kp="1000" kv="50"/>',
        "  </actuator>",
        "</mujoco>",
    ]
    return "\n".join(head + lines + tail) + "\n"


def _coupling_constraints(mech: Mechanism, joints: NameMap) -> list[str]:
    """``joint`` equality constraints for couplings (a coupled joint turns as the first of its group: equal
    displacements from the start) and fixed joints (held at the start)."""
    out = []
    for members in mech.group_members():
        first = xml_attribute(joints[mech.joint_names[members[0]]])
        for j in members[1:]:
            out.append(
                f"    <joint name={xml_attribute('couple_' + joints[mech.joint_names[j]])} "
                f'joint1={xml_attribute(joints[mech.joint_names[j]])} joint2={first} polycoef="0 1 0 0 0"/>'
            )
    for k in np.flatnonzero(mech.groups < 0).tolist():
        name = joints[mech.joint_names[k]]
        out.append(
            f'    <joint name={xml_attribute("fixed_" + name)} joint1={xml_attribute(name)} polycoef="0 0 0 0 0"/>'
        )
    return out


def joint_offsets(mech: Mechanism) -> dict[str, float]:
    """Our joint values at MuJoCo's ``qpos = 0``: ``value = offset + qpos`` for every joint (cut ones too)."""
    return {name: float(mech.offsets[j]) for j, name in enumerate(mech.joint_names)}

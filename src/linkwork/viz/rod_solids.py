"""The designed solids of built-in linkages, in their own design configuration: Hedgepeth's triangular rods
(Gan & Pellegrino 2006, Sec. 3, Fig. 5), the mitred rods of :mod:`linkwork.linkages.hedgepeth_rods`, and Guest's
frame (Sec. 6).

Each function returns ``(bodies, pins, points, directions)``: the meshes and the joint lines they were built on,
which :mod:`linkwork.viz.solids` maps onto the mechanism's reference configuration body by body; ``None`` when the
mechanism is not the linkage the style draws (then it is drawn with round bars).
"""

from __future__ import annotations

import numpy as np

from linkwork.kinematics.mechanism import Mechanism
from linkwork.viz.mesh import PIN_COLOR, ROD_COLORS, Array, Mesh, cut_prism, cylinder, prism_faces
from linkwork.viz.mesh import unit as _unit

__all__ = ["ROD_WIDTH", "guest_design", "hedgepeth_design", "hedgepeth_rods_design"]

ROD_WIDTH = 0.2  # Hedgepeth rod: side of the triangle section / rod length

Design = tuple[dict[str, Mesh], list[Mesh], Array, Array]
"""Body meshes, pins, and the joint lines (points, directions) of the design configuration."""


def _rod_frames(mech: Mechanism) -> list[Array]:
    """Frames of the paper's rod chain at the mechanism's reference values: ``F[k]`` has joint ``k`` on its z-axis.

    Factor ``k`` is ``C_k Rz(theta_k)`` (Eq. (12)); joint ``k``'s axis is the z-axis after ``C_k``.
    """
    from linkwork.geometry import rot_z
    from linkwork.kinematics.chains import rod_transform

    g = np.eye(4)
    frames = []
    for k, rod in enumerate(mech.meta["rods"]):
        g = g @ rod_transform(rod["phi"], rod["omega"], rod["psi"], rod["v"])
        frames.append(g.copy())
        g = g @ rot_z(mech.offsets[k])
    return frames


def hedgepeth_design(mech: Mechanism) -> Design | None:
    """Hedgepeth's triangular rods in the rod chain's own frame (Sec. 3, Fig. 5).

    Body ``link{i}`` (after joint ``i``) is the rod from joint ``i``'s frame origin to joint ``i+1``'s along its
    apex line. Its section is an isosceles triangle, apex on the apex line, apex angle ``alpha1 = 2 pi / n``,
    equal sides along the half-lines ``h_i``, ``h_{i+1}``: the hinge axes projected across the rod, with
    alternating signs so that the n sections tile a regular n-gon around the bundle's axis (Fig. 5(a)).
    """
    n = mech.n_joints
    frames = _rod_frames(mech)
    if np.max(np.abs(frames[-1] @ _rz(mech.offsets[-1]) - np.eye(4))) > 1e-6:
        return None
    origins = np.array([F[:3, 3] for F in frames])
    axes = np.array([F[:3, 2] for F in frames])
    lengths = np.linalg.norm(np.roll(origins, -1, axis=0) - origins, axis=1)
    width = ROD_WIDTH * float(np.median(lengths))
    bodies: dict[str, Mesh] = {}
    for i in range(n):
        a, b = i, (i + 1) % n
        if mech.joint_bodies[a][1] != mech.joint_bodies[b][0]:
            return None
        body = mech.joint_bodies[a][1]
        o0, o1 = origins[a], origins[b]
        u = _unit(o1 - o0)
        h0 = _unit(axes[a] - (axes[a] @ u) * u) * (1.0 if a % 2 == 0 else -1.0)
        h1 = _unit(axes[b] - (axes[b] @ u) * u) * (1.0 if b % 2 == 0 else -1.0)
        if np.cross(h0, h1) @ u < 0:  # keep the section counter-clockwise about the axis
            h0, h1 = h1, h0
        bisector = _unit(h0 + h1)
        side_normal = np.cross(u, bisector)  # normal of the rod's plane of symmetry
        planes = []
        for origin, z in ((o0, axes[a]), (o1, axes[b])):
            m = np.cross(z, side_normal)  # contains z; normal in the plane of symmetry
            planes.append((origin, _unit(m)))
        section = np.array([o0, o0 + width * h0, o0 + width * h1])
        vertices = cut_prism(section, u, planes[0], planes[1])
        color = ROD_COLORS[i % 2]
        bodies[body] = Mesh(vertices, prism_faces(3), color=color, kind="rod", name=body)
    pins = []
    for j in range(n):
        half = 0.5 * width * axes[j]
        pins.append(
            cylinder(
                origins[j] - half,
                origins[j] + half,
                0.12 * width,
                color=PIN_COLOR,
                kind="pin",
                name=mech.joint_names[j],
            )
        )
    bodies = {name: bodies[name] for name in mech.bodies}
    return bodies, pins, origins, axes


def hedgepeth_rods_design(mech: Mechanism) -> Design | None:
    """The mitred triangular rods of :mod:`linkwork.linkages.hedgepeth_rods`, in the folded bundle.

    Rod ``i`` is the prism of isosceles section (apex on the apex line, equal sides ``width`` at ``+-180/n``
    from the section's axis) between the mitre planes ``x cos(beta) +- y sin(beta) = ...`` of its body frame; the
    pins run along the hinge edges from the apex to the base corner of the end section.
    """
    from linkwork.linkages.hedgepeth_rods import hinge_edge, rod_frame, start_face_sign

    n = int(mech.meta.get("n", mech.n_joints))
    if n != mech.n_joints or len(mech.bodies) != n:
        return None
    width = float(mech.meta.get("width", ROD_WIDTH))
    beta = np.pi / n
    corner = width * np.array([np.sin(beta), np.cos(beta)])
    bodies: dict[str, Mesh] = {}
    points, axes = np.zeros((n, 3)), np.zeros((n, 3))
    pins = []
    for i in range(n):
        F = rod_frame(n, i)
        R, o = F[:3, :3], F[:3, 3]
        section = (
            o + np.array([[0.0, 0.0, 0.0], [0.0, corner[0], corner[1]], [0.0, -corner[0], corner[1]]]) @ R.T
        )
        start = (o, R @ np.array([np.cos(beta), np.sin(beta), 0.0]))
        end = (o + R[:, 0], R @ np.array([np.cos(beta), -np.sin(beta), 0.0]))
        vertices = cut_prism(section, R[:, 0], start, end)
        bodies[mech.joint_bodies[i][1]] = Mesh(
            vertices, prism_faces(3), color=ROD_COLORS[i % 2], kind="rod", name=mech.joint_bodies[i][1]
        )
        sign = start_face_sign(i)
        edge = R @ hinge_edge(n, sign)
        length = width / float(hinge_edge(n, sign) @ np.array([0.0, 0.0, 1.0])) * np.cos(beta)
        points[i], axes[i] = o, -sign * edge
        pins.append(
            cylinder(
                o, o + length * edge, 0.06 * width, color=PIN_COLOR, kind="pin", name=mech.joint_names[i]
            )
        )
    bodies = {name: bodies[name] for name in mech.bodies}
    return bodies, pins, points, axes


def _rz(angle: float) -> Array:
    from linkwork.geometry import rot_z

    return rot_z(angle)


def guest_design(mech: Mechanism) -> Design | None:
    """Guest's frame flat in z = 0: diamond-section rods, mitred corners, short sides cut at y = 0 (Sec. 6)."""
    from linkwork.linkages.guest import HINGE_SITES, JOINTS, guest_hinges

    if mech.joint_names != JOINTS:
        return None
    length, width, section = (float(mech.meta[k]) for k in ("length", "width", "section"))
    points, directions = guest_hinges(length, width, section)
    h = section / np.sqrt(2.0)
    ez = np.array([0.0, 0.0, 1.0])

    def site(k: int) -> tuple[Array, Array]:
        sx, sy = HINGE_SITES[k]
        centre = np.array([sx * length / 2.0, sy * width / 2.0, 0.0])
        normal = np.array([0.0, 1.0, 0.0]) if sy == 0 else _unit(np.array([sy, -sx, 0.0]))  # cut / mitre
        return centre, normal

    bodies: dict[str, Mesh] = {}
    for i in range(6):
        a, b = i, (i + 1) % 6
        body = mech.joint_bodies[a][1]
        (c0, n0), (c1, n1) = site(a), site(b)
        u = _unit(c1 - c0)
        e1 = np.cross(ez, u)  # horizontal, across the rod
        # Section diagonals horizontal and vertical; counter-clockwise about u (e1, ez, -e1, -ez).
        diamond = np.array([c0 + h * e1, c0 + h * ez, c0 - h * e1, c0 - h * ez])
        vertices = cut_prism(diamond, u, (c0, n0), (c1, n1))
        color = ROD_COLORS[0] if i in (1, 4) else ROD_COLORS[1]  # long sides, half short sides
        bodies[body] = Mesh(vertices, prism_faces(4), color=color, kind="rod", name=body)
    pins = []
    for j in range(6):
        # The hinge runs along an edge of the cut, from a horizontal vertex (z = 0) to the top one (z = h).
        d = directions[j] if directions[j][2] > 0 else -directions[j]
        top = points[j] + d * (h / d[2])
        mid = 0.5 * (points[j] + top)
        half = 0.6 * np.linalg.norm(top - points[j]) * d
        pins.append(
            cylinder(mid - half, mid + half, 0.12 * section, color=PIN_COLOR, kind="pin", name=JOINTS[j])
        )
    bodies = {name: bodies[name] for name in mech.bodies}
    return bodies, pins, points, directions

"""Independent numpy references for the audit of linkwork's tracer.

Nothing here imports linkwork: every reference (closed forms, forward kinematics, closure Jacobians and their
SVD) is computed from the geometry written in the audit's own spec dictionaries.

Conventions (docs/spec-format.md): a joint with ``bodies = [before, after]`` moves ``after`` relative to
``before`` by ``exp(xi q)``, ``xi`` the joint's line in the start configuration; its reading is
``value + q``. Body poses are 4x4 homogeneous matrices mapping start coordinates to current ones, the ground
(or the first body) held still.
"""

from __future__ import annotations

import csv
import json
from collections import deque
from pathlib import Path

import numpy as np

# ---------------------------------------------------------------------------------------------- rigid motions


def rot(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation matrix about a unit ``axis`` by ``angle`` (Rodrigues)."""
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * kx + (1 - np.cos(angle)) * kx @ kx


def about_line(point: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    """4x4 rotation by ``angle`` about the line through ``point`` along ``axis``."""
    g = np.eye(4)
    r = rot(axis, angle)
    g[:3, :3] = r
    g[:3, 3] = np.asarray(point, float) - r @ np.asarray(point, float)
    return g


def along(direction: np.ndarray, dist: float) -> np.ndarray:
    """4x4 translation by ``dist`` along the unit of ``direction``."""
    g = np.eye(4)
    d = np.asarray(direction, float)
    g[:3, 3] = dist * d / np.linalg.norm(d)
    return g


def dh(theta: float, d: float, a: float, alpha: float) -> np.ndarray:
    """``Rz(theta) Tz(d) Tx(a) Rx(alpha)`` as a 4x4 matrix (docs/spec-format.md, dh convention)."""
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array(
        [
            [ct, -st * ca, st * sa, a * ct],
            [st, ct * ca, -ct * sa, a * st],
            [0, sa, ca, d],
            [0, 0, 0, 1.0],
        ]
    )


def wrap_deg(x: np.ndarray) -> np.ndarray:
    """Angle difference wrapped into (-180, 180] degrees."""
    return (np.asarray(x) + 180.0) % 360.0 - 180.0


# ------------------------------------------------------------------------------------------- mechanisms


class Mech:
    """A mechanism as the audit writes it: joints with ``name, type, bodies, point, direction, value``.

    Angles in degrees (``value`` of a revolute joint), points 3-vectors. ``planar`` keeps 3 closure rows
    per loop (rotation about z, translation x, y).
    """

    def __init__(self, name: str, joints: list[dict], planar: bool, root: str = "ground") -> None:
        self.name = name
        self.planar = planar
        self.joints = []
        for j in joints:
            p = np.array(list(j.get("point", [0, 0, 0])) + [0.0] * (3 - len(j.get("point", [0, 0, 0]))))
            dflt = [0, 0, 1] if j.get("type", "R") == "R" else None
            d = np.array(list(j.get("direction", dflt)) + [0.0] * (3 - len(j.get("direction", dflt))), float)
            self.joints.append(
                dict(name=j["name"], type=j.get("type", "R"), bodies=list(j["bodies"]), point=p,
                     direction=d / np.linalg.norm(d), value=float(j.get("value", 0.0)))
            )
        self.names = [j["name"] for j in self.joints]
        bodies = []
        for j in self.joints:
            for b in j["bodies"]:
                if b not in bodies:
                    bodies.append(b)
        self.root = root if root in bodies else bodies[0]
        self.bodies = bodies

    # ---- TOML
    def toml(self, scale: float = 1.0, motion: np.ndarray | None = None) -> str:
        """The mechanism as a spec file; lengths times ``scale``, then moved by the 4x4 ``motion``."""
        g = np.eye(4) if motion is None else motion
        out = [f'name = "{self.name}"', "", "[mechanism]", f"planar = {'true' if self.planar else 'false'}"]
        for j in self.joints:
            p = g[:3, :3] @ (scale * j["point"]) + g[:3, 3]
            d = g[:3, :3] @ j["direction"]
            val = j["value"] * (scale if j["type"] == "P" else 1.0)
            out += ["", "[[mechanism.joints]]", f'name = "{j["name"]}"', f'type = "{j["type"]}"',
                    f'bodies = ["{j["bodies"][0]}", "{j["bodies"][1]}"]',
                    "point = [" + ", ".join(repr(float(x)) for x in p) + "]",
                    "direction = [" + ", ".join(repr(float(x)) for x in d) + "]",
                    f"value = {val!r}"]
        return "\n".join(out) + "\n"

    # ---- graph
    def tree_and_loops(self) -> tuple[dict[str, tuple[int, int]], list[list[tuple[int, int]]]]:
        """BFS spanning tree from the root, and the fundamental cycles of the joints not in it.

        Returns ``parent[body] = (joint index, sign)`` and loops as lists of ``(joint index, sign)`` (sign +1
        when the loop crosses the joint from its ``before`` body to its ``after`` body).
        """
        adj: dict[str, list[tuple[int, str, int]]] = {b: [] for b in self.bodies}
        for k, j in enumerate(self.joints):
            b0, b1 = j["bodies"]
            adj[b0].append((k, b1, +1))
            adj[b1].append((k, b0, -1))
        parent: dict[str, tuple[int, int, str] | None] = {self.root: None}
        order = [self.root]
        dq = deque([self.root])
        tree_joints = set()
        while dq:
            b = dq.popleft()
            for k, nb, s in adj[b]:
                if nb not in parent:
                    parent[nb] = (k, s, b)
                    tree_joints.add(k)
                    order.append(nb)
                    dq.append(nb)
        self.order = order
        self.parent = parent

        def path_to_root(b: str) -> list[tuple[int, int, str]]:
            out = []
            while parent[b] is not None:
                k, s, pb = parent[b]
                out.append((k, s, pb))
                b = pb
            return out

        loops = []
        for k, j in enumerate(self.joints):
            if k in tree_joints:
                continue
            b0, b1 = j["bodies"]
            # loop: root -> ... -> b0 --(k,+1)--> b1 -> ... -> root
            down0 = [(kk, ss) for kk, ss, _ in reversed(path_to_root(b0))]
            up1 = [(kk, -ss) for kk, ss, _ in path_to_root(b1)]
            loop = down0 + [(k, +1)] + up1
            # cancel the common prefix (shared tree path)
            while len(loop) >= 2 and loop[0][0] == loop[-1][0]:
                loop = loop[1:-1]
            loops.append(loop)
        return parent, loops

    # ---- kinematics from a row of readings
    def rel(self, k: int, reading: float) -> np.ndarray:
        """Relative motion of joint ``k`` (after w.r.t. before, start-frame coordinates) at ``reading``."""
        j = self.joints[k]
        if j["type"] == "R":
            return about_line(j["point"], j["direction"], np.radians(reading - j["value"]))
        return along(j["direction"], reading - j["value"])

    def poses(self, readings: dict[str, float]) -> tuple[dict[str, np.ndarray], float]:
        """Body poses from a row's joint readings along the BFS tree, and the largest closure mismatch.

        The mismatch is, over the joints not in the tree, the largest entry of
        ``g_before rel(q) - g_after`` (4x4, lengths in the mechanism's unit).
        """
        parent, _ = self.tree_and_loops()
        g = {self.root: np.eye(4)}
        for b in self.order[1:]:
            k, s, pb = parent[b]
            m = self.rel(k, readings[self.names[k]])
            g[b] = g[pb] @ (m if s > 0 else np.linalg.inv(m))
        mis = 0.0
        tree = {parent[b][0] for b in self.order[1:]}
        for k, j in enumerate(self.joints):
            if k in tree:
                continue
            b0, b1 = j["bodies"]
            mis = max(mis, float(np.abs(g[b0] @ self.rel(k, readings[j["name"]]) - g[b1]).max()))
        return g, mis

    def twist(self, k: int, g_before: np.ndarray) -> np.ndarray:
        """Current unit twist ``(w, v)`` of joint ``k`` in the world frame, its before body at ``g_before``."""
        j = self.joints[k]
        d = g_before[:3, :3] @ j["direction"]
        if j["type"] == "R":
            p = g_before[:3, :3] @ j["point"] + g_before[:3, 3]
            return np.concatenate([d, np.cross(p, d)])
        return np.concatenate([np.zeros(3), d])

    def jacobian(self, readings: dict[str, float], loops: list[list[tuple[int, int]]] | None = None,
                 columns: list[list[str]] | None = None) -> np.ndarray:
        """Closure Jacobian: per loop, the current twists ``s_i xi_i`` of its joints, the root held still.

        Rows per loop: 6 (w, v), or 3 for a planar mechanism (w_z, v_x, v_y). ``columns`` groups joints into
        unknowns (couplings: their columns add); default one unknown per joint.
        """
        g, _ = self.poses(readings)
        if loops is None:
            _, loops = self.tree_and_loops()
        cols = columns or [[n] for n in self.names]
        idx = {n: i for i, n in enumerate(self.names)}
        rows = []
        for loop in loops:
            block = np.zeros((6, len(cols)))
            for k, s in loop:
                tw = s * self.twist(k, g[self.joints[k]["bodies"][0]])
                for c, grp in enumerate(cols):
                    if self.names[k] in grp:
                        block[:, c] += tw
            rows.append(block[[2, 3, 4]] if self.planar else block)
        return np.vstack(rows)


def dh_loop_jacobian(params: list[tuple[float, float, float, float]]) -> np.ndarray:
    """6 x n closure Jacobian of a ``dh`` loop: column i the twist of joint i's axis (z of frame i-1).

    ``params`` are ``(theta, d, a, alpha)`` in radians; frame 0 (the base, on joint 1's axis) is held still.
    """
    g = np.eye(4)
    cols = []
    for th, d, a, al in params:
        z, o = g[:3, 2], g[:3, 3]
        cols.append(np.concatenate([z, np.cross(o, z)]))
        g = g @ dh(th, d, a, al)
    return np.array(cols).T


def dh_closure(params: list[tuple[float, float, float, float]]) -> float:
    """Largest entry of ``T_1 ... T_n - I`` for ``dh`` parameters in radians."""
    g = np.eye(4)
    for p in params:
        g = g @ dh(*p)
    return float(np.abs(g - np.eye(4)).max())


# --------------------------------------------------------------------------------------------- planar solving


def circles(c1: np.ndarray, r1: float, c2: np.ndarray, r2: float) -> tuple[np.ndarray, np.ndarray]:
    """The two intersections of two circles in the plane (x, y); NaN where they do not meet."""
    c1, c2 = np.asarray(c1[:2], float), np.asarray(c2[:2], float)
    dv = c2 - c1
    dd = np.hypot(*dv)
    x = (dd * dd + r1 * r1 - r2 * r2) / (2 * dd)
    h2 = r1 * r1 - x * x
    h = np.sqrt(max(h2, 0.0)) if h2 > -1e-12 * r1 * r1 else np.nan
    e = dv / dd
    n = np.array([-e[1], e[0]])
    return c1 + x * e + h * n, c1 + x * e - h * n


def pose2(p0: np.ndarray, q0: np.ndarray, p1: np.ndarray, q1: np.ndarray) -> np.ndarray:
    """Planar pose (4x4) taking the start points p0, q0 to p1, q1 (their distance must agree)."""
    a0 = np.arctan2(q0[1] - p0[1], q0[0] - p0[0])
    a1 = np.arctan2(q1[1] - p1[1], q1[0] - p1[0])
    g = about_line(np.zeros(3), [0, 0, 1], a1 - a0)
    g[:2, 3] = np.asarray(p1[:2]) - g[:2, :2] @ np.asarray(p0[:2])
    return g


def readings_from_poses(mech: Mech, g: dict[str, np.ndarray]) -> dict[str, float]:
    """Joint readings from body poses: ``g_before^-1 g_after`` projected on the joint's start line."""
    out = {}
    for j in mech.joints:
        m = np.linalg.inv(g[j["bodies"][0]]) @ g[j["bodies"][1]]
        if j["type"] == "R":
            r = m[:3, :3]
            w = j["direction"]
            # angle about w: from the rotation of a vector normal to w
            u = np.cross(w, [1.0, 0, 0]) if abs(w[0]) < 0.9 else np.cross(w, [0, 1.0, 0])
            u /= np.linalg.norm(u)
            ru = r @ u
            ang = np.arctan2(np.dot(np.cross(u, ru), w), np.dot(u, ru))
            out[j["name"]] = j["value"] + np.degrees(ang)
        else:
            out[j["name"]] = j["value"] + float(np.dot(m[:3, 3], j["direction"]))
    return out


# --------------------------------------------------------------------------------------------- reading results


def read_path_csv(folder: str | Path) -> dict[str, np.ndarray]:
    """path.csv as columns of floats."""
    with open(Path(folder) / "path.csv") as f:
        rows = list(csv.reader(f))
    head, data = rows[0], np.array(rows[1:], float)
    return {h: data[:, i] for i, h in enumerate(head)}


def read_report(folder: str | Path) -> dict:
    """report.json."""
    return json.loads((Path(folder) / "report.json").read_text())


def sigma_columns(cols: dict[str, np.ndarray]) -> np.ndarray:
    """The sigma_1..sigma_k columns of path.csv, (N, k)."""
    ks = sorted((int(h.split("_")[1]) for h in cols if h.startswith("sigma_")))
    return np.stack([cols[f"sigma_{k}"] for k in ks], axis=1)

"""Independent numpy references for tests/audit (no linkwork import): closed forms, forward kinematics, closure
Jacobians. A copy of the audit's scripts (audit/ref.py, audit/planar.py, audit/spatial.py on branch audit).

Conventions (docs/spec-format.md): a joint with ``bodies = [before, after]`` moves ``after`` relative to
``before`` by ``exp(xi q)``, ``xi`` the joint's line in the start configuration; its reading is ``value + q``.
"""

from __future__ import annotations

from collections import deque

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
                dict(
                    name=j["name"],
                    type=j.get("type", "R"),
                    bodies=list(j["bodies"]),
                    point=p,
                    direction=d / np.linalg.norm(d),
                    value=float(j.get("value", 0.0)),
                )
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
            out += [
                "",
                "[[mechanism.joints]]",
                f'name = "{j["name"]}"',
                f'type = "{j["type"]}"',
                f'bodies = ["{j["bodies"][0]}", "{j["bodies"][1]}"]',
                "point = [" + ", ".join(repr(float(x)) for x in p) + "]",
                "direction = [" + ", ".join(repr(float(x)) for x in d) + "]",
                f"value = {val!r}",
            ]
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
            loop = [*down0, (k, +1), *up1]
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

    def jacobian(
        self,
        readings: dict[str, float],
        loops: list[list[tuple[int, int]]] | None = None,
        columns: list[list[str]] | None = None,
    ) -> np.ndarray:
        """Closure Jacobian: per loop, the current twists ``s_i xi_i`` of its joints, the root held still.

        Rows per loop: 6 (w, v), or 3 for a planar mechanism (w_z, v_x, v_y). ``columns`` groups joints into
        unknowns (couplings: their columns add); default one unknown per joint.
        """
        g, _ = self.poses(readings)
        if loops is None:
            _, loops = self.tree_and_loops()
        cols = columns or [[n] for n in self.names]
        {n: i for i, n in enumerate(self.names)}
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


Z = np.array([0.0, 0.0, 1.0])


def P(x: float, y: float) -> np.ndarray:
    return np.array([x, y, 0.0])


class FourBar:
    """Ground pivots A = (0, 0), D = (g, 0); crank A-B (length a), coupler B-C (b), rocker C-D (c)."""

    inputs = ("A", "D")

    def __init__(
        self,
        name: str,
        g: float,
        a: float,
        b: float,
        c: float,
        theta0: float,
        side: int = 0,
        coupler_point: tuple[float, float] | None = None,
    ) -> None:
        self.g, self.a, self.b, self.c = g, a, b, c
        th = np.radians(theta0)
        A, D = P(0, 0), P(g, 0)
        B = P(a * np.cos(th), a * np.sin(th))
        C = circles(B, b, D, c)[side]
        self.pts = dict(A=A, B=B, C=np.array([C[0], C[1], 0.0]), D=D)
        self.mech = Mech(
            name,
            [
                dict(name="A", bodies=["ground", "crank"], point=list(A), value=theta0),
                dict(name="B", bodies=["crank", "coupler"], point=list(B)),
                dict(name="C", bodies=["coupler", "rocker"], point=list(self.pts["C"])),
                dict(name="D", bodies=["rocker", "ground"], point=list(D)),
            ],
            planar=True,
        )

    def fold_refs(self, drive: str) -> list[float]:
        """Drive readings (deg) at the drive's extremes: law of cosines, the other two links in line."""
        A, C0, D = self.pts["A"], self.pts["C"], self.pts["D"]
        out = []
        if drive == "A":
            for L in (self.b + self.c, abs(self.b - self.c)):
                cs = (self.a**2 + self.g**2 - L**2) / (2 * self.a * self.g)
                if abs(cs) <= 1:
                    out += [np.degrees(np.arccos(cs)), -np.degrees(np.arccos(cs))]
        elif drive == "D":
            for L in (self.a + self.b, abs(self.b - self.a)):
                for C1 in circles(A, L, D, self.c):
                    if not np.isnan(C1).any():
                        psi = np.arctan2(C1[1] - D[1], C1[0] - D[0]) - np.arctan2(C0[1] - D[1], C0[0] - D[0])
                        out.append(-np.degrees(psi))
        return out

    def solve(self, drive: str, reading: float) -> list[dict[str, float]]:
        A, B, C, D = (self.pts[k] for k in "ABCD")
        out = []
        if drive == "A":
            gc = about_line(A, [0, 0, 1], np.radians(reading - self.mech.joints[0]["value"]))
            B1 = gc[:3, :3] @ B + gc[:3, 3]
            for C1 in circles(B1, self.b, D, self.c):
                if np.isnan(C1).any():
                    continue
                C1 = np.array([C1[0], C1[1], 0.0])
                g = dict(ground=np.eye(4), crank=gc, coupler=pose2(B, C, B1, C1), rocker=pose2(D, C, D, C1))
                out.append(readings_from_poses(self.mech, g))
        elif drive == "D":
            # D's bodies are [rocker, ground]: the rocker turns by -q_D relative to the ground
            gr = about_line(D, [0, 0, 1], -np.radians(reading - self.mech.joints[3]["value"]))
            C1 = gr[:3, :3] @ C + gr[:3, 3]
            for B1 in circles(A, self.a, C1, self.b):
                if np.isnan(B1).any():
                    continue
                B1 = np.array([B1[0], B1[1], 0.0])
                g = dict(ground=np.eye(4), crank=pose2(A, B, A, B1), coupler=pose2(B, C, B1, C1), rocker=gr)
                out.append(readings_from_poses(self.mech, g))
        else:
            raise ValueError(drive)
        return out


class SliderCrank:
    """Crank A-B (r) about the origin, rod B-C (l), slider pin C on the line y = e; D the prismatic joint."""

    inputs = ("A", "D")

    def __init__(self, name: str, r: float, l: float, e: float, theta0: float, side: int = +1) -> None:
        self.r, self.l, self.e = r, l, e
        th = np.radians(theta0)
        B = P(r * np.cos(th), r * np.sin(th))
        x0 = B[0] + side * np.sqrt(l * l - (e - B[1]) ** 2)
        C = P(x0, e)
        self.pts = dict(A=P(0, 0), B=B, C=C)
        self.x0 = x0
        self.mech = Mech(
            name,
            [
                dict(name="A", bodies=["ground", "crank"], point=[0, 0, 0], value=theta0),
                dict(name="B", bodies=["crank", "rod"], point=list(B)),
                dict(name="C", bodies=["rod", "slider"], point=list(C)),
                dict(
                    name="D",
                    type="P",
                    bodies=["ground", "slider"],
                    point=[0, 0, 0],
                    direction=[1, 0, 0],
                    value=x0,
                ),
            ],
            planar=True,
        )

    def fold_refs(self, drive: str) -> list[float]:
        """Slider extremes (pin on the start side): crank and rod in line, x = sqrt((l +- r)^2 - e^2)."""
        if drive != "D":
            return []
        return [np.sqrt((self.l + self.r) ** 2 - self.e**2), np.sqrt((self.l - self.r) ** 2 - self.e**2)]

    def solve(self, drive: str, reading: float) -> list[dict[str, float]]:
        A, B, C = self.pts["A"], self.pts["B"], self.pts["C"]
        out = []
        if drive == "A":
            gc = about_line(A, Z, np.radians(reading - self.mech.joints[0]["value"]))
            B1 = gc[:3, :3] @ B + gc[:3, 3]
            h2 = self.l**2 - (self.e - B1[1]) ** 2
            if h2 < 0:
                return []
            for s in (+1, -1):
                C1 = P(B1[0] + s * np.sqrt(h2), self.e)
                gs = np.eye(4)
                gs[0, 3] = C1[0] - C[0]
                g = dict(ground=np.eye(4), crank=gc, rod=pose2(B, C, B1, C1), slider=gs)
                out.append(readings_from_poses(self.mech, g))
        elif drive == "D":
            C1 = P(reading, self.e)
            gs = np.eye(4)
            gs[0, 3] = C1[0] - C[0]
            for B1 in circles(A, self.r, C1, self.l):
                if np.isnan(B1).any():
                    continue
                B1 = np.array([B1[0], B1[1], 0.0])
                g = dict(ground=np.eye(4), crank=pose2(A, B, A, B1), rod=pose2(B, C, B1, C1), slider=gs)
                out.append(readings_from_poses(self.mech, g))
        else:
            raise ValueError(drive)
        return out


class _SixBar:
    """A four-bar A-B-C-D (ground pivots A, D) whose link ``CARRIER`` also carries E, and a dyad E-F-G (G on
    the ground): Watt II when the rocker carries E, Stephenson III when the coupler does.

    Bodies: ground (A, D, G), crank (A, B), coupler (B, C), rocker (C, D), link5 (E, F), link6 (F, G); E on
    ``CARRIER``. Solved by two circle intersections (every assembly).
    """

    CARRIER = ""

    def __init__(self, name: str, pts: dict[str, tuple[float, float]], theta0: float) -> None:
        self.pts = {k: P(*v) for k, v in pts.items()}
        d = lambda u, v: float(np.linalg.norm(self.pts[u] - self.pts[v]))  # noqa: E731
        self.len = {k: d(*k) for k in ["AB", "BC", "CD", "EF", "FG"]}
        self.mech = Mech(
            name,
            [
                dict(name="A", bodies=["ground", "crank"], point=list(self.pts["A"]), value=theta0),
                dict(name="B", bodies=["crank", "coupler"], point=list(self.pts["B"])),
                dict(name="C", bodies=["coupler", "rocker"], point=list(self.pts["C"])),
                dict(name="D", bodies=["rocker", "ground"], point=list(self.pts["D"])),
                dict(name="E", bodies=[self.CARRIER, "link5"], point=list(self.pts["E"])),
                dict(name="F", bodies=["link5", "link6"], point=list(self.pts["F"])),
                dict(name="G", bodies=["link6", "ground"], point=list(self.pts["G"])),
            ],
            planar=True,
        )

    def solve(self, drive: str, reading: float) -> list[dict[str, float]]:
        assert drive == "A"
        p = self.pts
        gc = about_line(p["A"], Z, np.radians(reading - self.mech.joints[0]["value"]))
        B1 = gc[:3, :3] @ p["B"] + gc[:3, 3]
        out = []
        for C1 in circles(B1, self.len["BC"], p["D"], self.len["CD"]):
            if np.isnan(C1).any():
                continue
            C1 = np.array([*C1, 0.0])
            poses = dict(coupler=pose2(p["B"], p["C"], B1, C1), rocker=pose2(p["D"], p["C"], p["D"], C1))
            carrier = poses[self.CARRIER]
            E1 = carrier[:3, :3] @ p["E"] + carrier[:3, 3]
            for F1 in circles(E1, self.len["EF"], p["G"], self.len["FG"]):
                if np.isnan(F1).any():
                    continue
                F1 = np.array([*F1, 0.0])
                g = dict(
                    ground=np.eye(4),
                    crank=gc,
                    **poses,
                    link5=pose2(p["E"], p["F"], E1, F1),
                    link6=pose2(p["G"], p["F"], p["G"], F1),
                )
                out.append(readings_from_poses(self.mech, g))
        return out


class Watt(_SixBar):
    """Watt II: the ternary rocker C-D-E carries the dyad E-F-G."""

    CARRIER = "rocker"


class Stephenson3(_SixBar):
    """Stephenson III: the ternary coupler B-C-E carries the dyad E-F-G (the ternary links, ground and coupler,
    are not joined directly: Stephenson's chain)."""

    CARRIER = "coupler"


def nearest(
    cands: list[dict[str, float]], row: dict[str, float], names: list[str], prismatic: set[str]
) -> tuple[float, int]:
    """Largest difference (deg, or length for prismatic joints) between a row and its nearest candidate."""
    best, bi = np.inf, -1
    for i, c in enumerate(cands):
        err = 0.0
        for n in names:
            dlt = row[n] - c[n]
            if n not in prismatic:
                dlt = (dlt + 180.0) % 360.0 - 180.0
            err = max(err, abs(dlt))
        if err < best:
            best, bi = err, i
    return best, bi


def _fmt(v: np.ndarray) -> str:
    return "[" + ", ".join(repr(float(x)) for x in v) + "]"


class DHLoop:
    """A ``dh`` loop: ``params`` (d, a, alpha_deg) per joint and start angles (deg)."""

    def __init__(self, name: str, links: list[tuple[float, float, float]], theta0: list[float]) -> None:
        self.name = name
        self.links = links
        self.theta0 = list(theta0)
        self.names = [chr(ord("A") + i) for i in range(len(links))]

    def toml(self, scale: float = 1.0, theta: list[float] | None = None) -> str:
        th = self.theta0 if theta is None else theta
        out = [f'name = "{self.name}"', "", "[loop]", 'convention = "dh"']
        for n, (d, a, al), t in zip(self.names, self.links, th, strict=True):
            out += [
                "",
                "[[loop.joints]]",
                f'name = "{n}"',
                f"theta = {float(t)!r}",
                f"d = {float(d * scale)!r}",
                f"a = {float(a * scale)!r}",
                f"alpha = {float(al)!r}",
            ]
        return "\n".join(out) + "\n"

    def params(self, row_deg: np.ndarray) -> list[tuple[float, float, float, float]]:
        return [
            (np.radians(t), d, a, np.radians(al)) for t, (d, a, al) in zip(row_deg, self.links, strict=True)
        ]

    def closure(self, row_deg: np.ndarray) -> float:
        return dh_closure(self.params(row_deg))

    def jacobian(self, row_deg: np.ndarray) -> np.ndarray:
        return dh_loop_jacobian(self.params(row_deg))

    def solve_at(self, drive_idx: int, value_deg: float, guess_deg: np.ndarray) -> np.ndarray:
        """Newton (least squares, numpy) for the other angles with the drive held; from ``guess``."""
        x = np.radians(np.asarray(guess_deg, float)).copy()
        x[drive_idx] = np.radians(value_deg)
        free = [i for i in range(len(x)) if i != drive_idx]

        def resid(x: np.ndarray) -> np.ndarray:
            g = np.eye(4)
            for t, (d, a, al) in zip(x, self.links, strict=True):
                g = g @ dh(t, d, a, np.radians(al))
            return (g - np.eye(4))[:3].ravel()

        for _ in range(60):
            r = resid(x)
            if np.abs(r).max() < 1e-15:
                break
            jac = np.zeros((12, len(free)))
            for c, i in enumerate(free):
                h = 1e-7
                xp, xm = x.copy(), x.copy()
                xp[i] += h
                xm[i] -= h
                jac[:, c] = (resid(xp) - resid(xm)) / (2 * h)
            dx = np.linalg.lstsq(jac, -r, rcond=None)[0]
            x[free] += dx
        return np.degrees(x)


class Bennett(DHLoop):
    """Bennett: links (a1, alpha1), (a2, alpha2) alternating, a1 / sin alpha1 = a2 / sin alpha2.

    Closed form (verified by the audit's own DH closure): tan(t1/2) tan(t2/2) = sin((al2+al1)/2) /
    sin((al2-al1)/2), t3 = -t1, t4 = -t2.
    """

    def __init__(self, name: str, a1: float, al1: float, al2: float, t1: float) -> None:
        a2 = a1 * np.sin(np.radians(al2)) / np.sin(np.radians(al1))
        self.K = np.sin(np.radians(al2 + al1) / 2) / np.sin(np.radians(al2 - al1) / 2)
        t2 = self.t2(t1)
        super().__init__(name, [(0, a1, al1), (0, a2, al2), (0, a1, al1), (0, a2, al2)], [t1, t2, -t1, -t2])

    def t2(self, t1: float) -> float:
        return float(np.degrees(2 * np.arctan(self.K / np.tan(np.radians(t1) / 2))))

    def check(self, row: np.ndarray) -> dict:
        t1 = row[0]
        ref = np.array([t1, self.t2(t1), -t1, -self.t2(t1)])
        # near t1 = 0 (mod 360) tan(t1/2) -> 0 and t2 -> 180: compare t2 through the relation's other form
        return dict(angle=float(np.max(np.abs(wrap_deg(row - ref)))), closure=self.closure(row))


class Spherical4R:
    """Spherical four-bar: hinge lines through the origin, ground link D-A held still.

    Link angles: ground (A, D) g, input (A, B) a, coupler (B, C) b, output (C, D) c (degrees). The output
    follows from the input-output equation ``A cos psi + B sin psi = K`` (derived in the docstring of
    :meth:`solve`).
    """

    def __init__(
        self, name: str, g: float, a: float, b: float, c: float, theta0: float, side: int = 0
    ) -> None:
        self.name = name
        uA = np.array([0.0, 0.0, 1.0])
        uD = rot([0, 1.0, 0], np.radians(g)) @ uA
        uB = rot([1.0, 0, 0], np.radians(a)) @ uA
        uB = rot(uA, np.radians(theta0)) @ uB
        self.cos_b = np.cos(np.radians(b))
        # uC: angle b from uB and c from uD
        cands = self._cone_cone(uB, b, uD, c)
        uC = cands[side]
        self.u = dict(A=uA, B=uB, C=uC, D=uD)
        self.theta0 = theta0
        self.names = list("ABCD")
        self.mech = Mech(
            name,
            [
                dict(name="A", bodies=["L3", "L0"], point=[0, 0, 0], direction=list(uA), value=theta0),
                dict(name="B", bodies=["L0", "L1"], point=[0, 0, 0], direction=list(uB)),
                dict(name="C", bodies=["L1", "L2"], point=[0, 0, 0], direction=list(uC)),
                dict(name="D", bodies=["L2", "L3"], point=[0, 0, 0], direction=list(uD)),
            ],
            planar=False,
            root="L3",
        )

    @staticmethod
    def _cone_cone(u1: np.ndarray, a1: float, u2: np.ndarray, a2: float) -> list[np.ndarray]:
        """Unit vectors at angle a1 from u1 and a2 from u2 (degrees)."""
        c1, c2 = np.cos(np.radians(a1)), np.cos(np.radians(a2))
        m = np.array([u1, u2])
        x0 = np.linalg.lstsq(m, [c1, c2], rcond=None)[0]
        n = np.cross(u1, u2)
        n /= np.linalg.norm(n)
        h = np.sqrt(1 - x0 @ x0)
        return [x0 + h * n, x0 - h * n]

    def toml(self, motion: np.ndarray | None = None) -> str:
        r = np.eye(3) if motion is None else motion[:3, :3]
        t = np.zeros(3) if motion is None else motion[:3, 3]
        out = [f'name = "{self.name}"', "", "[loop]", 'convention = "hinge-lines"']
        for n in self.names:
            out += [
                "",
                "[[loop.joints]]",
                f'name = "{n}"',
                f"point = {_fmt(t)}",
                f"direction = {_fmt(r @ self.u[n])}",
                f"theta = {float(self.theta0 if n == 'A' else 0.0)!r}",
            ]
        return "\n".join(out) + "\n"

    def solve(self, drive: str, reading: float) -> list[dict[str, float]]:
        """Both assemblies at input reading ``reading`` (deg).

        With the input turned by ``th``: ``b = R(uA, th) uB0``; the output turned by ``psi`` about ``uD``
        (joint D's bodies are [L2, L3], so ``psi = -q_D``) carries ``uC0`` to
        ``cos psi uC0 + sin psi (uD x uC0) + (1 - cos psi)(uD . uC0) uD``; the coupler keeps ``b . uC`` at
        ``cos(b)``: ``A cos psi + B sin psi = K`` with ``A = b . uC0 - (uD . uC0)(b . uD)``,
        ``B = b . (uD x uC0)``, ``K = cos(b) - (uD . uC0)(b . uD)``.
        """
        assert drive == "A"
        uA, uB0, uC0, uD = (self.u[k] for k in "ABCD")
        th = np.radians(reading - self.theta0)
        ra = rot(uA, th)
        b = ra @ uB0
        A = b @ uC0 - (uD @ uC0) * (b @ uD)
        B = b @ np.cross(uD, uC0)
        K = self.cos_b - (uD @ uC0) * (b @ uD)
        rr = np.hypot(A, B)
        if abs(K) > rr:
            return []
        out = []
        for s in (+1, -1):
            psi = np.arctan2(B, A) + s * np.arccos(K / rr)
            r2 = rot(uD, psi)
            c = r2 @ uC0
            f0 = np.array([uB0, uC0, np.cross(uB0, uC0)]).T
            f1 = np.array([b, c, np.cross(b, c)]).T
            r1 = f1 @ np.linalg.inv(f0)
            g = {}
            for nm, r in (("L3", np.eye(3)), ("L0", ra), ("L1", r1), ("L2", r2)):
                m = np.eye(4)
                m[:3, :3] = r
                g[nm] = m
            out.append(readings_from_poses(self.mech, g))
        return out

    def check(self, row: np.ndarray) -> dict:
        rd = dict(zip(self.names, row, strict=True))
        best = min(
            (
                float(np.max(np.abs(wrap_deg(np.array([c[n] for n in self.names]) - row))))
                for c in self.solve("A", rd["A"])
            ),
            default=np.inf,
        )
        return dict(angle=best, closure=self.mech.poses(rd)[1])

    def jacobian(self, row: np.ndarray) -> np.ndarray:
        return self.mech.jacobian(dict(zip(self.names, row, strict=True)))


def bricard_line(name: str) -> DHLoop:
    """A line-symmetric Bricard loop of the audit's own dimensions; start solved by Newton (numpy)."""
    links = [(0.2, 1.2, 50.0), (-0.4, 0.9, 100.0), (0.6, 1.5, -70.0)]
    links = links + links
    loop = DHLoop(name, links, [0.0] * 6)
    rng = np.random.default_rng(7)
    for _ in range(200):
        guess = np.concatenate([[40.0], rng.uniform(-180, 180, 5)])
        th = loop.solve_at(0, 40.0, guess)
        if loop.closure(th) < 1e-14:
            break
    loop.theta0 = list(th)
    return loop


def bricard_plane(name: str) -> DHLoop:
    """A plane-symmetric Bricard loop (links AB, FA mirror images; BC, EF; CD, DE), own dimensions."""
    a1, a2, a3, al1, al2, al3, d2, d3 = 0.9, 1.3, 0.7, 35.0, 120.0, 140.0, 0.25, -0.5
    links = [
        (0.0, a1, al1),
        (d2, a2, al2),
        (d3, a3, al3),
        (0.0, a3, 360 - al3),
        (-d3, a2, 360 - al2),
        (-d2, a1, 360 - al1),
    ]
    loop = DHLoop(name, links, [0.0] * 6)
    rng = np.random.default_rng(11)
    for _ in range(400):
        guess = np.concatenate([[50.0], rng.uniform(-180, 180, 5)])
        th = loop.solve_at(0, 50.0, guess)
        if loop.closure(th) < 1e-14:
            break
    loop.theta0 = list(th)
    return loop


class Goldberg:
    """Goldberg's 5R linkage from two Bennett loops (Goldberg 1943), written by its hinge lines.

    Bennett loop 1 has joints J1, J2, J3, J4 and links (a1, al1), (a2, al2), (a1, al1), (a2, al2); loop 2 has
    J1, J5, J6, J4 and links (a3, al3), (a2, al2), (a3, al3), (a2, al2) (every ``a_i = k sin al_i``). Both start
    from the frame on J1 whose x-axis is the common normal from J4 (the shared link J4-J1), so they share the
    lines J1 and J4. The shared link is removed and the links J1-J2 and J1-J5 are fused: the 5R loop J2, J3, J4,
    J6, J5, in which both Bennett loops turn their J1 by the same ``delta`` (:meth:`predict`).
    """

    def __init__(self, name: str, k: float, al1: float, al2: float, al3: float, t1: float, p1: float) -> None:
        a1, a3 = (k * np.sin(np.radians(x)) for x in (al1, al3))
        self.b1 = Bennett("b1", a1, al1, al2, t1)
        self.b2 = Bennett("b2", a3, al3, al2, p1)
        self.t10, self.p10 = t1, p1
        lines = []
        for b in (self.b1, self.b2):
            g, frames = np.eye(4), []
            for p in b.params(np.array(b.theta0)):
                frames.append(g.copy())
                g = g @ dh(*p)
            assert np.abs(g - np.eye(4)).max() < 1e-12  # both Bennett loops close at their start
            lines.append([(f[:3, 3].copy(), f[:3, 2].copy()) for f in frames])
        (_, j2, j3, j4), (_, j5, j6, _) = lines
        self.lines = [j2, j3, j4, j6, j5]
        self.names = list("ABCDE")
        self.mech = Mech(
            name,
            [
                dict(name=n, bodies=[f"L{(i - 1) % 5}", f"L{i}"], point=list(p), direction=list(d))
                for i, (n, (p, d)) in enumerate(zip(self.names, self.lines, strict=True))
            ],
            planar=False,
            root="L4",
        )

    def predict(self, delta: float) -> np.ndarray:
        """The five joints' displacements (deg) when both Bennett loops turn J1 by ``delta`` (deg): Bennett's
        relation in each; at J4, ``theta4 = -theta2`` turns the shared link against J3-J4 and ``phi4 = -phi5``
        against J6-J4, so J6-J4 turns against J3-J4 by their difference; J6 and J5 are crossed against loop 2's
        order (``phi6 = -phi1``)."""
        th2, th20 = self.b1.t2(self.t10 + delta), self.b1.theta0[1]
        ph5, ph50 = self.b2.t2(self.p10 + delta), self.b2.theta0[1]
        d4 = (th20 - th2) - (ph50 - ph5)
        return np.array([th2 - th20, -delta, d4, delta, ph50 - ph5])

    def toml(self, thetas: list[float] | None = None) -> str:
        """The loop as a ``hinge-lines`` spec (reported angles ``thetas`` at the start, default 0)."""
        th = [0.0] * 5 if thetas is None else thetas
        out = [f'name = "{self.mech.name}"', "", "[loop]", 'convention = "hinge-lines"']
        for n, (p, d), t in zip(self.names, self.lines, th, strict=True):
            out += ["", "[[loop.joints]]", f'name = "{n}"', f"point = {_fmt(p)}", f"direction = {_fmt(d)}"]
            out.append(f"theta = {float(t)!r}")
        return "\n".join(out) + "\n"

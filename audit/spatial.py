"""Spatial linkages of the audit (numpy only): spherical 4R, Bennett, line- and plane-symmetric Bricard.

Each case gives a spec text, the joint names, ``check(row_deg) -> dict of errors`` against its closed form or
an independent closure, and ``jacobian(row_deg)``: the raw closure Jacobian built from the row's angles.
"""

from __future__ import annotations

import numpy as np

from ref import Mech, dh, dh_closure, dh_loop_jacobian, readings_from_poses, rot, wrap_deg


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
        for n, (d, a, al), t in zip(self.names, self.links, th):
            out += ["", "[[loop.joints]]", f'name = "{n}"', f"theta = {float(t)!r}", f"d = {float(d * scale)!r}",
                    f"a = {float(a * scale)!r}", f"alpha = {float(al)!r}"]
        return "\n".join(out) + "\n"

    def params(self, row_deg: np.ndarray) -> list[tuple[float, float, float, float]]:
        return [(np.radians(t), d, a, np.radians(al)) for t, (d, a, al) in zip(row_deg, self.links)]

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
            for t, (d, a, al) in zip(x, self.links):
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

    def __init__(self, name: str, g: float, a: float, b: float, c: float, theta0: float, side: int = 0) -> None:
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
        self.mech = Mech(name, [
            dict(name="A", bodies=["L3", "L0"], point=[0, 0, 0], direction=list(uA), value=theta0),
            dict(name="B", bodies=["L0", "L1"], point=[0, 0, 0], direction=list(uB)),
            dict(name="C", bodies=["L1", "L2"], point=[0, 0, 0], direction=list(uC)),
            dict(name="D", bodies=["L2", "L3"], point=[0, 0, 0], direction=list(uD)),
        ], planar=False, root="L3")

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
            out += ["", "[[loop.joints]]", f'name = "{n}"', f"point = {_fmt(t)}", f"direction = {_fmt(r @ self.u[n])}",
                    f"theta = {float(self.theta0 if n == 'A' else 0.0)!r}"]
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
        rd = dict(zip(self.names, row))
        best = min((float(np.max(np.abs(wrap_deg(np.array([c[n] for n in self.names]) - row))))
                    for c in self.solve("A", rd["A"])), default=np.inf)
        return dict(angle=best, closure=self.mech.poses(rd)[1])

    def jacobian(self, row: np.ndarray) -> np.ndarray:
        return self.mech.jacobian(dict(zip(self.names, row)))


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
    links = [(0.0, a1, al1), (d2, a2, al2), (d3, a3, al3), (0.0, a3, 360 - al3), (-d3, a2, 360 - al2),
             (-d2, a1, 360 - al1)]
    loop = DHLoop(name, links, [0.0] * 6)
    rng = np.random.default_rng(11)
    for _ in range(400):
        guess = np.concatenate([[50.0], rng.uniform(-180, 180, 5)])
        th = loop.solve_at(0, 50.0, guess)
        if loop.closure(th) < 1e-14:
            break
    loop.theta0 = list(th)
    return loop

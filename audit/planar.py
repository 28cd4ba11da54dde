"""Planar linkages of the audit, with closed-form solvers written from their geometry (numpy only).

Each case is a :class:`ref.Mech` plus ``solve(drive, reading) -> list of readings dicts``: every assembly
(circle/line intersection choice) of the mechanism at that drive reading, from the start geometry alone.
"""

from __future__ import annotations

import itertools

import numpy as np

from ref import Mech, about_line, circles, pose2, readings_from_poses

Z = np.array([0.0, 0.0, 1.0])


def P(x: float, y: float) -> np.ndarray:
    return np.array([x, y, 0.0])


class FourBar:
    """Ground pivots A = (0, 0), D = (g, 0); crank A-B (length a), coupler B-C (b), rocker C-D (c)."""

    inputs = ("A", "D")

    def __init__(self, name: str, g: float, a: float, b: float, c: float, theta0: float, side: int = 0,
                 coupler_point: tuple[float, float] | None = None) -> None:
        self.g, self.a, self.b, self.c = g, a, b, c
        th = np.radians(theta0)
        A, D = P(0, 0), P(g, 0)
        B = P(a * np.cos(th), a * np.sin(th))
        C = circles(B, b, D, c)[side]
        self.pts = dict(A=A, B=B, C=np.array([C[0], C[1], 0.0]), D=D)
        self.mech = Mech(name, [
            dict(name="A", bodies=["ground", "crank"], point=list(A), value=theta0),
            dict(name="B", bodies=["crank", "coupler"], point=list(B)),
            dict(name="C", bodies=["coupler", "rocker"], point=list(self.pts["C"])),
            dict(name="D", bodies=["rocker", "ground"], point=list(D)),
        ], planar=True)

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
        self.mech = Mech(name, [
            dict(name="A", bodies=["ground", "crank"], point=[0, 0, 0], value=theta0),
            dict(name="B", bodies=["crank", "rod"], point=list(B)),
            dict(name="C", bodies=["rod", "slider"], point=list(C)),
            dict(name="D", type="P", bodies=["ground", "slider"], point=[0, 0, 0], direction=[1, 0, 0],
                 value=x0),
        ], planar=True)

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
            h2 = self.l ** 2 - (self.e - B1[1]) ** 2
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


class Watt:
    """Watt II: four-bar A-B-C-D (ground pivots A, D), ternary rocker C-D-E, dyad E-F-G (G on ground).

    Bodies: ground (A, D, G), crank (A, B), coupler (B, C), rocker (C, D, E), link5 (E, F), link6 (F, G).
    """

    def __init__(self, name: str, pts: dict[str, tuple[float, float]], theta0: float) -> None:
        self.pts = {k: P(*v) for k, v in pts.items()}
        d = lambda u, v: float(np.linalg.norm(self.pts[u] - self.pts[v]))  # noqa: E731
        self.len = {k: d(*k) for k in ["AB", "BC", "CD", "EF", "FG", "DE"]}
        self.mech = Mech(name, [
            dict(name="A", bodies=["ground", "crank"], point=list(self.pts["A"]), value=theta0),
            dict(name="B", bodies=["crank", "coupler"], point=list(self.pts["B"])),
            dict(name="C", bodies=["coupler", "rocker"], point=list(self.pts["C"])),
            dict(name="D", bodies=["rocker", "ground"], point=list(self.pts["D"])),
            dict(name="E", bodies=["rocker", "link5"], point=list(self.pts["E"])),
            dict(name="F", bodies=["link5", "link6"], point=list(self.pts["F"])),
            dict(name="G", bodies=["link6", "ground"], point=list(self.pts["G"])),
        ], planar=True)

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
            grk = pose2(p["D"], p["C"], p["D"], C1)
            E1 = grk[:3, :3] @ p["E"] + grk[:3, 3]
            for F1 in circles(E1, self.len["EF"], p["G"], self.len["FG"]):
                if np.isnan(F1).any():
                    continue
                F1 = np.array([*F1, 0.0])
                g = dict(ground=np.eye(4), crank=gc, coupler=pose2(p["B"], p["C"], B1, C1), rocker=grk,
                         link5=pose2(p["E"], p["F"], E1, F1), link6=pose2(p["G"], p["F"], p["G"], F1))
                out.append(readings_from_poses(self.mech, g))
        return out


class Stephenson3:
    """Stephenson III: four-bar A-B-C-D, ternary coupler B-C-E, dyad E-F-G with G on the ground.

    Bodies: ground (A, D, G), crank (A, B), coupler (B, C, E), rocker (C, D), link5 (E, F), link6 (F, G).
    The ternary links (ground, coupler) are not joined directly: Stephenson's chain.
    """

    def __init__(self, name: str, pts: dict[str, tuple[float, float]], theta0: float) -> None:
        self.pts = {k: P(*v) for k, v in pts.items()}
        d = lambda u, v: float(np.linalg.norm(self.pts[u] - self.pts[v]))  # noqa: E731
        self.len = {k: d(*k) for k in ["AB", "BC", "CD", "EF", "FG"]}
        self.mech = Mech(name, [
            dict(name="A", bodies=["ground", "crank"], point=list(self.pts["A"]), value=theta0),
            dict(name="B", bodies=["crank", "coupler"], point=list(self.pts["B"])),
            dict(name="C", bodies=["coupler", "rocker"], point=list(self.pts["C"])),
            dict(name="D", bodies=["rocker", "ground"], point=list(self.pts["D"])),
            dict(name="E", bodies=["coupler", "link5"], point=list(self.pts["E"])),
            dict(name="F", bodies=["link5", "link6"], point=list(self.pts["F"])),
            dict(name="G", bodies=["link6", "ground"], point=list(self.pts["G"])),
        ], planar=True)

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
            gcp = pose2(p["B"], p["C"], B1, C1)
            E1 = gcp[:3, :3] @ p["E"] + gcp[:3, 3]
            for F1 in circles(E1, self.len["EF"], p["G"], self.len["FG"]):
                if np.isnan(F1).any():
                    continue
                F1 = np.array([*F1, 0.0])
                g = dict(ground=np.eye(4), crank=gc, coupler=gcp, rocker=pose2(p["D"], p["C"], p["D"], C1),
                         link5=pose2(p["E"], p["F"], E1, F1), link6=pose2(p["G"], p["F"], p["G"], F1))
                out.append(readings_from_poses(self.mech, g))
        return out


def nearest(cands: list[dict[str, float]], row: dict[str, float], names: list[str], prismatic: set[str]
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


_ = itertools

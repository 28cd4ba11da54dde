"""report.json max_condition / condition_at_end against the audit's own normalised Jacobian (docs/tracing.md,
"The robustness ratio"): moments about the least-squares centre c of the revolute lines, lengths over L (RMS
distance from c to the lines), both at each configuration; ratio largest / smallest non-zero singular value."""
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from ref import read_path_csv, read_report  # noqa: E402
from run_planar import cases  # noqa: E402
from spatial import Bennett  # noqa: E402

OUT = Path(__file__).parent.parent / "out" / "audit"


def normalised_ratio(lines: list[tuple[np.ndarray, np.ndarray]], planar: bool, rank: int) -> float:
    """lines: current (point, unit direction) of every revolute joint, in loop column order (one loop)."""
    a = sum(np.eye(3) - np.outer(w, w) for _, w in lines)
    rhs = sum((np.eye(3) - np.outer(w, w)) @ p for p, w in lines)
    c = np.linalg.lstsq(a, rhs, rcond=None)[0]
    dist = [np.linalg.norm((np.eye(3) - np.outer(w, w)) @ (p - c)) for p, w in lines]
    L = float(np.sqrt(np.mean(np.square(dist))))
    cols = [np.concatenate([w, np.cross(p - c, w) / L]) for p, w in lines]
    j = np.array(cols).T
    if planar:
        j = j[[2, 3, 4]]
    s = np.linalg.svd(j, compute_uv=False)
    return float(s[0] / s[rank - 1])


def main() -> None:
    fb = cases()["crank-rocker"][0].mech
    for run in ("crank-rocker-loop", "crank-rocker-paper"):
        cols, rep = read_path_csv(OUT / run), read_report(OUT / run)
        ratios = []
        for i in range(len(cols["s"])):
            g, _ = fb.poses({n: cols[n][i] for n in fb.names})
            lines = []
            for j in fb.joints:
                b = g[j["bodies"][0]]
                lines.append((b[:3, :3] @ j["point"] + b[:3, 3], b[:3, :3] @ j["direction"]))
            ratios.append(normalised_ratio(lines, True, 3))
        print(f"{run}: max_condition {rep['max_condition']!r} own {max(ratios)!r}; at end {rep['condition_at_end']!r}"
              f" own {ratios[-1]!r}")
    b = Bennett("bennett-audit", 0.8, 30.0, 110.0, 70.0)
    cols, rep = read_path_csv(OUT / "bennett-audit-loop"), read_report(OUT / "bennett-audit-loop")
    ratios = []
    from ref import dh

    for i in range(len(cols["s"])):
        g = np.eye(4)
        lines = []
        for t, (d, a, al) in zip([cols[n][i] for n in b.names], b.links):
            lines.append((g[:3, 3].copy(), g[:3, 2].copy()))
            g = g @ dh(np.radians(t), d, a, np.radians(al))
        ratios.append(normalised_ratio(lines, False, 3))
    print(f"bennett-audit-loop: max_condition {rep['max_condition']!r} own {max(ratios)!r}; at end "
          f"{rep['condition_at_end']!r} own {ratios[-1]!r}")


if __name__ == "__main__":
    main()


def watt() -> None:
    """Two loops: rows orthonormalised over the cycle space, W = (Z Z^T)^(-1/2), Z the signed loop-joint incidence."""
    m = cases()["watt"][0].mech
    cols, rep = read_path_csv(OUT / "watt-loop"), read_report(OUT / "watt-loop")
    _, loops = m.tree_and_loops()
    z = np.zeros((len(loops), len(m.joints)))
    for li, loop in enumerate(loops):
        for k, s in loop:
            z[li, k] = s
    ev, evec = np.linalg.eigh(z @ z.T)
    w = evec @ np.diag(ev**-0.5) @ evec.T
    ratios = []
    for i in range(len(cols["s"])):
        g, _ = m.poses({n: cols[n][i] for n in m.names})
        lines = []
        for j in m.joints:
            b = g[j["bodies"][0]]
            lines.append((b[:3, :3] @ j["point"] + b[:3, 3], b[:3, :3] @ j["direction"]))
        a = sum(np.eye(3) - np.outer(u, u) for _, u in lines)
        rhs = sum((np.eye(3) - np.outer(u, u)) @ p for p, u in lines)
        c = np.linalg.lstsq(a, rhs, rcond=None)[0]
        L = float(np.sqrt(np.mean([np.linalg.norm((np.eye(3) - np.outer(u, u)) @ (p - c)) ** 2 for p, u in lines])))
        tw = np.array([np.concatenate([u, np.cross(p - c, u) / L])[[2, 3, 4]] for p, u in lines])  # (7, 3)
        jac = np.vstack([np.array([z[li, k] * tw[k] for k in range(7)]).T for li in range(len(loops))])
        jac = np.kron(w, np.eye(3)) @ jac
        s = np.linalg.svd(jac, compute_uv=False)
        ratios.append(float(s[0] / s[5]))
    print(f"watt-loop: max_condition {rep['max_condition']!r} own {max(ratios)!r}; at end {rep['condition_at_end']!r}"
          f" own {ratios[-1]!r}")


watt()

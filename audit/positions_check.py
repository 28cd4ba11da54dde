"""Trace.positions() of the audit's Bennett (d = 0): the DH frame origins (so consecutive joints are the link
lengths apart), with the first body (link0, after joint A: DH frame 1) held still, as docs/tracing.md says; one
rigid motion for every row against the audit's own DH product."""
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from ref import dh  # noqa: E402
from spatial import Bennett  # noqa: E402

HERE = Path(__file__).parent


def origins_in_frame1(b: Bennett, row: np.ndarray) -> np.ndarray:
    g, o = np.eye(4), []
    for th, (d, a, al) in zip(row, b.links):
        o.append(g[:, 3].copy())
        g = g @ dh(np.radians(th), d, a, np.radians(al))
    t1 = dh(np.radians(row[0]), *b.links[0][:2], np.radians(b.links[0][2]))
    return (np.linalg.inv(t1) @ np.array(o).T).T[:, :3]


def main() -> None:
    import linkwork as lw

    b = Bennett("bennett-audit", 0.8, 30.0, 110.0, 70.0)
    t = lw.trace(lw.load(str(HERE / "specs" / "bennett-audit.toml")))
    pos, ang = t.positions(), np.degrees(np.asarray(t.angles))
    p0, q0 = origins_in_frame1(b, ang[0]), pos[0]
    pc, qc = p0.mean(0), q0.mean(0)
    u, _, vt = np.linalg.svd((p0 - pc).T @ (q0 - qc))
    r = (u @ vt).T
    tr = qc - r @ pc
    worst = max(float(np.abs(origins_in_frame1(b, a) @ r.T + tr - p).max()) for a, p in zip(ang, pos))
    lens = max(abs(np.linalg.norm(p[(k + 1) % 4] - p[k]) - b.links[k][1]) for p in pos for k in range(4))
    print(f"Bennett positions(): link lengths {lens:.1e}; against the own DH origins with link0 held, one rigid "
          f"motion for every row: {worst:.1e}")


if __name__ == "__main__":
    main()

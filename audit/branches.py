"""--branches on the parallelogram and the deltoid: every branch's rows on the loop (own closure), the
bifurcation points where the pivots are in line, and the branch tangents against finite differences of the
closed form's two assemblies (parallelogram) or the crank held still (deltoid)."""
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from ref import read_path_csv, read_report  # noqa: E402
from run_planar import cases  # noqa: E402

HERE = Path(__file__).parent
OUT = HERE.parent / "out" / "audit"


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def main() -> None:
    C = cases()
    for nm in ("parallelogram", "deltoid", "change-point"):
        case = C[nm][0]
        spec = HERE / "specs" / f"{nm}.toml"
        out = OUT / f"{nm}-branches"
        p = subprocess.run(["linkwork", "trace", str(spec), "--branches", "--no-plots", "-o", str(out)],
                           capture_output=True, text=True)
        rep = read_report(out)
        cols = read_path_csv(out)
        names = case.mech.names
        clos = max(case.mech.poses({n: cols[n][i] for n in names})[1] for i in range(len(cols["s"])))
        print(f"{nm}: rc {p.returncode}, {len(rep['bifurcations'])} bifurcations, {len(rep['branches'])} branches, "
              f"rows {len(cols['s'])}, own closure worst {clos:.1e}")
        for b in rep["bifurcations"]:
            row = np.array([b["angles"][n] for n in names])
            # reference tangents: finite differences of each closed-form assembly through the point (drive A),
            # plus, where the crank can stay put (deltoid, B on D), the direction with dA = 0 from the Jacobian
            refs = []
            a = row[0]
            for dl in (1e-3, -1e-3):  # one-sided secants (deg) along each assembly: +-tangent to O(1e-5)
                for c in case.solve("A", a + dl):
                    v = np.array([c[n] for n in names])
                    dv = (v - row + 180) % 360 - 180
                    if np.linalg.norm(dv) < 1e-2:
                        refs.append(unit(dv))
            # null space of the own Jacobian at the point (its dimension is 2 at a simple bifurcation)
            jac = case.mech.jacobian(dict(zip(names, row)))
            _, s, vt = np.linalg.svd(jac)
            null = vt[-2:]
            # a branch along which the crank stays put (the deltoid with B on D): dA = 0 in the null space
            w = null[:, 0]
            if np.linalg.norm(w) > 0:
                refs.append(unit(null.T @ np.array([w[1], -w[0]])))
            got = [unit(np.array(t)) for t in b["tangents"]]
            match = []
            for t in got:
                d = [min(np.linalg.norm(t - r), np.linalg.norm(t + r)) for r in refs] or [np.nan]
                match.append(round(float(min(d)), 9))
            in_null = [float(np.linalg.norm(t - null.T @ (null @ t))) for t in got]
            print(f"  point A={b['angles']['A']:.9f} kind {b['kind']} rank {b['rank']} sigma_3/sigma_1 "
                  f"{s[2] / s[0]:.1e}; {len(got)} tangents; distance to closed-form tangents {match}; "
                  f"out of own null space {max(in_null):.1e}")
        for br in rep["branches"]:
            print(f"   branch {br['id']} parent {br['parent']} dir {br['direction']} steps {br['steps']} "
                  f"end {br['end_reason']!r}")


if __name__ == "__main__":
    main()

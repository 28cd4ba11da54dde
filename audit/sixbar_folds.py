"""Six-bars driven by a joint that turns back: rows on the closed form (solved from the crank A, which turns
fully), folds where the Jacobian without the drive's column is singular (numpy SVD of the audit's own Jacobian),
and the drive's range over the loop equal to its extremes over a dense closed-form scan."""
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from planar import nearest  # noqa: E402
from ref import read_path_csv, read_report, wrap_deg  # noqa: E402
from run_planar import cases  # noqa: E402

HERE = Path(__file__).parent
OUT = HERE.parent / "out" / "audit"


def main() -> None:
    C = cases()
    for nm, drive in (("watt", "E"), ("watt", "G"), ("stephenson3", "D"), ("stephenson3", "G"), ("stephenson3", "F")):
        case = C[nm][0]
        names = case.mech.names
        spec = HERE / "specs" / f"{nm}.toml"
        out = OUT / f"{nm}-drive-{drive}"
        p = subprocess.run(["linkwork", "trace", str(spec), "--drive", drive, "--no-plots", "-o", str(out)],
                           capture_output=True, text=True)
        cols, rep = read_path_csv(out), read_report(out)
        rows = np.stack([cols[n] for n in names], 1)
        worst = 0.0
        for r in rows:
            row = dict(zip(names, r))
            worst = max(worst, nearest(case.solve("A", row["A"]), row, names, set())[0])
        k = names.index(drive)
        fold_sing = []
        for f in rep["folds"]:
            row = {n: f["angles"][n] for n in names}
            jac = case.mech.jacobian(row)
            s = np.linalg.svd(np.delete(jac, k, axis=1), compute_uv=False)
            fold_sing.append(float(s[-1] / s[0]))
        # dense scan of the closed form along the start's assembly, continued in A over the loop
        a0 = case.mech.joints[0]["value"]
        prev = {n: case.mech.joints[i]["value"] for i, n in enumerate(names)}
        vals = []
        for a in np.linspace(a0, a0 + 360.0, 20001):
            c = min(case.solve("A", a), key=lambda x: max(abs(float(wrap_deg(x[n] - prev[n]))) for n in names))
            v = prev[drive] + float(wrap_deg(c[drive] - prev[drive]))
            prev = {n: prev[n] + float(wrap_deg(c[n] - prev[n])) for n in names}
            vals.append(v)
        rng = rep["branches"][0]["range"][drive]
        print(f"{nm} drive {drive}: rc {p.returncode}, rows {len(rows)}, end {rep['branches'][0]['end_reason']!r}; "
              f"rows vs closed form {worst:.1e} deg; {len(rep['folds'])} folds, reduced-Jacobian "
              f"sigma_min/sigma_max there {max(fold_sing, default=0):.1e}; range {rng[0]:.6f}..{rng[1]:.6f} vs "
              f"dense closed-form scan {min(vals):.6f}..{max(vals):.6f}")


if __name__ == "__main__":
    main()

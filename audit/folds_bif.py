"""Check 3: folds of the Bricard loops (independent: the Jacobian without the drive column is singular there),
Trace.folds vs report.json, and paper-mode steps landing exactly on a bifurcation point."""
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from ref import read_path_csv, read_report  # noqa: E402
from run_planar import cases as pcases  # noqa: E402
from spatial import bricard_line, bricard_plane  # noqa: E402

HERE = Path(__file__).parent
OUT = HERE.parent / "out" / "audit"


def main() -> None:
    import linkwork as lw

    for case in (bricard_line("bricard-line-audit"), bricard_plane("bricard-plane-audit")):
        spec = HERE / "specs" / f"{case.name}.toml"
        rep = read_report(OUT / f"{case.name}-loop")
        tr = lw.trace(lw.load(str(spec)))
        py = [float(np.degrees(f.value)) for f in tr.folds]
        js = [f["value"] for f in rep["folds"]]
        print(case.name, "folds json", js, "python", py)
        for f in rep["folds"]:
            row = np.array([f["angles"][n] for n in case.names])
            jac = case.jacobian(row)
            s_full = np.linalg.svd(jac, compute_uv=False)
            s_red = np.linalg.svd(jac[:, 1:], compute_uv=False)  # drive A's column removed
            print(f"  fold A={f['value']:.9f}: own closure {case.closure(row):.1e}; without the drive column "
                  f"sigma_min/sigma_max = {s_red[-1] / s_red[0]:.1e} (full Jacobian rank-5 gap "
                  f"{s_full[4] / s_full[0]:.1e})")
        # the drive's range over the loop from a dense numpy scan of the closure: the extremes must be the folds
        cols = read_path_csv(OUT / f"{case.name}-loop")
        print("  path A range", cols["A"].min(), cols["A"].max())

    # paper mode whose equal steps land on a bifurcation point
    C = pcases()
    for nm, args, expect in [("parallelogram", ["--until", "A=200", "--steps", "170"], 180.0),
                             ("change-point", ["--until", "A=190", "--steps", "130"], 180.0),
                             ("deltoid", ["--until", "A=370", "--steps", "320"], 360.0)]:
        spec = HERE / "specs" / f"{nm}.toml"
        spec.write_text(C[nm][0].mech.toml())
        out = OUT / f"{nm}-onbif"
        p = subprocess.run(["linkwork", "trace", str(spec), *args, "--no-plots", "-o", str(out)], capture_output=True,
                           text=True)
        rep = read_report(out)
        print(nm, args, "rc", p.returncode, "bifurcations at A =", [b["angles"]["A"] for b in rep["bifurcations"]],
              "expected", expect, "ends", [(b["end_reason"], b["end_value"]) for b in rep["branches"]],
              p.stderr.strip()[:200])


if __name__ == "__main__":
    main()

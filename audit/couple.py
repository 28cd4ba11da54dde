"""Couplings: the plane-symmetric Bricard with its symmetry imposed (couple B=F, C=E) traces the same path, and
its singular values are those of the reduced Jacobian (coupled columns added, docs/tracing.md)."""
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from ref import read_path_csv, read_report, sigma_columns, wrap_deg  # noqa: E402
from spatial import bricard_plane  # noqa: E402

HERE = Path(__file__).parent
OUT = HERE.parent / "out" / "audit"


def main() -> None:
    case = bricard_plane("bricard-plane-audit")
    text = case.toml().replace('convention = "dh"', 'convention = "dh"\ncouple = [["B", "F"], ["C", "E"]]')
    spec = HERE / "specs" / "bricard-plane-coupled.toml"
    spec.write_text(text)
    for label, s, args in (("spec couple", spec, []),
                           ("--couple", HERE / "specs" / "bricard-plane-audit.toml", ["--couple", "B=F", "--couple", "C=E"])):
        out = OUT / "bricard-plane-coupled"
        p = subprocess.run(["linkwork", "trace", str(s), *args, "--no-plots", "-o", str(out)], capture_output=True,
                           text=True)
        cols, rep = read_path_csv(out), read_report(out)
        rows = np.stack([cols[n] for n in case.names], 1)
        sig = sigma_columns(cols)
        werr = wclos = 0.0
        for i, r in enumerate(rows):
            jac = case.jacobian(r)
            red = np.stack([jac[:, 0], jac[:, 1] + jac[:, 5], jac[:, 2] + jac[:, 4], jac[:, 3]], 1)
            s_ref = np.linalg.svd(red, compute_uv=False)
            werr = max(werr, float(np.max(np.abs(sig[i] - s_ref[: sig.shape[1]])) / s_ref[0]))
            wclos = max(wclos, case.closure(r))
        un = read_path_csv(OUT / "bricard-plane-audit-loop")
        print(f"{label}: rc {p.returncode}, unknowns {rep['unknowns']}, rank {rep['rank']}, mobility {rep['mobility']},"
              f" sigma columns {sig.shape[1]}, rows {len(rows)} (uncoupled {len(un['s'])}); own closure {wclos:.1e};"
              f" sigma vs SVD of the reduced 6x4 Jacobian {werr:.1e}; B-F {np.max(np.abs(wrap_deg(rows[:, 1] - rows[:, 5]))):.1e}"
              f" | {p.stderr.strip()[:200]}")


if __name__ == "__main__":
    main()

"""Check 1 and 2 on spatial loops: spherical 4R, Bennett, line- and plane-symmetric Bricard.

Usage: python audit/run_spatial.py [CASE ...]
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from ref import read_path_csv, read_report, sigma_columns, wrap_deg  # noqa: E402
from spatial import Bennett, Spherical4R, bricard_line, bricard_plane  # noqa: E402

HERE = Path(__file__).parent
SPECS = HERE / "specs"
OUT = HERE.parent / "out" / "audit"


def cases() -> dict:
    c = {}
    c["spherical-4r"] = (Spherical4R("spherical-4r", 70, 25, 60, 50, 30), [
        ("loop", []), ("paper", ["--until", "A=200", "--steps", "85"])])
    b = Bennett("bennett-audit", 0.8, 30.0, 110.0, 70.0)
    c["bennett-audit"] = (b, [("loop", []), ("paper", ["--until", "A=250", "--steps", "90"]),
                              ("turn", ["--until", "A=430"]), ("below-turn", ["--until", "A=429.99999"])])
    c["bricard-line-audit"] = (bricard_line("bricard-line-audit"), [("loop", [])])
    c["bricard-plane-audit"] = (bricard_plane("bricard-plane-audit"), [("loop", [])])
    return c


SYM = {"bricard-line-audit": [(0, 3), (1, 4), (2, 5)], "bricard-plane-audit": [(1, 5), (2, 4)]}


def check(name: str, case, rows: np.ndarray, sig: np.ndarray) -> dict:
    w = dict(angle=0.0, closure=0.0, sigma=0.0, ratio=0.0, sym=0.0, polish=0.0)
    for i, r in enumerate(rows):
        if hasattr(case, "check"):
            e = case.check(r)
            w["angle"] = max(w["angle"], e["angle"])
        w["closure"] = max(w["closure"], case.closure(r) if hasattr(case, "closure") else e["closure"])
        for p, q in SYM.get(name, []):
            w["sym"] = max(w["sym"], abs(float(wrap_deg(r[p] - r[q]))))
        if name.startswith("bricard"):
            pol = case.solve_at(0, r[0], r)
            w["polish"] = max(w["polish"], float(np.max(np.abs(wrap_deg(pol - r)))))
        s_ref = np.linalg.svd(case.jacobian(r), compute_uv=False)
        k = sig.shape[1]
        w["sigma"] = max(w["sigma"], float(np.max(np.abs(sig[i] - s_ref[:k])) / s_ref[0]))
        w["ratio"] = max(w["ratio"], float(np.max(np.abs(sig[i] / sig[i][0] - s_ref[:k] / s_ref[0]))))
    return w


def main(which: list[str]) -> None:
    import linkwork as lw

    SPECS.mkdir(exist_ok=True)
    for name, (case, runs) in cases().items():
        if which and name not in which:
            continue
        spec = SPECS / f"{name}.toml"
        spec.write_text(case.toml())
        for label, args in runs:
            out = OUT / f"{name}-{label}"
            p = subprocess.run(["linkwork", "trace", str(spec), *args, "--no-plots", "-o", str(out)],
                               capture_output=True, text=True)
            if not (out / "path.csv").exists():
                print(f"{name:20s} {label:10s} rc={p.returncode} NO OUTPUT {p.stderr.strip()}")
                continue
            cols = read_path_csv(out)
            rep = read_report(out)
            rows = np.stack([cols[n] for n in case.names], 1)
            sig = sigma_columns(cols)
            w = check(name, case, rows, sig)
            closed = ""
            b0 = cols["branch"] == 0
            if rep["branches"][0]["end_kind"] == "closed":
                closed = (f" closed: joints {np.max(np.abs(wrap_deg(rows[b0][0] - rows[b0][-1]))):.1e} sigma "
                          f"{np.max(np.abs(sig[b0][0] - sig[b0][-1])):.1e}")
            print(f"{name:20s} {label:10s} rc={p.returncode} rows={len(rows)} "
                  + " ".join(f"{k}={v:.1e}" for k, v in w.items())
                  + f" rank={rep['rank']} mob={rep['mobility']} bif={len(rep['bifurcations'])} "
                  f"folds={[round(f['value'], 6) for f in rep['folds']]} "
                  f"ends={[(b['end_kind'], b['end_value']) for b in rep['branches']]}{closed}"
                  + (f" stderr={p.stderr.strip()!r}" if p.stderr.strip() else ""))
            until = steps = None
            if "--until" in args:
                j, v = args[args.index("--until") + 1].split("=")
                until = (j, np.radians(float(v)))
            if "--steps" in args:
                steps = int(args[args.index("--steps") + 1])
            tr = lw.trace(lw.load(str(spec)), until=until, steps=steps)
            ang = np.degrees(np.asarray(tr.angles))
            w2 = check(name, case, ang, np.asarray(tr.sigma))
            same = float(np.max(np.abs(wrap_deg(ang - rows)))) if ang.shape == rows.shape else np.nan
            print(f"{'':20s} {'python':10s} rows={len(ang)} " + " ".join(f"{k}={v:.1e}" for k, v in w2.items())
                  + f" cli-vs-py={same:.1e}")


if __name__ == "__main__":
    main(sys.argv[1:])

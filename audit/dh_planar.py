"""Check 3: a dh loop with every twist and offset zero is treated as planar (trace, robustness).

The audit's crank-rocker (run_planar.py) written as a dh loop: a_i the link lengths, theta_i the turning angle of
link i from link i-1 (frame i's x axis lies along link i). The joint displacements of the two descriptions are
the same relative rotations, so their rows must agree after subtracting the start readings.
"""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from ref import dh_closure, dh_loop_jacobian, read_path_csv, read_report, sigma_columns, wrap_deg  # noqa: E402
from run_planar import cases  # noqa: E402

HERE = Path(__file__).parent
OUT = HERE.parent / "out" / "audit"


def dh_text(fb) -> tuple[str, list[float], list[float]]:
    pts = [fb.pts[k] for k in "ABCD"]
    dirs = [pts[(i + 1) % 4] - pts[i] for i in range(4)]
    ang = [np.degrees(np.arctan2(d[1], d[0])) for d in dirs]
    lens = [float(np.hypot(d[0], d[1])) for d in dirs]
    theta = [float(wrap_deg(ang[i] - ang[i - 1])) for i in range(4)]
    out = ['name = "crank-rocker-dh"', "", "[loop]", 'convention = "dh"']
    for n, t, a in zip("ABCD", theta, lens):
        out += ["", "[[loop.joints]]", f'name = "{n}"', f"theta = {t!r}", "d = 0.0", f"a = {a!r}", "alpha = 0.0"]
    return "\n".join(out) + "\n", theta, lens


def run(spec: Path, args: list[str], out: Path) -> subprocess.CompletedProcess:
    return subprocess.run(["linkwork", *args[:1], str(spec), *args[1:], "--no-plots", "-o", str(out)],
                          capture_output=True, text=True)


def main() -> None:
    fb = cases()["crank-rocker"][0]
    text, theta, lens = dh_text(fb)
    spec = HERE / "specs" / "crank-rocker-dh.toml"
    spec.write_text(text)
    mspec = HERE / "specs" / "crank-rocker.toml"
    mspec.write_text(fb.mech.toml())
    a0 = fb.mech.joints[0]["value"]
    for args, margs in (([], []), (["--until", "A=" + repr(theta[0] + 180.0), "--steps", "90"],
                                   ["--until", "A=" + repr(a0 + 180.0), "--steps", "90"])):
        p = run(spec, ["trace", *args], OUT / "dh-planar")
        q = run(mspec, ["trace", *margs], OUT / "dh-planar-mech")
        print("trace", args, "rc", p.returncode, q.returncode, p.stderr.strip()[:200])
        a, r = read_path_csv(OUT / "dh-planar"), read_report(OUT / "dh-planar")
        b, rb = read_path_csv(OUT / "dh-planar-mech"), read_report(OUT / "dh-planar-mech")
        print("  dh: equations", r["equations"], "rank", r["rank"], "mobility", r["mobility"], "sigma columns",
              sigma_columns(a).shape[1], "rows", len(a["s"]), "| mechanism: equations", rb["equations"],
              "sigma columns", sigma_columns(b).shape[1], "rows", len(b["s"]))
        clos = max(dh_closure([(np.radians(a[n][i]), 0, L, 0) for n, L in zip("ABCD", lens)])
                   for i in range(len(a["s"])))
        sig = sigma_columns(a)
        serr = 0.0
        for i in range(len(a["s"])):
            s_ref = np.linalg.svd(dh_loop_jacobian([(np.radians(a[n][i]), 0, L, 0) for n, L in zip("ABCD", lens)]),
                                  compute_uv=False)
            serr = max(serr, float(np.max(np.abs(sig[i] - s_ref[:sig.shape[1]])) / s_ref[0]))
        print(f"  dh rows: own closure {clos:.1e}, sigma vs numpy SVD of the 6x4 DH Jacobian {serr:.1e}")
        if len(a["s"]) == len(b["s"]):
            dq = max(float(np.max(np.abs(wrap_deg((a[n] - a[n][0]) - (b[n] - b[n][0]))))) for n in "ABCD")
            print(f"  dh vs [mechanism] displacements: {dq:.1e} deg; s: {np.max(np.abs(a['s'] - b['s'])):.1e}")
            print("  max_condition dh", r["max_condition"], "mechanism", rb["max_condition"], "| raw", r["max_condition_raw"],
                  rb["max_condition_raw"])
    for sp, rob in ((spec, OUT / "dh-planar-rob"), (mspec, OUT / "dh-planar-rob-mech")):
        rob_one(sp, rob)


def rob_one(spec: Path, rob: Path) -> None:
    p = subprocess.run(["linkwork", "robustness", str(spec), "--samples", "20", "--hinge-position-tol", "1e-3",
                        "--hinge-direction-tol", "0.05", "--workers", "1", "--no-plots", "-o", str(rob)],
                       capture_output=True, text=True)
    print("robustness rc", p.returncode, p.stderr.strip()[-300:])
    if (rob / "robustness.json").exists():
        rj = json.loads((rob / "robustness.json").read_text())
        print("  ", spec.name, "errors:", rj["tolerances"]["errors"], "misfit_max:", rj["misfit_max"],
              "mobility_kept:", rj["mobility_kept"], "first_order max:", rj["first_order"]["max"])


if __name__ == "__main__":
    main()

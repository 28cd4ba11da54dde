"""Check 3: --until targets at and just inside a drive's extremes (law of cosines), CLI."""
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from ref import read_path_csv, read_report  # noqa: E402
from run_planar import cases  # noqa: E402

C = cases()


def run(spec: str, args: list[str], out: str) -> tuple[int, str]:
    p = subprocess.run(["linkwork", "trace", spec, *args, "--no-plots", "-o", out], capture_output=True, text=True)
    return p.returncode, p.stderr.strip()


cr = C["crank-rocker"][0]
f = sorted(float(x) for x in cr.fold_refs("D"))[:2]
tr = C["triple-rocker"][0]
ft = sorted(float(x) for x in tr.fold_refs("A"))
sc = C["offset-slider-crank"][0]
fs = sorted(float(x) for x in sc.fold_refs("D"))
print("crank-rocker D extremes (law of cosines):", f)
print("triple-rocker A extremes:", ft)
print("slider extremes:", fs)
for nm, drive, vals in [("crank-rocker", "D", [f[0], f[0] + 1e-9, f[0] + 1e-6, f[-1] - 1e-9, f[-1]]),
                        ("triple-rocker", "A", [ft[-1], ft[-1] - 1e-9, ft[-1] - 1e-6, ft[0] + 1e-9, ft[0]]),
                        ("offset-slider-crank", "D", [fs[0], fs[0] + 1e-9, fs[-1] - 1e-9, fs[-1]])]:
    for v in vals:
        rc, err = run(f"{Path(__file__).parent}/specs/{nm}.toml", ["--drive", drive, "--until", f"{drive}={v!r}"],
                      "/tmp/audit-ext")
        rep = read_report("/tmp/audit-ext") if rc in (0, 3) else {}
        cols = read_path_csv("/tmp/audit-ext") if rc in (0, 3) else {}
        last = cols[drive][cols["branch"] == 0][-1] if cols else None
        rng = rep.get("branches", [{}])[0].get("range", {}).get(drive)
        print(f"{nm} {drive}={v!r}: rc={rc} last={last!r} range={rng} {err[:200]}")

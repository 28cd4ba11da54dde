"""Misc checks: paper mode up to and across a Bricard fold; Bennett driven by B; a spec in radians."""
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from ref import read_path_csv, read_report, wrap_deg  # noqa: E402
from run_planar import cases  # noqa: E402
from spatial import Bennett, bricard_line  # noqa: E402

HERE = Path(__file__).parent
OUT = HERE.parent / "out" / "audit"


def run(spec: Path, args: list[str], out: Path) -> subprocess.CompletedProcess:
    return subprocess.run(["linkwork", "trace", str(spec), *args, "--no-plots", "-o", str(out)], capture_output=True,
                          text=True)


def main() -> None:
    br = bricard_line("bricard-line-audit")
    spec = HERE / "specs" / "bricard-line-audit.toml"
    fold = read_report(OUT / "bricard-line-audit-loop")["folds"][0]["value"]
    for tgt, steps in ((fold - 1e-6, 130), (fold, 130), (fold + 1.0, 130), (fold - 1e-6, 0)):
        args = ["--until", f"A={tgt!r}"] + (["--steps", str(steps)] if steps else [])
        p = run(spec, args, OUT / "bricard-fold")
        rep = read_report(OUT / "bricard-fold")
        cols = read_path_csv(OUT / "bricard-fold")
        clos = max(br.closure(np.array([cols[n][i] for n in br.names])) for i in range(len(cols["s"])))
        print(f"bricard-line until A={tgt:.9f} steps={steps}: rc {p.returncode}, end "
              f"{[(b['end_reason'], b['end_value']) for b in rep['branches']]}, rows {len(cols['s'])}, own closure "
              f"{clos:.1e} | {p.stderr.strip()[:200]}")
    b = Bennett("bennett-audit", 0.8, 30.0, 110.0, 70.0)
    spec = HERE / "specs" / "bennett-audit.toml"
    t2 = b.theta0[1]
    for args in (["--drive", "B"], ["--drive", "B", "--until", f"B={t2 + 360!r}"], ["--drive", "B", "--until",
                                                                                     f"B={t2 - 100!r}", "--steps", "50"]):
        p = run(spec, args, OUT / "bennett-B")
        cols = read_path_csv(OUT / "bennett-B")
        rep = read_report(OUT / "bennett-B")
        err = max(b.check(np.array([cols[n][i] for n in b.names]))["angle"] for i in range(len(cols["s"])))
        print(f"bennett {args}: rc {p.returncode}, rows {len(cols['s'])}, closed-form error {err:.1e} deg, ends "
              f"{[(x['end_reason'], x['end_value']) for x in rep['branches']]}")
    # the crank-rocker in radians
    fb = cases()["crank-rocker"][0].mech
    text = fb.toml().replace("value = 35.0", f"value = {float(np.radians(35.0))!r}")
    text = text.replace('name = "crank-rocker"', 'name = "crank-rocker"\nangles = "rad"', 1)
    spec = HERE / "specs" / "crank-rocker-rad.toml"
    spec.write_text(text)
    p = run(spec, ["--until", "A=215", "--steps", "90"], OUT / "rad")
    q = run(HERE / "specs" / "crank-rocker.toml", ["--until", "A=215", "--steps", "90"], OUT / "deg")
    a, c = read_path_csv(OUT / "rad"), read_path_csv(OUT / "deg")
    print("angles = rad vs deg:", p.returncode, q.returncode,
          max(float(np.max(np.abs(wrap_deg(a[n] - c[n])))) for n in "ABCD"), p.stderr.strip()[:200])


if __name__ == "__main__":
    main()

"""points.csv world positions vs the audit's own forward kinematics of each row (planar cases, a named point)."""
import csv
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from ref import read_path_csv  # noqa: E402
from run_planar import cases  # noqa: E402

HERE = Path(__file__).parent
OUT = HERE.parent / "out" / "audit"


def main() -> None:
    C = cases()
    for nm in ("crank-rocker", "offset-slider-crank", "watt"):
        case = C[nm][0]
        text = case.mech.toml()
        body = "coupler" if nm != "offset-slider-crank" else "rod"
        pp = np.array([1.7, 2.9, 0.0])
        text += f'\n[[points]]\nname = "P"\nbody = "{body}"\nposition = [{pp[0]}, {pp[1]}]\n'
        spec = HERE / "specs" / f"{nm}-points.toml"
        spec.write_text(text)
        out = OUT / f"{nm}-points"
        p = subprocess.run(["linkwork", "trace", str(spec), "--no-plots", "-o", str(out)], capture_output=True,
                           text=True)
        assert p.returncode == 0, p.stderr
        cols = read_path_csv(out)
        with open(out / "points.csv") as f:
            rows = list(csv.reader(f))
        head, data = rows[0], np.array(rows[1:], float)
        pc = {h: data[:, i] for i, h in enumerate(head)}
        worst = 0.0
        for i in range(len(cols["s"])):
            g, _ = case.mech.poses({n: cols[n][i] for n in case.mech.names})
            for j in case.mech.joints:
                if j["type"] == "R":
                    b = g[j["bodies"][0]]
                    ref = b[:3, :3] @ j["point"] + b[:3, 3]
                else:  # the mean of the revolute joints of the sliding body, carried by it
                    slider = j["bodies"][1]
                    pts = [k["point"] for k in case.mech.joints if k["type"] == "R" and slider in k["bodies"]]
                    b = g[slider]
                    ref = b[:3, :3] @ np.mean(pts, axis=0) + b[:3, 3]
                got = np.array([pc[f"{j['name']}_{c}"][i] for c in "xyz"])
                worst = max(worst, float(np.abs(got - ref).max()))
            b = g[body]
            ref = b[:3, :3] @ pp + b[:3, 3]
            got = np.array([pc[f"P_{c}"][i] for c in "xyz"])
            worst = max(worst, float(np.abs(got - ref).max()))
        print(f"{nm}: points.csv rows {len(data)} vs path rows {len(cols['s'])}; worst position error {worst:.1e}; "
              f"columns {head[:3]}...{head[-4:]}")


if __name__ == "__main__":
    main()

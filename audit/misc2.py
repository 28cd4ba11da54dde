"""More probes: a start on a bifurcation point, a five-bar with a fixed joint, a Bennett start given rounded."""
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from planar import FourBar, nearest  # noqa: E402
from ref import Mech, about_line, circles, pose2, read_path_csv, read_report, readings_from_poses, sigma_columns  # noqa: E402
from spatial import Bennett  # noqa: E402

HERE = Path(__file__).parent
OUT = HERE.parent / "out" / "audit"


def run(spec: Path, args: list[str], out: Path) -> subprocess.CompletedProcess:
    return subprocess.run(["linkwork", "trace", str(spec), *args, "--no-plots", "-o", str(out)], capture_output=True,
                          text=True)


def main() -> None:
    # 1. a parallelogram started on its crossing (A = 0: all four pivots in line)
    pg = FourBar("parallelogram-at-0", 3.0, 1.0, 3.0, 1.0, 0.0)
    spec = HERE / "specs" / "parallelogram-at-0.toml"
    spec.write_text(pg.mech.toml())
    p = run(spec, [], OUT / "pg0")
    print("parallelogram started at the crossing: rc", p.returncode, "|", p.stderr.strip()[:300])
    # 2. a five-bar (2 dof) with its ground joint E fixed: the four-bar A-B-C-D with D on the ground
    pts = dict(A=(0, 0), B=(0.9, 1.1), C=(3.0, 2.6), D=(4.2, 0.9), E=(4.6, -0.4))
    joints = [dict(name="A", bodies=["ground", "l1"], point=list(pts["A"]), value=50.0),
              dict(name="B", bodies=["l1", "l2"], point=list(pts["B"])),
              dict(name="C", bodies=["l2", "l3"], point=list(pts["C"])),
              dict(name="D", bodies=["l3", "l4"], point=list(pts["D"])),
              dict(name="E", bodies=["l4", "ground"], point=list(pts["E"]))]
    five = Mech("five-bar", joints, planar=True)
    spec = HERE / "specs" / "five-bar.toml"
    spec.write_text(five.toml().replace("planar = true", 'planar = true\nfixed = ["E"]'))
    p = run(spec, [], OUT / "five")
    cols, rep = read_path_csv(OUT / "five"), read_report(OUT / "five")
    # reference: the four-bar with ground pivots A and D (D fixed with l4 held to the ground)
    ref4 = Mech("ref4", [dict(joints[0]), dict(joints[1]), dict(joints[2]),
                         dict(name="D", bodies=["l3", "ground"], point=list(pts["D"]))], planar=True)
    P = {k: np.array([*v, 0.0]) for k, v in pts.items()}
    lbc, lcd = float(np.linalg.norm(P["C"] - P["B"])), float(np.linalg.norm(P["D"] - P["C"]))

    def solve(a_deg: float) -> list[dict[str, float]]:
        g1 = about_line(P["A"], [0, 0, 1], np.radians(a_deg - 50.0))
        b1 = g1[:3, :3] @ P["B"] + g1[:3, 3]
        out = []
        for c1 in circles(b1, lbc, P["D"], lcd):
            c1 = np.array([c1[0], c1[1], 0.0])
            g = dict(ground=np.eye(4), l1=g1, l2=pose2(P["B"], P["C"], b1, c1), l3=pose2(P["D"], P["C"], P["D"], c1))
            out.append(readings_from_poses(ref4, g))
        return out

    worst = worst_sig = 0.0
    sig = sigma_columns(cols)
    for i in range(len(cols["s"])):
        row = {n: cols[n][i] for n in "ABCD"}
        worst = max(worst, nearest(solve(row["A"]), row, list("ABCD"), set())[0])
        full = five.jacobian({**row, "E": cols["E"][i]}, columns=[["A"], ["B"], ["C"], ["D"]])
        s_ref = np.linalg.svd(full, compute_uv=False)
        worst_sig = max(worst_sig, float(np.max(np.abs(sig[i] - s_ref[: sig.shape[1]])) / s_ref[0]))
    print(f"five-bar with E fixed: rc {p.returncode}, unknowns {rep['unknowns']}, rank {rep['rank']}, rows "
          f"{len(cols['s'])}, E moved {np.max(np.abs(cols['E'] - cols['E'][0])):.1e}, A-D vs the four-bar closed form "
          f"{worst:.1e} deg, sigma vs SVD without E's column {worst_sig:.1e}, end {rep['branches'][0]['end_reason']}")
    # 3. Bennett with its start rounded to 0.01 deg: corrected onto the loop, every row on Bennett's relation
    b = Bennett("bennett-audit", 0.8, 30.0, 110.0, 70.0)
    spec = HERE / "specs" / "bennett-rounded.toml"
    spec.write_text(b.toml(theta=[round(t, 2) for t in b.theta0]))
    p = run(spec, [], OUT / "bennett-rounded")
    cols, rep = read_path_csv(OUT / "bennett-rounded"), read_report(OUT / "bennett-rounded")
    err = max(b.check(np.array([cols[n][i] for n in b.names]))["angle"] for i in range(len(cols["s"])))
    print(f"bennett start rounded to 0.01 deg: rc {p.returncode}, correction {rep['assembly']['correction_deg']}, "
          f"residual {rep['assembly']['residual_before']:.1e} -> {rep['assembly']['residual_after']:.1e}; rows "
          f"{len(cols['s'])} on Bennett's relation to {err:.1e} deg; end {rep['branches'][0]['end_reason']}")


if __name__ == "__main__":
    main()

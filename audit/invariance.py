"""Check 3: the adaptive step sequence is the same with every length x1000 and with the linkage moved and turned.

Each variant is written by the audit as its own spec file (the geometry transformed in numpy), traced by the
CLI without a target (the whole loop); the rows' ``s`` and joint values are compared with the original's.
"""
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from ref import Mech, dh, read_path_csv, read_report, rot, wrap_deg  # noqa: E402
from run_planar import cases as pcases  # noqa: E402
from spatial import Bennett, Spherical4R  # noqa: E402

HERE = Path(__file__).parent
OUT = HERE.parent / "out" / "audit"


def motion(seed: int, planar: bool = False) -> np.ndarray:
    rng = np.random.default_rng(seed)
    g = np.eye(4)
    if planar:
        g[:3, :3] = rot([0, 0, 1], rng.uniform(-np.pi, np.pi))
        g[:2, 3] = rng.uniform(-50, 50, 2)
    else:
        g[:3, :3] = rot(rng.normal(size=3), rng.uniform(-np.pi, np.pi))
        g[:3, 3] = rng.uniform(-50, 50, 3)
    return g


def bennett_lines(b: Bennett) -> Mech:
    """Bennett's hinge lines from its DH frames at the start (the audit's DH product), as a spatial loop."""
    g = np.eye(4)
    joints = []
    bodies = ["L3", "L0", "L1", "L2", "L3"]
    for i, (n, (d, a, al), t) in enumerate(zip(b.names, b.links, b.theta0)):
        joints.append(dict(name=n, bodies=[bodies[i], bodies[i + 1]], point=list(g[:3, 3]),
                           direction=list(g[:3, 2]), value=t))
        g = g @ dh(np.radians(t), d, a, np.radians(al))
    return Mech("bennett-lines", joints, planar=False, root="L3")


def trace(text: str, name: str, args: list[str] = ()) -> dict:
    spec = HERE / "specs" / f"{name}.toml"
    spec.write_text(text)
    out = OUT / f"inv-{name}"
    p = subprocess.run(["linkwork", "trace", str(spec), *args, "--no-plots", "-o", str(out)], capture_output=True,
                       text=True)
    assert p.returncode == 0, p.stderr
    c = read_path_csv(out)
    c["_report"] = read_report(out)
    return c


def compare(a: dict, b: dict, names: list[str]) -> str:
    if len(a["s"]) != len(b["s"]):
        return f"ROWS DIFFER {len(a['s'])} vs {len(b['s'])}"
    ds = float(np.max(np.abs(a["s"] - b["s"])))
    dj = max(float(np.max(np.abs(wrap_deg(a[n] - b[n])))) for n in names)
    return f"rows={len(a['s'])} max|ds|={ds:.1e} deg max|djoint|={dj:.1e} deg"


def main() -> None:
    b = Bennett("bennett-audit", 0.8, 30.0, 110.0, 70.0)
    base = trace(b.toml(), "bennett-dh-1")
    print("bennett dh x1000:", compare(base, trace(b.toml(scale=1000), "bennett-dh-1000"), b.names))
    m = bennett_lines(b)
    hl = trace(m.toml(), "bennett-mech")
    print("bennett dh vs hinge lines:", compare(base, hl, b.names))
    print("bennett lines x1000:", compare(hl, trace(m.toml(scale=1000), "bennett-mech-1000"), b.names))
    for seed in (1, 2):
        print(f"bennett lines moved+turned ({seed}):",
              compare(hl, trace(m.toml(motion=motion(seed)), f"bennett-mech-moved{seed}"), b.names))
    print("bennett lines x1000 moved+turned:",
          compare(hl, trace(m.toml(scale=1000, motion=motion(3)), "bennett-mech-1000-moved"), b.names))
    s = Spherical4R("spherical-4r", 70, 25, 60, 50, 30)
    sp = trace(s.toml(), "sph-0")
    print("spherical moved+turned:", compare(sp, trace(s.toml(motion=motion(4)), "sph-moved"), s.names))
    fb = pcases()["crank-rocker"][0].mech
    f0 = trace(fb.toml(), "fb-0")
    print("four-bar x1000:", compare(f0, trace(fb.toml(scale=1000), "fb-1000"), fb.names))
    print("four-bar moved+turned in plane:", compare(f0, trace(fb.toml(motion=motion(5, True)), "fb-moved"), fb.names))
    sp3 = Mech(fb.name, [dict(j, point=list(j["point"]), direction=list(j["direction"])) for j in fb.joints],
               planar=False)
    f3 = trace(sp3.toml(motion=motion(6)), "fb-spatial-moved")
    print("four-bar as a spatial [mechanism], moved+turned in space:", compare(f0, f3, fb.names),
          "rank", f3["_report"]["rank"], "equations", f3["_report"]["equations"])
    for lbl, args in [("paper", ["--until", "A=215", "--steps", "90"]), ("drive-D", ["--drive", "D"])]:
        a = trace(fb.toml(), f"fb-0-{lbl}", args)
        print(f"four-bar {lbl} x1000 moved:",
              compare(a, trace(fb.toml(scale=1000, motion=motion(7, True)), f"fb-1000-{lbl}", args), fb.names))
    sc = pcases()["offset-slider-crank"][0].mech
    s0 = trace(sc.toml(), "sc-0", ["--drive", "D"])
    s1 = trace(sc.toml(scale=1000, motion=motion(8, True)), "sc-1000-moved", ["--drive", "D"])
    # the slider reading is a length: compare it scaled back
    s1["D"] = s1["D"] / 1000
    print("slider-crank (slider drive) x1000 moved:", compare(s0, s1, sc.names),
          "(s is in degrees and lengths mixed: see audit.md)")


if __name__ == "__main__":
    main()

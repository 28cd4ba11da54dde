"""Check 4: exit codes and one-line messages for malformed spec files and requests (CLI)."""
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from run_planar import cases  # noqa: E402
from spatial import Bennett, Spherical4R  # noqa: E402

HERE = Path(__file__).parent
BAD = HERE / "specs" / "bad"


def variants() -> list[tuple[str, str, str, list[str], int]]:
    """(file name, text, what the message must name, extra args, expected exit code)."""
    fb = cases()["crank-rocker"][0].mech.toml()
    sc = cases()["offset-slider-crank"][0].mech.toml()
    bn = Bennett("bennett-audit", 0.8, 30.0, 110.0, 70.0).toml()
    sp = Spherical4R("spherical-4r", 70, 25, 60, 50, 30).toml()
    v = []
    v.append(("fb-missing-bodies.toml", fb.replace('bodies = ["crank", "coupler"]\n', "", 1), "mechanism.joints[1].bodies", [], 2))
    v.append(("fb-point-string.toml", fb.replace("point = [4.0, 0.0, 0.0]", 'point = [4.0, "x", 0.0]'), "mechanism.joints[3].point[1]", [], 2))
    v.append(("fb-value-string.toml", fb.replace("value = 35.0", 'value = "35"'), "mechanism.joints[0].value", [], 2))
    v.append(("fb-point-nan.toml", fb.replace("point = [4.0, 0.0, 0.0]", "point = [nan, 0.0, 0.0]"), "mechanism.joints[3].point[0]", [], 2))
    v.append(("fb-point-inf.toml", fb.replace("point = [4.0, 0.0, 0.0]", "point = [inf, 0.0, 0.0]"), "mechanism.joints[3].point[0]", [], 2))
    v.append(("fb-value-neginf.toml", fb.replace("value = 35.0", "value = -inf"), "mechanism.joints[0].value", [], 2))
    v.append(("sc-slider-dir-zero.toml", sc.replace("direction = [1.0, 0.0, 0.0]", "direction = [0.0, 0.0, 0.0]"), "mechanism.joints[3].direction", [], 2))
    v.append(("bn-a-string.toml", bn.replace("a = 0.8", 'a = "0.8"', 1), "loop.joints[0].a", [], 2))
    v.append(("bn-alpha-nan.toml", bn.replace("alpha = 30.0", "alpha = nan", 1), "loop.joints[0].alpha", [], 2))
    v.append(("bn-d-inf.toml", bn.replace("d = 0.0", "d = inf", 1), "loop.joints[0].d", [], 2))
    v.append(("bn-theta-missing-convention.toml", bn.replace('convention = "dh"\n', ""), "loop.convention", [], 2))
    # rounded twist: Bennett no longer closes (an over-constrained loop with a wrong link)
    v.append(("bn-not-closing.toml", bn.replace("alpha = 110.0", "alpha = 110.5", 1), "misfit", [], 2))
    # link lengths that cannot close at all
    v.append(("bn-far.toml", bn.replace("a = 0.8", "a = 8.0", 1), "bn-far.toml", [], 2))
    v.append(("bn-negative-a.toml", bn.replace("a = 0.8", "a = -0.8", 1), "loop.joints[0].a", [], 2))
    v.append(("sp-direction-missing.toml", sp.replace("direction = [0.0, 0.0, 1.0]\n", "", 1), "loop.joints[0].direction", [], 2))
    v.append(("sp-point-short.toml", sp.replace("point = [0.0, 0.0, 0.0]", "point = [0.0, 0.0]", 1), "loop.joints[0].point", [], 2))
    v.append(("sp-theta-bool.toml", sp.replace("theta = 30.0", "theta = true", 1), "loop.joints[0].theta", [], 2))
    v.append(("ok-fb.toml", fb, "--until", ["--until", "B=abc"], 2))
    v.append(("ok-fb2.toml", fb, "--until", ["--until", "E=10"], 2))
    v.append(("ok-fb3.toml", fb, "--steps", ["--steps", "10"], 2))
    v.append(("ok-fb4.toml", fb, "--drive", ["--drive", "Q"], 2))
    v.append(("ok-fb5.toml", fb, "never reaches", ["--drive", "D", "--until", "D=-90"], 3))
    v.append(("ok-sc.toml", sc, "never reaches", ["--drive", "D", "--until", "D=5"], 3))
    v.append(("ok-sc2.toml", sc, "--until", ["--drive", "D", "--until", "D=nan"], 2))
    v.append(("ok-fb6.toml", fb, "--max-step", ["--max-step", "-1"], 2))
    return v


def main() -> None:
    BAD.mkdir(parents=True, exist_ok=True)
    fails = 0
    for fname, text, key, args, code in variants():
        f = BAD / fname
        f.write_text(text)
        p = subprocess.run(["linkwork", "trace", str(f), *args, "--no-plots", "-o", "/tmp/audit-bad"],
                           capture_output=True, text=True)
        lines = [x for x in p.stderr.splitlines() if x.strip()]
        ok = (p.returncode == code and "Traceback" not in p.stderr and len(lines) == 1 and key in p.stderr
              and (fname in p.stderr or args))
        fails += not ok
        print(("ok  " if ok else "FAIL"), fname, args, "rc", p.returncode, "|", " / ".join(lines)[:400])
    print("failures:", fails)


if __name__ == "__main__":
    main()

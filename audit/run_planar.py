"""Check 1 and 2 on planar linkages: CLI path.csv and the Python Trace against closed forms and numpy SVDs.

Usage: python audit/run_planar.py [CASE ...]   (from the worktree, the venv active, PYTHONPATH=src)
Writes audit/specs/<case>.toml and out/audit/<case>-<run>/, prints one line per run with the worst errors.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from planar import FourBar, SliderCrank, Stephenson3, Watt, nearest  # noqa: E402
from ref import read_path_csv, read_report, sigma_columns, wrap_deg  # noqa: E402

HERE = Path(__file__).parent
SPECS = HERE / "specs"
OUT = HERE.parent / "out" / "audit"


def cases() -> dict:
    """name -> (case object, list of (label, CLI args, drive))."""
    c = {}
    c["crank-rocker"] = (FourBar("crank-rocker", 4.0, 1.3, 3.7, 2.9, 35.0), [
        ("loop", [], "A"),
        ("paper", ["--until", "A=215", "--steps", "90"], "A"),
        ("turn", ["--until", "A=395"], "A"),
        ("below-turn", ["--until", "A=394.9999"], "A"),
        ("rocker-drive", ["--drive", "D"], "D"),
    ])
    c["double-crank"] = (FourBar("double-crank", 1.0, 2.5, 3.0, 2.8, 70.0), [
        ("loop", [], "A"),
        ("rocker-turn", ["--drive", "D", "--until", "D=-360"], "D"),
        ("paper", ["--until", "A=-100", "--steps", "17"], "A"),
    ])
    c["triple-rocker"] = (FourBar("triple-rocker", 4.0, 2.0, 3.5, 2.4, 20.0), [
        ("loop", [], "A"),
        ("paper", ["--until", "A=150", "--steps", "65"], "A"),
    ])
    c["change-point"] = (FourBar("change-point", 4.0, 1.5, 3.0, 2.5, 60.0), [
        ("loop", [], "A"),
        ("paper", ["--until", "A=170", "--steps", "110"], "A"),
    ])
    c["parallelogram"] = (FourBar("parallelogram", 3.0, 1.0, 3.0, 1.0, 30.0), [
        ("loop", [], "A"),
        ("paper-on-bif", ["--until", "A=200", "--steps", "170"], "A"),
    ])
    c["deltoid"] = (FourBar("deltoid", 1.0, 1.0, 2.5, 2.5, 50.0), [
        ("loop", [], "A"),
    ])
    sc = SliderCrank("offset-slider-crank", 1.0, 3.0, 0.4, 40.0)
    c["offset-slider-crank"] = (sc, [
        ("loop", [], "A"),
        ("slider-drive", ["--drive", "D"], "D"),
        ("slider-target", ["--drive", "D", "--until", f"D={float(sc.x0) - 1.2!r}"], "D"),
        ("paper", ["--until", "A=130", "--steps", "45"], "A"),
    ])
    c["watt"] = (Watt("watt-audit", dict(A=(0, 0), B=(0.6, 0.8), C=(3.1, 2.9), D=(3.8, 0.2), E=(5.2, 2.1),
                                         F=(7.1, 3.6), G=(8.4, -0.3)), 53.13010235415598), [
        ("loop", [], "A"),
        ("paper", ["--until", "A=233.13010235415598", "--steps", "60"], "A"),
    ])
    c["stephenson3"] = (Stephenson3("stephenson-audit", dict(A=(0, 0), B=(0.7, 0.6), C=(3.3, 2.4), D=(4.1, -0.1),
                                                             E=(1.9, 3.6), F=(-1.2, 4.8), G=(-2.3, 0.4)), 40.6), [
        ("loop", [], "A"),
        ("paper", ["--until", "A=100.6", "--steps", "30"], "A"),
    ])
    return c


def check_rows(case, names: list[str], rows: np.ndarray, sig: np.ndarray | None, drive: str,
               units_deg: bool = True) -> dict:
    """Worst errors of rows (N, n joints; degrees / lengths) against the closed form and numpy SVDs."""
    mech = case.mech
    pris = {j["name"] for j in mech.joints if j["type"] == "P"}
    worst_angle, worst_closure, worst_sig, worst_ratio = 0.0, 0.0, 0.0, 0.0
    switches, last = [], None
    for i, r in enumerate(rows):
        row = dict(zip(names, r))
        cands = case.solve(drive, row[drive])
        err, bi = nearest(cands, row, names, pris)
        # near a fold of the drive the closed form from the drive is ill-conditioned (a square root of ~0):
        # the row is then checked from the other input the case can solve from, well-conditioned there
        for other in getattr(case, "inputs", ()):
            if other != drive:
                err = min(err, nearest(case.solve(other, row[other]), row, names, pris)[0])
        worst_angle = max(worst_angle, err)
        if last is not None and bi != last:
            # an assembly switch is legitimate only where the two assemblies (nearly) coincide
            gap = nearest([cands[1 - bi]], row, names, pris)[0] if len(cands) == 2 else np.nan
            switches.append((i, round(float(row[drive]), 6), float(gap)))
        last = bi
        _, mis = mech.poses(row)
        worst_closure = max(worst_closure, mis)
        if sig is not None:
            s_ref = np.linalg.svd(mech.jacobian(row), compute_uv=False)
            k = sig.shape[1]
            worst_sig = max(worst_sig, float(np.max(np.abs(sig[i] - s_ref[:k])) / s_ref[0]))
            worst_ratio = max(worst_ratio, float(np.max(np.abs(sig[i] / sig[i][0] - s_ref[:k] / s_ref[0]))))
    return dict(rows=len(rows), angle=worst_angle, closure=worst_closure, sigma_rel=worst_sig,
                ratio=worst_ratio, switches=switches)


def run_cli(case_name: str, case, label: str, args: list[str]) -> tuple[int, str, Path]:
    SPECS.mkdir(exist_ok=True)
    spec = SPECS / f"{case_name}.toml"
    spec.write_text(case.mech.toml())
    out = OUT / f"{case_name}-{label}"
    p = subprocess.run(["linkwork", "trace", str(spec), *args, "--no-plots", "-o", str(out)],
                       capture_output=True, text=True)
    return p.returncode, p.stderr.strip(), out


def main(which: list[str]) -> None:
    import linkwork as lw

    for name, (case, runs) in cases().items():
        if which and name not in which:
            continue
        for label, args, drive in runs:
            rc, err, out = run_cli(name, case, label, args)
            if not (out / "path.csv").exists():
                print(f"{name:22s} {label:14s} rc={rc} NO OUTPUT: {err}")
                continue
            cols = read_path_csv(out)
            rep = read_report(out)
            names = case.mech.names
            rows = np.stack([cols[n] for n in names], axis=1)
            res = check_rows(case, names, rows, sigma_columns(cols), drive)
            pdrive = drive in {x["name"] for x in case.mech.joints if x["type"] == "P"}
            fr = case.fold_refs(drive) if hasattr(case, "fold_refs") else []
            fold_err = 0.0
            for f in rep["folds"]:
                d = [abs(f["value"] - x) if pdrive else abs(wrap_deg(f["value"] - x)) for x in fr]
                fold_err = max(fold_err, min(d) if d else np.inf)
            closed = ""
            b0 = cols["branch"] == 0
            if rep["branches"][0]["end_kind"] == "closed":
                first, last = rows[b0][0], rows[b0][-1]
                dj = np.where([x["type"] == "P" for x in case.mech.joints], first - last, wrap_deg(first - last))
                sg = sigma_columns(cols)[b0]
                closed = (f" closed: joints {np.max(np.abs(dj)):.1e} sigma {np.max(np.abs(sg[0] - sg[-1])):.1e}"
                          f" res {abs(cols['residual'][b0][0] - cols['residual'][b0][-1]):.1e}")
            ends = [(b["end_kind"], round(b["end_value"], 9) if b["end_value"] is not None else None)
                    for b in rep["branches"]]
            print(f"{name:22s} {label:14s} rc={rc} rows={res['rows']} angle={res['angle']:.2e} "
                  f"closure={res['closure']:.1e} sigma={res['sigma_rel']:.1e} ratio={res['ratio']:.1e} "
                  f"bif={[round(b['angles'][drive], 6) for b in rep['bifurcations']]} "
                  f"folds={[round(f['value'], 6) for f in rep['folds']]} ends={ends} "
                  f"maxres={max(cols['residual']):.1e} switches={res['switches'][:4]} fold_err={fold_err:.1e}{closed}"
                  + (f" stderr={err!r}" if err else ""))
            # the Python API, same request
            mech = lw.load(str(SPECS / f"{name}.toml"))
            until = None
            steps = None
            drv = drive
            if "--until" in args:
                j, v = args[args.index("--until") + 1].split("=")
                pj = j in {x["name"] for x in case.mech.joints if x["type"] == "P"}
                until = (j, float(v) if pj else np.radians(float(v)))
            if "--steps" in args:
                steps = int(args[args.index("--steps") + 1])
            tr = lw.trace(mech, drive=drv, until=until, steps=steps)
            pris = [x["type"] == "P" for x in case.mech.joints]
            ang = np.array([np.asarray(tr.angles)[:, k] if pris[k] else np.degrees(np.asarray(tr.angles)[:, k])
                            for k in range(len(names))]).T
            assert list(mech.joint_names) == names, (mech.joint_names, names)
            res2 = check_rows(case, names, ang, np.asarray(tr.sigma), drive)
            same = float(np.max(np.abs(wrap_deg(ang - rows)))) if ang.shape == rows.shape else np.nan
            fold_py = [float(np.degrees(f.value)) if not pris[names.index(drive)] else float(f.value)
                       for f in tr.folds]
            fold_js = [f["value"] for f in rep["folds"]]
            fold_diff = (max((abs(a - b) for a, b in zip(fold_py, fold_js)), default=0.0)
                         if len(fold_py) == len(fold_js) else f"count {len(fold_py)} vs {len(fold_js)}")
            print(f"{'':22s} {'python':14s} rows={res2['rows']} angle={res2['angle']:.2e} "
                  f"sigma={res2['sigma_rel']:.1e} cli-vs-py={same:.1e} folds py-vs-json={fold_diff}")


if __name__ == "__main__":
    main(sys.argv[1:])

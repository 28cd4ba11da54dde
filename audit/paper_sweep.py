"""Paper mode swept over targets and step counts (Python API): every request whose target lies on the start's
branch before the drive's first fold must be reached, with no joint jumping by a whole turn.

Reference: the drive's reachable interval from the law of cosines (the start's side of the first fold) and the
closed form's continuous joint values (the unwrapped difference between consecutive rows)."""
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from ref import wrap_deg  # noqa: E402
from run_planar import cases  # noqa: E402

HERE = Path(__file__).parent


def main() -> None:
    import linkwork as lw

    C = cases()
    rng = np.random.default_rng(3)
    for nm, drive, lo, hi in (("crank-rocker", "D", -54.958143662771214, 0.0012668920319210625),
                              ("triple-rocker", "A", -157.76278912443698, 157.76278912443698),
                              ("offset-slider-crank", "D", 1.9595917942265424, 3.97994974842648)):
        case = C[nm][0]
        mech = lw.load(str(HERE / "specs" / f"{nm}.toml"))
        k = case.mech.names.index(drive)
        pris = case.mech.joints[k]["type"] == "P"
        start = case.mech.joints[k]["value"]
        fails, jumps, n = [], [], 0
        for _ in range(60):
            tgt = float(rng.uniform(lo, hi))
            if abs(tgt - start) < 1e-3:
                continue
            steps = int(rng.integers(2, 80))
            n += 1
            t = lw.trace(mech, drive=drive, until=(drive, tgt if pris else np.radians(tgt)), steps=steps)
            ang = np.asarray(t.angles).copy()
            for j, jj in enumerate(case.mech.joints):
                if jj["type"] == "R":
                    ang[:, j] = np.degrees(ang[:, j])
            if t.stats.unmet is not None:
                fails.append((round(tgt, 6), steps, t.branches[0].end_reason[:30]))
            dif = np.abs(np.diff(ang, axis=0))
            wrapped = np.abs(wrap_deg(np.diff(ang, axis=0)))
            revo = [j for j, jj in enumerate(case.mech.joints) if jj["type"] == "R"]
            if len(ang) > 1 and np.max(dif[:, revo] - wrapped[:, revo]) > 1.0:
                jumps.append((round(tgt, 6), steps, float(np.max(dif[:, revo]))))
        print(f"{nm} drive {drive}: {n} requests inside [{lo:.6f}, {hi:.6f}] from the start; not reached: "
              f"{len(fails)} {fails[:6]}; whole-turn jumps between rows: {len(jumps)} {jumps[:6]}")


def bricard() -> None:
    """The same on the audit's line-symmetric Bricard (folds of A at -94.061 and 171.306 deg, start 40)."""
    import linkwork as lw

    from spatial import bricard_line

    case = bricard_line("bricard-line-audit")
    mech = lw.load(str(HERE / "specs" / "bricard-line-audit.toml"))
    rng = np.random.default_rng(5)
    fails, jumps, worst = [], [], 0.0
    for _ in range(40):
        tgt = float(rng.uniform(-94.0610565214379, 171.30592224673168))
        steps = int(rng.integers(2, 80))
        t = lw.trace(mech, until=("A", np.radians(tgt)), steps=steps)
        ang = np.degrees(np.asarray(t.angles))
        if t.stats.unmet is not None:
            fails.append((round(tgt, 6), steps, t.branches[0].end_reason[:30]))
        if len(ang) > 1:
            dif = np.abs(np.diff(ang, axis=0))
            if np.max(dif - np.abs(wrap_deg(np.diff(ang, axis=0)))) > 1.0:
                jumps.append((round(tgt, 6), steps, float(np.max(dif))))
        worst = max(worst, max(case.closure(r) for r in ang))
    print(f"bricard-line drive A: 40 requests inside [-94.061, 171.306]; not reached: {len(fails)} {fails[:6]};"
          f" whole-turn jumps: {len(jumps)} {jumps[:6]}; own closure worst {worst:.1e}")


if __name__ == "__main__":
    bricard()
    main()

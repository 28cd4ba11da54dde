"""How often F2 bites with default settings: random Grashof crank-rockers (the audit's FourBar), traced round
their loop by lw.trace with and without a progress callback (the CLI always passes one)."""
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from planar import FourBar  # noqa: E402


def main(n: int = 100) -> None:
    import linkwork as lw

    rng = np.random.default_rng(11)
    differ, tried, mods, rows_all = [], 0, [], []
    with tempfile.TemporaryDirectory() as tmp:
        while tried < n:
            a, b, c, g = rng.uniform(0.5, 1.0), rng.uniform(2.0, 4.0), rng.uniform(2.0, 4.0), rng.uniform(2.0, 4.0)
            s_, l_ = min(a, b, c, g), max(a, b, c, g)
            if not (s_ + l_ < a + b + c + g - s_ - l_ and s_ == a):
                continue
            fb = FourBar("r", g, a, b, c, float(rng.uniform(0, 360)))
            if np.isnan(fb.pts["C"]).any():
                continue
            tried += 1
            spec = Path(tmp) / "r.toml"
            spec.write_text(fb.mech.toml())
            m = lw.load(str(spec))
            t0 = lw.trace(m, max_steps=3000)
            t1 = lw.trace(m, max_steps=3000, progress=lambda *x: None)
            mods.append(len(t0.angles) % 100)
            rows_all.append(len(t0.angles))
            if len(t0.angles) != len(t1.angles):
                differ.append((round(g, 3), round(a, 3), round(b, 3), round(c, 3), len(t0.angles), len(t1.angles),
                               t1.branches[0].end_reason))
    print(f"{tried} random crank-rockers, default settings: {len(differ)} close differently with a progress "
          f"callback (the CLI's chunks): {differ[:8]}; rows mod 100 in 1..5: {sum(1 <= x <= 5 for x in mods)}; rows: {sorted(rows_all)[:5]}..{sorted(rows_all)[-5:]}")


if __name__ == "__main__":
    main()


def bennett(n: int = 150) -> None:
    """The same on random Bennett loops (the built-in, random twists), default settings."""
    import linkwork as lw

    rng = np.random.default_rng(12)
    differ, rows_all = [], []
    for _ in range(n):
        a1, a2 = rng.uniform(10, 80), rng.uniform(95, 170)
        m = lw.load("bennett", alpha1=np.radians(a1), alpha2=np.radians(a2), theta=np.radians(rng.uniform(10, 170)))
        t0 = lw.trace(m, max_steps=3000)
        t1 = lw.trace(m, max_steps=3000, progress=lambda *x: None)
        rows_all.append(len(t0.angles))
        if len(t0.angles) != len(t1.angles):
            differ.append((round(a1, 3), round(a2, 3), len(t0.angles), len(t1.angles), t1.branches[0].end_reason))
    print(f"{n} random Bennett loops, default settings: {len(differ)} close differently with a progress callback: "
          f"{differ[:6]}; rows {min(rows_all)}..{max(rows_all)}, mod 100 in 1..5: "
          f"{sum(1 <= x % 100 <= 5 for x in rows_all)}")


bennett()

"""Draw the figures of the synthesis example write-ups (``docs/examples/<name>.md``) into
``docs/examples/figures/``.

Run from anywhere after ``pip install -e .``: ``python docs/examples/make_figures.py``. Each example is
synthesised from the bundled ``<name>`` example (``linkwork.data.example(name)``) and its figures are written as ``<name>_<figure>.png`` (PNG
only, at 80 dpi, to keep each file small). It prints each example's E_max and run time, the numbers quoted in
the write-ups.
"""

from __future__ import annotations

import time
from pathlib import Path

import matplotlib

from linkwork.data import example
from linkwork.io.problem import load_problem
from linkwork.synthesis import synthesize
from linkwork.viz import synthesis_plots as plots

OUT = Path(__file__).resolve().parent / "figures"
NAMES = ("wing", "closed", "fixed-end", "seat")
DPI = 80


def main() -> None:
    """Synthesise every example and write its figures."""
    OUT.mkdir(parents=True, exist_ok=True)
    for name in NAMES:
        problem = load_problem(example(name))
        start = time.perf_counter()
        result = synthesize(problem)
        seconds = time.perf_counter() - start
        figures = {"profiles": plots.plot_profiles(result), "chain": plots.plot_chain(result)}
        kinds = [segment.kind for segment in result.segments]
        if "M" in kinds:
            figures["m_segment"] = plots.plot_mean_segment(result, kinds.index("M"))
        if "C" in kinds:
            figures["c_segment"] = plots.plot_arc_segment(result, kinds.index("C"))
        if result.compound is not None and result.compound.merged:
            figures["compound"] = plots.plot_compound(result)
        for stem, figure in figures.items():
            with matplotlib.rc_context({"svg.hashsalt": "linkwork"}):
                figure.savefig(OUT / f"{name}_{stem}.png", dpi=DPI, metadata={"Software": None})
        merged = "" if result.compound is None else f", compound E_max {result.compound.e_max:.4f}"
        print(
            f"{name:10s} design {result.design}  pieces {[t.pieces for t in result.targets]}  "
            f"E_max {result.e_max:.4f} -> joined {result.joined_e_max:.4f}{merged}  ({seconds:.1f} s)"
        )


if __name__ == "__main__":
    main()

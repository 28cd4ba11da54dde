"""``linkwork demo``: both halves of linkwork on bundled examples, written into one folder a newcomer can open.

References
----------
W. W. Gan, S. Pellegrino, Proc. IMechE Part C 220 (2006), Eq. (10).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, NamedTuple

import typer
from rich.text import Text

from linkwork.cli.common import friendly_errors
from linkwork.names import html_text
from linkwork.outputs.staging import check_output_folder, console, staged_output


@friendly_errors
def demo(
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder.")] = Path("linkwork-demo"),
    no_plots: Annotated[bool, typer.Option("--no-plots", help="Do not draw figures.")] = False,
) -> None:
    """Deploy Hedgepeth's hexagon from the bundle to the flat hexagon (Figs. 12-13), follow Guest's frame
    through its bifurcations (Figs. 15-16), synthesise and mechanize a morphing wing; write everything with an
    index.html into --out.

    Everything is written into a staging folder and moved into --out at the end: a demo interrupted (Ctrl-C,
    SIGTERM) or failing leaves --out as it was, its previous complete result or nothing."""
    check_output_folder(out)
    with staged_output(out) as stage:
        _build_demo(stage, no_plots)
    console.print(f"\nopen {out / 'index.html'} to see every result")


class Section(NamedTuple):
    """One part of the demo as index.html shows it: a title, a paragraph, its folder and its figures."""

    title: str
    text: str
    folder: Path
    figures: list[str]


def _build_demo(out: Path, no_plots: bool) -> None:
    """Run the four parts of the demo and write them, with index.html, into ``out`` (the staging folder)."""
    plots = not no_plots
    sections = [
        _hexagon(out, plots),
        _guest_frame(out, plots),
        _wing(out, plots),
        _mechanized_wing(out, plots),
    ]
    _write_index(out, sections)


def _heading(text: str) -> None:
    """A rule with the part's title on the terminal."""
    console.rule(Text(text, style="bold"))


def _hexagon(out: Path, plots: bool) -> Section:
    """Part 1: Hedgepeth's hexagon deployed from the bundle to the flat hexagon in the paper's 200 steps."""
    import numpy as np

    import linkwork as lw
    from linkwork.linkages.hedgepeth_rods import deployed_angles
    from linkwork.outputs.trace import print_trace_summary, write_trace_outputs

    _heading("1. Hedgepeth's deployable hexagon (Gan & Pellegrino 2006, Sec. 5, Figs. 12-13)")
    hexagon = lw.load("hedgepeth-rods", n=6)
    inner, outer = deployed_angles(6)
    traced = lw.trace(hexagon, until=("A", inner), steps=200)
    figs = write_trace_outputs(traced, out / "hexagon", plots=plots, html=True, animate=plots)
    print_trace_summary(traced)
    a = np.degrees(traced.angles[-1])
    return Section(
        "Hedgepeth's hexagon (Sec. 5, Figs. 12-13): from the bundle to the flat hexagon",
        f"The hoop built from its six mitred triangular rods, in 200 equal steps of θA from the folded "
        f"bundle to the flat hexagon; no symmetry imposed, and A = C = E = {a[0]:.4f}°, "
        f"B = D = F = {a[1]:.4f}° at the end (closed form {np.degrees(inner):.4f}° and "
        f"{np.degrees(outer):.4f}°; max |A - C| along the path "
        f"{np.degrees(np.abs(traced.angles[:, 0] - traced.angles[:, 2]).max()):.1e}°). Eq. (10)'s 87.0067° "
        "cannot be a flat hexagon: see docs/linkages.md.",
        out / "hexagon",
        [f.name for f in figs],
    )


def _guest_frame(out: Path, plots: bool) -> Section:
    """Part 2: Guest's rectangular frame, every branch through its bifurcation points."""
    import linkwork as lw
    from linkwork.outputs.trace import print_trace_summary, write_trace_outputs

    _heading("2. Guest's rectangular frame: bifurcations and every branch (Sec. 6, Figs. 15-16)")
    traced = lw.trace(lw.load("guest-frame"), branches=True, max_steps=6000)
    figs = write_trace_outputs(traced, out / "guest-frame", plots=plots, html=True, animate=plots)
    print_trace_summary(traced)
    lowest = min((b.rank for b in traced.bifurcations), default=traced.stats.start_rank)
    return Section(
        "Guest's frame, every branch",
        f"{len(traced.bifurcations)} bifurcation points (rank {traced.stats.start_rank} → {lowest}) and "
        f"{len(traced.branches)} traced branches.",
        out / "guest-frame",
        [f.name for f in figs],
    )


def _wing(out: Path, plots: bool) -> Section:
    """Part 3: the morphing wing synthesised from its three profiles, with its viewer."""
    from linkwork.outputs.synthesis import print_synthesis_summary, run_synthesis_example
    from linkwork.viz.viewer import write_synthesis_viewer

    _heading("3. Shape-change synthesis: a morphing wing (Shamsudin et al. 2013)")
    folder = out / "synthesis-wing"
    result = run_synthesis_example(folder, "wing", plots=plots)
    write_synthesis_viewer(result, folder / "viewer.html")
    print_synthesis_summary(result)
    return Section(
        "Morphing wing synthesis",
        "A chain of rigid links that approximates three wing profiles of different arc length.",
        folder,
        sorted(p.name for p in folder.glob("*.png")),
    )


def _mechanized_wing(out: Path, plots: bool) -> Section:
    """Part 4: the wing chain mechanized to one degree of freedom and verified by tracing."""
    from linkwork.io.readback import read_chain, read_mechanization
    from linkwork.outputs.synthesis import run_synthesis_example

    _heading("4. Mechanization: the wing chain brought to one degree of freedom (Sec. 7)")
    folder = out / "mechanism-wing"
    run_synthesis_example(folder, "wing", plots=plots, file="mechanize.toml")
    report = read_mechanization(folder / "mechanization.json")
    design = read_chain(folder / "chain.json")["design"]
    errors = ", ".join(f"{p['e_max']:.4f}" for p in report["profiles"])
    text = (
        f"The wing chain (design {design}) with binary links added by rigid-body "
        f"guidance: DOF {report['dof']}, drive {report['drive']}, verified by tracing it through every "
        f"profile in order (no circuit, branch or order defect); E_max per profile {errors}. "
        "mechanism.toml runs with linkwork trace as it is."
    )
    console.print(text)
    figures = sorted(p.name for p in folder.glob("mechanism*.png")) + sorted(
        p.name for p in folder.glob("mechanism*.gif")
    )
    return Section("Mechanized wing (one degree of freedom)", text, folder, figures)


#: What each section's interactive viewer lets a reader do.
VIEWER_HINTS = {
    "hexagon": "drag the slider from the folded bundle to the flat hexagon",
    "guest-frame": "follow branch 0 to a bifurcation point, then take another branch from the panel",
    "synthesis-wing": "slide across the three wing profiles",
}


def _write_index(out: Path, sections: list[Section]) -> None:
    """A plain, self-contained index.html linking every file written, each interactive viewer first."""
    parts = [
        "<!doctype html><html><head><meta charset='utf-8'><title>linkwork demo</title>",
        "<style>body{font-family:sans-serif;max-width:1000px;margin:2em auto;padding:0 1em}"
        "img,video{max-width:100%;border:1px solid #ddd;margin:.5em 0}"
        ".viewer{display:inline-block;background:#1f5f9e;color:#fff;padding:.4em .9em;border-radius:4px;"
        "text-decoration:none;font-weight:600}</style></head><body>",
        "<h1>linkwork demo</h1>",
    ]
    for title, text, folder, figures in sections:
        rel = folder.relative_to(out)
        files = sorted(p.name for p in folder.iterdir() if p.is_file())
        parts.append(f"<h2>{html_text(title)}</h2><p>{html_text(text)}</p>")
        if (folder / "viewer.html").is_file():
            hint = VIEWER_HINTS.get(str(rel), "drag the slider along the path")
            parts.append(
                f"<p><a class='viewer' href='{rel}/viewer.html'>Open the interactive viewer</a> "
                f"&nbsp;{html_text(hint)}.</p>"
            )
        parts.append("<p>files: ")
        parts.append(", ".join(f"<a href='{rel}/{html_text(f)}'>{html_text(f)}</a>" for f in files))
        parts.append("</p>")
        for fig in figures:
            if fig.endswith(".html") or (fig.endswith(".mp4") and fig[:-4] + ".gif" in figures):
                continue  # the viewer has its own button; an MP4 next to its GIF is linked under "files"
            src = f"{rel}/{html_text(fig)}"
            if fig.endswith(".mp4"):
                parts.append(f"<video src='{src}' controls loop muted></video>")
            else:
                parts.append(f"<img src='{src}' alt='{html_text(fig)}'>")
    parts.append("</body></html>")
    (out / "index.html").write_text("\n".join(parts))

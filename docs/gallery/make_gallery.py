"""Reproduce the papers' figures: ``python docs/gallery/make_gallery.py`` (writes the PNGs next to this file).

Gan & Pellegrino (2006): Figs. 9-13, 15, 16, and Sec. 7's membrane remark. Shamsudin et al. (2013): Figs. 3, 6, 7, 8, 10, 13 (via 8 and 10), 14 (seat example).
Needs the ``viz`` extra (matplotlib, pillow). Takes about 20 s.
"""

from __future__ import annotations

import shutil
import sys
import tempfile
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np

from linkwork.data import example
from linkwork.kinematics.tracer import trace
from linkwork.linkages import hedgepeth_rods
from linkwork.linkages.guest import guest_frame
from linkwork.linkages.hedgepeth_rods import deployed_angles
from linkwork.viz.snapshots import deployment_sequence
from linkwork.viz.trace_plots import plot_angles, plot_singular_values

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]


def eq13_theta_b(theta_a: np.ndarray) -> np.ndarray:
    """Eq. (13) in the sense in which the hoop deploys: theta_B of the symmetric square, radians.

    The printed matrices turn the hinges the other way (the square is flat at their theta_A = -120 deg), so the
    deploying branch is ``-Eq13(-theta_A)``; Eq. (13) is an arctan (theta_B modulo 180 deg), unwrapped here to
    the branch that starts at 0 in the bundle.
    """
    c, s = np.cos(-theta_a), np.sin(-theta_a)
    r3 = np.sqrt(3.0)
    num = 2 * r3 * c**2 - 3 * s * c + 3 * s - 4 * r3 * c + 2 * r3
    den = -(c**2) - 2 * r3 * s * c + 2 * r3 * s - c + 2
    return -np.unwrap(2.0 * np.arctan(num / den)) / 2.0


def fig09(out: Path) -> Path:
    """theta_A against theta_B of the symmetric square: traced (couplings A = C, B = D) and Eq. (13)."""
    import matplotlib.pyplot as plt

    deployed = deployed_angles(4)[0]
    path = trace(hedgepeth_rods(4, couple=True), until=("A", deployed), steps=200)
    a, b = np.degrees(path.angles[:, 0]), np.degrees(path.angles[:, 1])
    fine = np.linspace(1e-6, deployed, 400)
    fig, ax = plt.subplots(figsize=(5.0, 4.0), layout="constrained")
    ax.plot(np.degrees(fine), np.degrees(eq13_theta_b(fine)), "-", color="0.6", lw=4, label="Eq. (13)")
    ax.plot(a[::8], b[::8], "o", ms=3.5, color="C0", label="traced, 200 steps")
    ax.set_xlabel("θA (deg)")
    ax.set_ylabel("θB (deg)")
    ax.set_title("Hedgepeth square, symmetric (θA = θC, θB = θD)", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.savefig(out, dpi=100)
    plt.close(fig)
    gap = np.max(np.abs(np.degrees(eq13_theta_b(path.angles[1:, 0])) - b[1:]))
    print(f"  Fig. 9: largest |theta_B - Eq. (13)| along the path = {gap:.2e} deg")
    return out


def line_plot(plot, path, out: Path, **kwargs) -> Path:
    """Call a trace_plots function (which also writes an SVG) and keep only the PNG."""
    plot(path, out, **kwargs)
    out.with_suffix(".svg").unlink(missing_ok=True)
    return out


def hexagon_stretch(hexagon, out: Path) -> Path:
    """Sec. 7: the membrane a deployed hexagon would carry must stretch on the way (docs/deployment.md)."""
    from linkwork.viz.deployment_plots import stretch_figure

    stretch_figure(hexagon).savefig(out, dpi=80)
    return out


def main() -> None:
    started = time.perf_counter()
    written = [fig09(HERE / "fig09_square_symmetric.png")]

    # The hoops as built from their rods (docs/linkages.md: the printed Sec. 3 rods do not open flat for n >= 6).
    square = trace(hedgepeth_rods(4), until=("A", deployed_angles(4)[0]), steps=200)  # no symmetry assumed
    written.append(line_plot(plot_angles, square, HERE / "fig10_square_angles.png"))
    written.append(deployment_sequence(square, HERE / "fig11_square_sequence.png", dpi=80))

    hexagon = trace(hedgepeth_rods(6), until=("A", deployed_angles(6)[0]), steps=200)
    written.append(line_plot(plot_angles, hexagon, HERE / "fig12_hexagon_angles.png"))
    written.append(deployment_sequence(hexagon, HERE / "fig13_hexagon_sequence.png", dpi=80))
    written.append(hexagon_stretch(hexagon, HERE / "sec7_hexagon_stretch.png"))

    frame = trace(guest_frame(), branches=True, max_steps=6000)
    written.append(line_plot(plot_singular_values, frame, HERE / "fig15_guest_singular_values.png", branch=0))
    # Branch 1 leaves the first bifurcation point of branch 0: the symmetry-breaking path.
    written.append(deployment_sequence(frame, HERE / "fig16_guest_symmetry_breaking.png", branch=1, dpi=80))

    from linkwork.io.problem import load_problem
    from linkwork.synthesis import synthesize
    from linkwork.viz.synthesis_plots import write_synthesis_figures

    result = synthesize(load_problem(example("seat")))
    names = {
        "profiles": "synth_fig03_profiles.png",
        "m_segment": "synth_fig06_m_segment.png",
        "c_segment": "synth_fig07_c_segment.png",
        "chain": "synth_fig08_chain.png",
        "compound": "synth_fig10_compound.png",
    }
    with tempfile.TemporaryDirectory() as tmp:
        for file in write_synthesis_figures(result, tmp):
            if file.suffix == ".png" and file.stem in names:
                written.append(Path(shutil.copy(file, HERE / names[file.stem])))
    # Fig. 14: the seat chain mechanized to one degree of freedom (seat/mechanize.toml).
    from linkwork.outputs.mechanization import mechanize_into

    seat = synthesize(load_problem(example("seat", "mechanize.toml")))
    with tempfile.TemporaryDirectory() as tmp:
        mechanize_into(seat, Path(tmp), plots=True)
        written.append(
            Path(shutil.copy(Path(tmp) / "mechanism.png", HERE / "synth_fig14_seat_mechanism.png"))
        )
    for file in written:
        print(f"  {file.name}: {file.stat().st_size / 1024:.0f} kB")
    print(f"{len(written)} figures in {time.perf_counter() - started:.1f} s")


if __name__ == "__main__":
    sys.exit(main())

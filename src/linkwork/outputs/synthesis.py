"""The files of a synthesised chain (chain.json, target_profiles.csv, outline.svg/.dxf, figures), its printed
summary, a bundled example run end to end, and a ``linkwork synth`` output folder read back.

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Mech. Mach. Theory (2013), Eq. (34).
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from rich.text import Text

from linkwork.data import example
from linkwork.errors import SpecError
from linkwork.io.toml_reader import show
from linkwork.outputs.staging import console, have_matplotlib, staged_output

if TYPE_CHECKING:
    from rich.table import Table

    from linkwork.synthesis.problem import Problem
    from linkwork.synthesis.result import SynthesisResult


def write_synthesis_outputs(result: SynthesisResult, folder: Path, *, plots: bool = True) -> list[Path]:
    """Write every output file of a synthesis result into ``folder`` and return their paths.

    ``chain.json`` (the contract of ``result.to_dict()``), ``target_profiles.csv``, ``outline.svg``,
    ``outline.dxf`` and, when ``plots``, the figures of
    :func:`linkwork.viz.synthesis_plots.write_synthesis_figures`.
    """
    from linkwork.io.profiles import write_outline_dxf, write_outline_svg
    from linkwork.io.writer import require_finite
    from linkwork.synthesis import write_target_profiles_csv

    folder.mkdir(parents=True, exist_ok=True)
    chain = folder / "chain.json"
    chain.write_text(json.dumps(result.to_dict(), indent=2, allow_nan=False) + "\n", encoding="utf-8")
    targets = folder / "target_profiles.csv"
    for target in result.targets:
        require_finite(target.points, f"target profile {show(target.name)}: its points")
    write_target_profiles_csv(result.targets, targets)
    write_outline_svg(folder / "outline.svg", result)
    write_outline_dxf(folder / "outline.dxf", result)
    written = [chain, targets, folder / "outline.svg", folder / "outline.dxf"]
    if plots:
        from linkwork.viz.synthesis_plots import write_synthesis_figures

        written += write_synthesis_figures(result, folder)
    return written


def run_synthesis_example(
    out_dir: Path, name: str = "wing", *, plots: bool = True, file: str = "problem.toml"
) -> SynthesisResult:
    """Run a bundled synthesis example and write its inputs and outputs into ``out_dir``.

    ``out_dir/problem/`` receives a copy of the example's problem file and profiles (so ``linkwork synth
    out_dir/problem/problem.toml`` runs it again); ``out_dir`` receives the files of
    :func:`write_synthesis_outputs`. Nothing is printed.

    Parameters
    ----------
    out_dir
        Folder to write into (created if needed).
    name
        One of :data:`linkwork.data.EXAMPLES`.
    plots
        Draw the figures (skipped anyway when matplotlib is not installed).
    file
        The example's problem file; ``mechanize.toml`` also mechanizes the chain (mechanism.toml,
        mechanization.json, figures).
    """
    from linkwork.io.problem import load_problem
    from linkwork.synthesis import synthesize

    problem_file = example(name, file)
    problem = load_problem(problem_file)
    result = synthesize(problem)
    with staged_output(Path(out_dir)) as stage:
        shutil.copytree(problem_file.parent, stage / "problem")
        write_synthesis_outputs(result, stage, plots=plots and have_matplotlib())
        if problem.mechanize:
            from linkwork.outputs.mechanization import mechanize_into

            mechanize_into(result, stage, plots=plots and have_matplotlib())
    return result


def load_synthesis(folder: Path, problem: Path | None = None) -> SynthesisResult:
    """The synthesis result of a ``linkwork synth`` output folder, checked against its ``chain.json``.

    Raises
    ------
    SpecError
        When ``chain.json`` or the problem file is missing, or the problem no longer gives the same chain.
    """
    return rerun_synthesis(folder, synthesis_problem(folder, problem))


def synthesis_problem(folder: Path, problem: Path | None = None) -> Problem:
    """The problem a ``linkwork synth`` output folder came from (``folder/problem/problem.toml`` unless
    ``problem`` is given), read without running the synthesis; the folder must hold a valid ``chain.json``."""
    from linkwork.io.problem import load_problem

    if not (folder / "chain.json").is_file():
        raise SpecError(f"{folder}: no chain.json; expected a `linkwork synth` output folder")
    _read_chain_json(folder / "chain.json")  # a broken chain.json is named before the problem is read
    problem = problem or folder / "problem" / "problem.toml"
    if not problem.is_file():
        raise SpecError(
            f"{folder}: no problem file at {problem}; pass the problem the chain came from with --problem"
        )
    return load_problem(problem)


def rerun_synthesis(folder: Path, spec: Problem) -> SynthesisResult:
    """Run the (seeded) synthesis of ``spec`` again and check that it gives the chain of ``folder/chain.json``."""
    from linkwork.synthesis import synthesize

    chain_file = folder / "chain.json"
    design, e_max = _read_chain_json(chain_file)
    result = synthesize(spec)
    same = design == result.design and math.isclose(e_max, result.joined_e_max, rel_tol=1e-9, abs_tol=1e-12)
    if not same:
        if design != result.design:
            differs = f"design {show(design)}, where it gives design {show(result.design)}"
        else:
            differs = (
                f"design {show(design)} with joined E_max {e_max:.6g}, where it gives E_max "
                f"{result.joined_e_max:.6g} on its {len(result.joined)} profile(s)"
            )
        raise SpecError(
            f"{chain_file}: the chain is not what {spec.source} gives now ({differs}); run `linkwork synth` again"
        )
    return result


def _read_chain_json(chain_file: Path) -> tuple[str, float]:
    """``(design, joined E_max)`` of a ``chain.json``, read through its schema
    (:data:`linkwork.io.readback.SCHEMAS`): anything else than the contract, or the chain of a search that was
    stopped early (``"complete": false``, which the seeded synthesis run again would not give), is a
    :class:`SpecError`."""
    from linkwork.io.readback import read_chain

    saved = read_chain(chain_file)
    if saved.get("complete") is False:
        raise SpecError(
            f"{chain_file}: is the chain of a design search stopped early ({saved.get('stopped') or 'interrupted'}"
            '; "complete": false); run `linkwork synth` again to its end before mechanizing'
        )
    return saved["design"], float(saved["joined"]["e_max"])


def _table(title: str) -> Table:
    from rich.table import Table

    return Table(title=title, title_justify="left", title_style="bold")


def _matrix_table(title: str, result: SynthesisResult, cells: np.ndarray, fmt: str) -> Table:
    """A ``(q, p)`` matrix printed as the paper prints it: one row per profile, one column per segment."""
    table = _table(title)
    table.add_column("profile")
    for e, kind in enumerate(result.design):
        table.add_column(f"{e + 1} {kind}", justify="right")
    for j, target in enumerate(result.targets):
        table.add_row(
            target.name or str(j + 1), *(format(cells[e, j], fmt) for e in range(len(result.design)))
        )
    return table


def print_synthesis_summary(result: SynthesisResult) -> None:
    """Print the profiles, the design, the segment and error matrices and the compound merges."""
    _print_profiles_and_design(result)
    console.print(_matrix_table("Segment matrix (pieces)", result, result.segment_matrix, "d"))
    console.print(_matrix_table("Error matrix after segmentation", result, result.error_matrix, ".4f"))
    console.print(_matrix_table("Error matrix after joining", result, result.joined_error_matrix, ".4f"))
    _print_errors(result)
    _print_compound(result)


def _print_profiles_and_design(result: SynthesisResult) -> None:
    """The profiles' table, the design vector and how the search found it (with the designs it skipped)."""
    profiles = _table("Profiles")
    for column in ("profile", "arc length C", "pieces m", "target length s", "S / C"):
        profiles.add_column(column, justify="left" if column == "profile" else "right")
    for j, target in enumerate(result.targets):
        profiles.add_row(
            target.name or str(j + 1),
            f"{target.arc_length:.4f}",
            str(target.pieces),
            f"{target.target_length:.4f}",
            f"{target.length / target.arc_length:.4f}",
        )
    console.print(profiles)
    problem = result.problem
    searched = "given" if problem.design else f"best of every design vector of {problem.segments} segments"
    console.print(
        Text("design", style="bold"),
        f"{result.design} ({searched}); {problem.kind} profiles, piece length "
        f"{problem.piece_length:g}, at least {problem.min_pieces} pieces per segment; "
        f"{result.stats.starts} starts, {result.stats.seconds:.2f} s",
        highlight=False,
    )
    stats = result.stats
    if stats.stopped:
        console.print(
            f"search stopped early ({stats.stopped}): {stats.designs_tried} of "
            f"{stats.designs_tried + stats.not_searched} design vectors searched, {stats.not_joined} of them not "
            "joined; the design is the best joined so far",
            highlight=False,
        )
    if not problem.design:
        joined = stats.designs_tried - len(stats.skipped) - stats.pruned - stats.not_joined
        console.print(
            f"search: {stats.designs_tried} design vectors, {joined} "
            f"joined, {stats.pruned} pruned (their lower bound on E_max exceeds the best), "
            f"{len(stats.skipped)} skipped (cannot be joined); ranked by {stats.rank_by}"
            + ("" if stats.e_max_tolerance is None else f" (E_max tolerance {stats.e_max_tolerance:g})"),
            highlight=False,
        )
    for design, reason in stats.skipped[:5]:
        console.print(f"skipped {design}: {reason}", highlight=False, markup=False)
    if len(stats.skipped) > 5:
        console.print(f"... and {len(stats.skipped) - 5} more skipped (see chain.json search.skipped)")


def _print_errors(result: SynthesisResult) -> None:
    """E_max and E_mean after segmentation, after joining and with compound segments."""
    compound = result.compound
    errors = _table("Errors")
    for column in ("stage", "E_max", "E_mean"):
        errors.add_column(column, justify="left" if column == "stage" else "right")
    errors.add_row("segmentation", f"{result.e_max:.4f}", f"{result.e_mean:.4f}")
    errors.add_row(
        "joined", f"{result.joined_e_max:.4f}", f"{float(np.mean(result.joined_error_matrix)):.4f}"
    )
    if compound is not None and compound.merged:
        errors.add_row("compound", f"{compound.e_max:.4f}", f"{float(np.mean(compound.error_matrix)):.4f}")
    console.print(errors)


def _print_compound(result: SynthesisResult) -> None:
    """The joints' ranges of motion (Eq. 34) and which were merged into compound segments."""
    compound = result.compound
    if compound is None:
        console.print("compound segments: off (merge_below = 0)")
        return
    joints = _table(
        f"Joint ranges, Eq. 34 (merge below {math.degrees(compound.threshold):.3g} deg, "
        f"on the {compound.merge_on})"
    )
    for column in ("joint", "between", "on targets (deg)", "on chain (deg)", "merged"):
        joints.add_column(column, justify="right" if "deg" in column else "left")
    on_targets = compound.target_ranges if compound.target_ranges is not None else compound.joint_ranges
    for i, motion in enumerate(compound.joint_ranges):
        between = f"{i + 1} {result.design[i]} - {i + 2} {result.design[i + 1]}"
        joints.add_row(
            str(i + 1),
            between,
            f"{math.degrees(on_targets[i]):.2f}",
            f"{math.degrees(motion):.2f}",
            "yes" if i in compound.merged else "",
        )
    console.print(joints)
    for note in compound.notes:
        console.print(f"note: {note}", highlight=False)

"""The tour notebook (docs/notebooks/tour.ipynb) runs from top to bottom in a fresh kernel, as a reader would run
it, and shows what it promises: short printed summaries, figures as images, the viewer inline."""

from __future__ import annotations

import re
from pathlib import Path

import nbclient
import nbformat
import pytest

TOUR = Path(__file__).resolve().parents[2] / "docs" / "notebooks" / "tour.ipynb"


@pytest.fixture(scope="module")
def executed() -> nbformat.NotebookNode:
    notebook = nbformat.read(TOUR, as_version=4)
    client = nbclient.NotebookClient(
        notebook, timeout=240, kernel_name="python3", resources={"metadata": {"path": str(TOUR.parent)}}
    )
    client.execute()  # raises CellExecutionError on the first failing cell
    return notebook


def _outputs(notebook: nbformat.NotebookNode, source_start: str, *, whole: bool = False) -> list[dict]:
    """Outputs of the one code cell whose source starts with (or, ``whole``, is) ``source_start``."""
    cells = [
        c
        for c in notebook.cells
        if c.cell_type == "code"
        and (c.source.strip() == source_start if whole else c.source.startswith(source_start))
    ]
    assert len(cells) == 1, f"expected one cell starting with {source_start!r}"
    return list(cells[0].outputs)


def _text(outputs: list[dict]) -> str:
    return "".join(o.get("text", "") for o in outputs if o["output_type"] == "stream")


@pytest.mark.slow
def test_tour_runs_and_shows_figures_and_viewers(executed: nbformat.NotebookNode) -> None:
    for cell in executed.cells:
        if cell.cell_type == "code":
            assert not [o for o in cell.outputs if o["output_type"] == "error"]
    # The last expression of a cell shows the viewer inline: an iframe holding the whole offline page.
    for name in ("hoop", "frame", "wing"):
        (result,) = _outputs(executed, name, whole=True)
        html = result["data"]["text/html"]
        assert html.startswith("<iframe srcdoc=") and "&lt;script" in html and "<script" not in html
        assert len(result["data"]["text/plain"].splitlines()) < 10
    for start in (
        "hoop.plot()",
        'frame.plot("singular_values")',
        'wing.plot("chain")',
        'wing.plot("errors")',
    ):
        (figure,) = _outputs(executed, start)
        assert "image/png" in figure["data"]


@pytest.mark.slow
def test_tour_numbers(executed: nbformat.NotebookNode) -> None:
    # Rods are rigid: the hinge-to-hinge distance along each rod is constant along the motion (round-off).
    text = _text(_outputs(executed, "xyz = hoop.positions()"))
    assert "positions: (234, 6, 3)" in text
    change = float(re.search(r"along the path: (\S+)", text).group(1))  # type: ignore[union-attr]
    assert change < 1e-12
    # The flat regular hexagon: all six hinges equally far from its centre (printed to 9 decimals).
    distances = re.search(r"distances from the centre: \[([^\]]+)\]", text).group(1).split()  # type: ignore[union-attr]
    assert len(set(distances)) == 1
    # The mechanized wing passes its verification with one degree of freedom.
    assert "passed: True, DOF 1" in _text(_outputs(executed, "from linkwork.mechanization import mechanize"))

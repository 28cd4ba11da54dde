"""The one name policy (:mod:`linkwork.names`) over hostile generated names and every built-in, checked by outside
parsers: the csv module reads every joint's values back from path.csv and sweep-style columns, xml.etree parses
MJCF, 3MF and SVG, MuJoCo loads the MJCF, trimesh loads the STL and 3MF, ezdxf reads the DXF layers, matplotlib
draws the names, and the HTML escape leaves no markup."""

from __future__ import annotations

import csv
import re
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import linkwork as lw
from linkwork.export.mjcf import mjcf, mjcf_names
from linkwork.export.solids import part_labels, part_names, parts, write_3mf, write_stl
from linkwork.io.drawing import svg_document, svg_path
from linkwork.io.readback import PATH_FIXED, path_columns
from linkwork.io.results import write_path_csv
from linkwork.kinematics.mechanism import Mechanism
from linkwork.linkages.registry import REGISTRY
from linkwork.names import (
    COLUMN_PREFIX,
    FORMULA_START,
    MJCF_RESERVED,
    csv_columns,
    describe,
    dxf_layers,
    html_text,
    mathtext,
    stl_names,
    xml_names,
)
from linkwork.studies.sweep import SWEEP_FIXED, joint_columns

mujoco = pytest.importorskip("mujoco")
trimesh = pytest.importorskip("trimesh")
ezdxf = pytest.importorskip("ezdxf")
pytest.importorskip("networkx")  # trimesh's 3MF reader

SOME = settings(max_examples=25, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))

RESERVED_WORDS = ["step", "branch", "s", "residual", "sigma_1", "sigma_12", "ratio", "mobility", "points",
                  "world", "joint:step", "transmission", "e", "misfit", "error", "ground"]  # fmt: skip
HOSTILE = ["a\nb", "<&\"'>", "x\x00y", "\x1b[31m", "$x^$", r"\foo", "a b", "", " ", "é✓", "\ud800", "\ufffe",
           "solid", "endsolid x", "a:b;c*?", "=,|`"]  # fmt: skip
names = st.one_of(
    st.sampled_from(RESERVED_WORDS + HOSTILE),
    st.text(alphabet=st.characters(codec="utf-8") | st.sampled_from("\n\r\t\x01<&$\\ _:"), max_size=10),
)


def four_bar(joints: list[str], bodies: list[str], name: str = "four-bar") -> Mechanism:
    """The built-in four-bar's joints between bodies ``bodies`` (ground, crank, coupler, rocker) named anew."""
    base = lw.load("four-bar")
    points = [(0.0, 0.0), (0.5, 0.8660254037844386), (2.8066233575366795, 1.8301253397175437), (2.0, 0.0)]
    pairs = [(0, 1), (1, 2), (2, 3), (0, 3)]
    return Mechanism.from_joints(
        name,
        [
            {
                "name": joints[k],
                "type": "R",
                "bodies": (bodies[a], bodies[b]),
                "point": points[k],
                "direction": (0.0, 0.0, 1.0),
                "value": float(base.offsets[k]),
            }
            for k, (a, b) in enumerate(pairs)
        ],
        planar=True,
        ground=bodies[0],
    )


distinct4 = st.lists(names, min_size=4, max_size=4, unique=True)


@given(joints=distinct4, bodies=distinct4, title=names)
@SOME
def test_hostile_names_reach_every_format_intact(tmp_path_factory: pytest.TempPathFactory, joints: list[str],
                                                 bodies: list[str], title: str) -> None:  # fmt: skip
    mech = four_bar(joints, bodies, title)
    trace = lw.trace(mech, max_steps=8)
    folder = tmp_path_factory.mktemp("names")

    # path.csv: the csv module reads every joint's values back from its own column; fixed columns intact
    write_path_csv(trace, folder / "path.csv")
    with open(folder / "path.csv", newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    header = rows[0]
    assert len(set(header)) == len(header)
    columns = path_columns(mech.joint_names)
    for j, joint in enumerate(mech.joint_names):
        k = header.index(columns[joint])
        values = np.radians([float(r[k]) for r in rows[1:]])
        np.testing.assert_allclose(values, trace.angles[:, j], rtol=1e-14, atol=1e-14)
    assert [int(r[header.index("step")]) for r in rows[1:]] == trace.step.tolist()

    # MJCF: well-formed, loaded by MuJoCo, 'world' never a body of ours, every name unique
    text = mjcf(mech)
    ET.fromstring(text)
    model = mujoco.MjModel.from_xml_string(text)
    body_map, joint_map = mjcf_names(mech)
    ours = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, i) for i in range(1, model.nbody)]
    assert "world" not in ours and len(set(ours)) == len(ours)
    assert {joint_map[j] for j in mech.joint_names} <= {
        mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, i) for i in range(model.njnt)
    }
    assert set(ours) == {body_map[b] for b in body_map}

    # STL: one solid line per part, unique one-word names; trimesh reads the solids back
    meshes = parts(mech, trace.angles[0])
    write_stl(folder / "x.stl", meshes)
    lines = (folder / "x.stl").read_text(encoding="ascii").splitlines()
    solids = [line.split(" ", 1)[1] for line in lines if line.startswith("solid ")]
    assert solids == part_names(meshes) and len(set(solids)) == len(solids)
    assert all(re.fullmatch(r"[A-Za-z0-9_.-]+", s) and "solid" not in s.lower() for s in solids)
    loaded = trimesh.load(folder / "x.stl", force="scene")
    assert len(loaded.geometry) == len(meshes)

    # 3MF: the model XML parses, trimesh loads every object
    write_3mf(folder / "x.3mf", meshes)
    with zipfile.ZipFile(folder / "x.3mf") as zf:
        root = ET.fromstring(zf.read("3D/3dmodel.model"))
    assert len(root.findall(".//{*}object")) == len(meshes)
    assert len(trimesh.load(folder / "x.3mf", force="scene").geometry) == len(meshes)

    # SVG: a title per joint name parses back to the (XML-allowed) name
    svg = svg_document(
        [svg_path("M 0,0 L 1,1", "#000", label=j) for j in joints], [np.zeros((2, 2)), np.ones((2, 2))]
    )
    ET.fromstring(svg.encode("utf-8"))


@given(layers=st.lists(names, min_size=1, max_size=6))
@SOME
def test_dxf_layers_are_readable_by_ezdxf(
    tmp_path_factory: pytest.TempPathFactory, layers: list[str]
) -> None:
    mapped = dxf_layers(layers, taken=["0", "links"])
    written = [mapped[n] for n in dict.fromkeys(layers)]
    assert len({w.lower() for w in written}) == len(written)  # DXF layer names ignore case
    doc = ezdxf.new("R2010")
    for w in written:
        doc.layers.add(w)
        doc.modelspace().add_line((0, 0), (1, 1), dxfattribs={"layer": w})
    file = tmp_path_factory.mktemp("dxf") / "x.dxf"
    doc.saveas(file)
    back = ezdxf.readfile(file)
    assert {w.lower() for w in written} <= {layer.dxf.name.lower() for layer in back.layers}


@given(text=names)
@settings(max_examples=12, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))
@pytest.mark.filterwarnings("ignore:Glyph .* missing from font")  # a box is drawn for a character no font has
def test_matplotlib_draws_any_name_as_written(text: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    try:
        ax.set_title(mathtext(text))
        ax.plot([0, 1], [0, 1], label=mathtext(text) or "x")
        ax.legend()
        fig.canvas.draw()  # a mathtext parse error would raise here
    finally:
        plt.close(fig)


@given(text=names)
@SOME
def test_html_text_leaves_no_markup(text: str) -> None:
    escaped = html_text(text)
    assert not set("<>\"'") & set(escaped)
    assert re.sub(r"&(amp|lt|gt|quot|#x27);", "", escaped).count("&") == 0


@given(joints=st.lists(names, min_size=1, max_size=8, unique=True))
@SOME
def test_csv_columns_are_one_to_one_and_avoid_fixed_columns(joints: list[str]) -> None:
    path = path_columns(joints)
    assert len(set(path.values())) == len(joints)
    for j in joints:
        col = path[j]
        assert col not in PATH_FIXED and not re.fullmatch(r"sigma_\d+", col)
        escaped = j.encode("utf-8", "backslashreplace").decode("utf-8")  # a lone surrogate: its escape
        assert col == j or col == COLUMN_PREFIX + escaped
        assert col[:1] not in FORMULA_START  # never a formula in a spreadsheet
    sweep = joint_columns(joints, grid=["twist"])
    cols = [f"{sweep[j]}{s}" for j in joints for s in ("_min", "_max")]
    assert len(set(cols)) == len(cols) and not set(cols) & {*SWEEP_FIXED, "twist"}


def test_a_joint_named_like_a_fixed_column_keeps_its_values(tmp_path: Path) -> None:
    """`step`, `branch`, `residual`, `s`, `sigma_1`: each gets its own prefixed column; the report says so."""
    mech = four_bar(["step", "branch", "residual", "sigma_1"], ["ground", "crank", "coupler", "rocker"])
    trace = lw.trace(mech, max_steps=5)
    write_path_csv(trace, tmp_path / "path.csv")
    with open(tmp_path / "path.csv", newline="") as fh:
        reader = csv.DictReader(fh)
        assert reader.fieldnames is not None
        assert reader.fieldnames[:3] == ["branch", "step", "s"]
        assert {"joint:step", "joint:branch", "joint:residual", "joint:sigma_1"} <= set(reader.fieldnames)
        first = next(reader)
    assert int(first["step"]) == 0
    assert float(first["joint:step"]) == pytest.approx(np.degrees(trace.angles[0, 0]), rel=1e-15)
    line = describe(path_columns(mech.joint_names))
    assert line is not None and '"step" written as "joint:step"' in line


def test_a_joint_named_like_a_formula_is_never_one_in_a_spreadsheet(tmp_path: Path) -> None:
    """A joint named ``=HYPERLINK(...)`` (or starting with ``+``, ``-``, ``@``): a spreadsheet opening path.csv
    would run its column name as a formula; it is written ``joint:=HYPERLINK(...)``, the report says why, and the
    column is read back (``path_columns``) with the joint's values."""
    names = ['=HYPERLINK("http://x","y")', "+1", "-A", "@SUM(A1)"]
    mech = four_bar(names, ["ground", "crank", "coupler", "rocker"])
    trace = lw.trace(mech, max_steps=5)
    write_path_csv(trace, tmp_path / "path.csv")
    with open(tmp_path / "path.csv", newline="") as fh:
        header = next(csv.reader(fh))
    assert not [c for c in header if c[:1] in FORMULA_START]
    assert {COLUMN_PREFIX + n for n in names} <= set(header)
    columns = path_columns(mech.joint_names)
    line = describe(columns)
    assert line is not None and "a spreadsheet reads as a formula" in line
    frame = np.genfromtxt(tmp_path / "path.csv", delimiter=",", names=None, skip_header=1)
    for j, name in enumerate(names):
        k = header.index(columns[name])
        np.testing.assert_allclose(frame[:, k], np.degrees(trace.angles[:, j]), rtol=1e-15)


def test_world_is_mapped_and_reported() -> None:
    mech = four_bar(["A", "B", "C", "D"], ["ground", "world", "coupler", "rocker"])
    bodies, _ = mjcf_names(mech)
    assert bodies["world"] == "world_2" and "world" in MJCF_RESERVED
    assert "MJCF body" in (describe(bodies) or "")
    assert (
        mujoco.MjModel.from_xml_string(mjcf(mech)).nbody == 1 + len(mech.bodies) + 1
    )  # world + bodies + cut


def test_two_parts_sharing_a_name_become_unique() -> None:
    """A body named `pin_A` and the pin of joint `A` share the STL label; the written names differ."""
    mech = four_bar(["A", "B", "C", "D"], ["ground", "pin_A", "coupler", "rocker"])
    meshes = parts(mech, mech.offsets)
    labels = part_labels(meshes)
    assert labels.count("pin_A") == 2
    written = part_names(meshes)
    assert len(set(written)) == len(written)
    assert stl_names(labels)[1].changes


@pytest.mark.parametrize("name", sorted(REGISTRY))
def test_every_builtin_loads_in_mujoco_and_trimesh_with_its_names_unchanged(
    name: str, tmp_path: Path
) -> None:
    mech = lw.load(name)
    model = mujoco.MjModel.from_xml_string(mjcf(mech))
    bodies, joints = mjcf_names(mech)
    assert not bodies.changes and not joints.changes
    assert model.njnt == mech.n_joints
    meshes = parts(mech, mech.offsets)
    write_stl(tmp_path / "x.stl", meshes)
    assert len(trimesh.load(tmp_path / "x.stl", force="scene").geometry) == len(meshes)
    assert part_names(meshes) == part_labels(meshes)
    assert not csv_columns("path.csv", mech.joint_names, PATH_FIXED).changes
    assert not xml_names("x", mech.bodies, MJCF_RESERVED).changes


@pytest.mark.slow
@pytest.mark.parametrize(
    ("joints", "bodies", "title"),
    [
        (["$x^$", r"\foo", "a$b", "<&>"], ["ground", "$\\frac$", "a\nb", "world"], r"$\alpha^$"),
        (["step", "s", "sigma_1", "residual"], ["ground", "pin_A", "x\x01y", "é✓"], "a\nb & <c>"),
    ],
)
def test_every_trace_figure_viewer_and_robustness_figure_draws_hostile_names(
    tmp_path: Path, joints: list[str], bodies: list[str], title: str
) -> None:
    """The figures, deployment sequence, viewer and the robustness figures of a linkage whose names mathtext
    would parse, drawn without error; the viewer's title escaped."""
    from linkwork.outputs.robustness import robustness_dict
    from linkwork.outputs.trace import write_trace_outputs
    from linkwork.studies.imperfections import ImperfectionModel
    from linkwork.studies.robustness import robustness
    from linkwork.viz.robustness_plots import write_robustness_figures

    mech = four_bar(joints, bodies, title)
    trace = lw.trace(mech, until=(joints[0], np.radians(100.0)))
    written = write_trace_outputs(trace, tmp_path / "out", plots=True, html=True)
    assert {p.name for p in written} >= {"angles.png", "sequence.png", "viewer.html"}
    page = (tmp_path / "out" / "viewer.html").read_text(encoding="utf-8")
    head = page[: page.index("</title>")]
    assert "<c>" not in head and ("&lt;c&gt;" in head) == ("<c>" in title)
    result = robustness(mech, trace, ImperfectionModel(1e-3, np.radians(0.1)), 4, seed=1, workers=0)
    summary = robustness_dict(result, title)
    figures = write_robustness_figures(result, summary, tmp_path)
    assert all(f.stat().st_size > 0 for f in figures)

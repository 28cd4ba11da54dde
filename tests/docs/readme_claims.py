"""What each README example says it shows, checked on the files it wrote (run by test_documented_commands.py
right after the command, in the folder the commands share).

A claim is keyed by a regular expression that must match exactly one README command; its check receives the
shared folder and the command's standard output and asserts the property the README's comment states, measured
on the files (trimesh for the solids, MuJoCo and pinocchio for the model, ezdxf for the drawing) or against a
closed form, never against linkwork's own numbers.
"""

from __future__ import annotations

import csv
import json
import math
import tomllib
from collections.abc import Callable
from pathlib import Path

import numpy as np

Check = Callable[[Path, str], None]

#: The flat regular hexagon of Hedgepeth's rods (hedgepeth_rods' docstring, the flat n-gon):
#: theta_A = arccos(sin^2(alpha1) / 2 - 1), alpha1 = 360/n, and theta_B = 360 - theta_A (degrees).
FLAT_A = math.degrees(math.acos(math.sin(math.radians(60.0)) ** 2 / 2.0 - 1.0))
#: The README's rounding of FLAT_A (degrees): the --until of its hexagon commands.
README_A = 128.6822


def rows(file: Path) -> tuple[list[str], np.ndarray]:
    """A CSV's header and its numeric rows."""
    with open(file, newline="") as fh:
        table = list(csv.reader(fh))
    return table[0], np.array(table[1:], dtype=float)


def column(file: Path, name: str) -> np.ndarray:
    header, data = rows(file)
    return data[:, header.index(name)]


def _linkages(folder: Path, output: str) -> None:
    from linkwork.linkages import REGISTRY

    for name in REGISTRY:
        assert name in output, f"`linkwork linkages` does not list {name}"


def _bundle_to_flat_hexagon(folder: Path, output: str) -> None:
    run = folder / "out" / "hedgepeth-rods-n=6-trace"
    header, data = rows(run / "path.csv")
    angles = data[:, [header.index(j) for j in "ABCDEF"]]
    assert np.abs(angles[0]).max() < 1e-9  # the folded bundle: every hinge angle zero
    assert abs(angles[-1, 0] - FLAT_A) < 1e-4 and abs(angles[-1, 1] - (360.0 - FLAT_A)) < 1e-3
    np.testing.assert_allclose(angles[-1, ::2], angles[-1, 0], atol=1e-6)  # A = C = E
    np.testing.assert_allclose(angles[-1, 1::2], angles[-1, 1], atol=1e-6)  # B = D = F
    assert (run / "viewer.html").is_file()


def _paper_steps(folder: Path, output: str) -> None:
    a = column(folder / "out" / "hexagon-200" / "path.csv", "A")
    assert len(a) == 201  # 200 equal steps of the drive
    np.testing.assert_allclose(np.diff(a), README_A / 200, rtol=0, atol=1e-9)


def _printed_not_flat(folder: Path, output: str) -> None:
    header, data = rows(folder / "out" / "hedgepeth-n=6-trace" / "points.csv")
    last = data[-1]
    xyz = np.array([[last[header.index(f"{j}_{c}")] for c in "xyz"] for j in "ABCDEF"])
    sigma = np.linalg.svd(xyz - xyz.mean(axis=0), compute_uv=False)
    assert sigma[2] > 0.05 * sigma[0], f"the printed n = 6 hoop ends flat: {sigma}"


def _guest_branches(folder: Path, output: str) -> None:
    report = json.loads((folder / "out" / "guest-frame-trace" / "report.json").read_text())
    assert len(report["bifurcations"]) >= 1 and len(report["branches"]) > 1


def _spec_file(folder: Path, output: str) -> None:
    import linkwork as lw

    mech = lw.load(str(folder / "my-bennett.toml"))
    assert mech.n_joints == 4 and len(mech.loops) == 1


def _spec_file_traced(folder: Path, output: str) -> None:
    assert (folder / "out" / "my-bennett-trace" / "path.csv").is_file()


def _coupler_curve(folder: Path, output: str) -> None:
    run = folder / "out" / "four-bar-trace"
    a = column(run / "path.csv", "A")
    assert abs(a[0] + 360.0 - a[-1]) < 1e-6  # one whole turn of the crank A
    x, y = column(run / "points.csv", "P_x"), column(run / "points.csv", "P_y")
    assert math.hypot(x[-1] - x[0], y[-1] - y[0]) < 1e-9  # so the coupler curve of P closes
    assert np.ptp(x) > 0.1 and np.ptp(y) > 0.1


def _flat_hexagon_solids(folder: Path, output: str) -> None:
    """The 3MF holds the flat hexagon: every part a closed solid, all of them side by side in one plane (the
    whole no thicker than one rod's section), spanning a hexagon of side 100 mm (--scale 100, unit rods)."""
    import trimesh

    scene = trimesh.load(folder / "hexagon.3mf")
    parts = list(scene.dump()) if isinstance(scene, trimesh.Scene) else [scene]
    assert len(parts) == 12  # six rods, six pins
    assert all(p.is_watertight and p.volume > 0 for p in parts)
    vertices = np.vstack([p.vertices for p in parts])
    centred = vertices - vertices.mean(axis=0)
    _, _, axes = np.linalg.svd(centred, full_matrices=False)
    normal = axes[2]
    thickness = np.ptp(centred @ normal)
    rod = max(np.ptp(p.vertices @ normal) for p in parts)
    assert thickness < 1.1 * rod, f"{thickness:.1f} mm thick: more than one rod section ({rod:.1f} mm)"
    span = sorted(np.ptp(centred @ axes[k]) for k in range(2))
    assert 2 * 100 * math.cos(math.radians(30)) <= span[0] and 200.0 <= span[1] <= 260.0, span
    assert thickness < 0.15 * span[0]


def _mjcf_four_bar(folder: Path, output: str) -> None:
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(folder / "four-bar.xml"))
    assert sorted(model.joint(k).name for k in range(model.njnt)) == ["A", "B", "C", "D"]
    welds = [k for k in range(model.neq) if model.eq_type[k] == mujoco.mjtEq.mjEQ_WELD]
    assert len(welds) == 1
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert np.abs(data.efc_pos[data.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY]).max() < 1e-9
    import pinocchio as pin

    pmodel, _, welds_pin = pin.buildModelAndConstraintsFromMJCF(str(folder / "four-bar.xml"))
    assert {"A", "B", "C", "D"} <= set(pmodel.names) and len(welds_pin) == 1
    pdata = pmodel.createData()
    pin.forwardKinematics(pmodel, pdata, pmodel.referenceConfigurations["qpos0"])
    weld = welds_pin[0]
    oMc1 = pdata.oMi[weld.joint1_id] * weld.joint1_placement
    oMc2 = pdata.oMi[weld.joint2_id] * weld.joint2_placement
    assert np.linalg.norm(pin.log6(oMc1.inverse() * oMc2).vector) < 1e-9  # closed at the start, as in MuJoCo


def _dxf_four_bar(folder: Path, output: str) -> None:
    import ezdxf

    doc = ezdxf.readfile(folder / "four-bar.dxf")
    assert doc.header["$INSUNITS"] == 4  # millimetres
    layers = {e.dxf.layer for e in doc.modelspace()}
    assert {"links", "pivots"} <= layers
    assert len(doc.modelspace().query('CIRCLE[layer=="pivots"]')) == 4  # a pivot on every joint


def _wing(folder: Path, output: str) -> None:
    run = folder / "out" / "wing-synth"
    for name in ("chain.json", "target_profiles.csv", "outline.svg", "outline.dxf"):
        assert (run / name).is_file(), name
    chain = json.loads((run / "chain.json").read_text())
    assert len(chain["profiles"]) == 3


def _mechanized(folder: Path, output: str) -> None:
    run = folder / "out" / "wing-mech"
    spec = tomllib.loads((run / "mechanism.toml").read_text())
    assert "mechanism" in spec
    assert json.loads((run / "mechanization.json").read_text())["dof"] == 1


def _mechanism_traced(folder: Path, output: str) -> None:
    d1a = column(folder / "out" / "check" / "path.csv", "D1a")
    assert abs(d1a[-1] - 24.33117) < 1e-6


def _short_links(folder: Path, output: str) -> None:
    report = json.loads((folder / "out" / "wing-short" / "mechanization.json").read_text())
    links = report.get("dyads") or report.get("binary_links") or []
    assert links and all(link["length"] <= 1.0 + 1e-9 for link in links)  # the cruise profile's chord is 1


def _robustness(folder: Path, output: str) -> None:
    summary = json.loads((folder / "out" / "hedgepeth-rods-n=6-robustness" / "robustness.json").read_text())
    assert summary["samples"] == 2000
    assert summary["misfit_max"]["p50"] <= summary["misfit_max"]["p95"] <= summary["misfit_max"]["max"]


def _sweep(folder: Path, output: str) -> None:
    study = tomllib.loads((folder / "examples" / "studies" / "bennett-twists.toml").read_text())
    expected = 1
    for values in study["grid"].values():
        expected *= values["count"] if isinstance(values, dict) else len(values)
    with open(folder / "out" / "bennett-twists-sweep" / "sweep.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert len(table) == expected  # one row per grid point
    assert all(not row.get("error") for row in table)


def _search(folder: Path, output: str) -> None:
    study = tomllib.loads((folder / "examples" / "studies" / "rect-frame-search.toml").read_text())
    out = folder / "out" / "rect-frame-search"
    with open(out / "candidates.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert len(table) == math.prod(len(v) for v in study["grid"].values())  # one row per candidate
    limits = study["criteria"]
    with open(out / "ranked.csv", newline="") as fh:
        ranked = list(csv.DictReader(fh))
    assert ranked  # some frames deploy with one degree of freedom and no bifurcation
    for row in ranked:  # every ranked frame meets the study's criteria as written in the file
        assert row["mobility_start"] == row["mobility_max"] == str(limits["mobility"])
        assert int(row["bifurcations_on_path"]) <= limits["max_bifurcations"]
        assert float(row["membrane_stretch"]) <= limits["max_membrane_stretch"]
        assert float(row["bundle_ratio"]) <= limits["max_bundle_ratio"]
        assert f"viewers/candidate-{int(row['index']):05d}.html" in (out / "gallery.html").read_text()
    guest = [r for r in table if r["cuts"] == "EW" and r["faces"] == "auto"]
    assert guest and all(r["mobility_max"] == "2" and r["passes"] == "False" for r in guest)  # G&P Sec. 6


def _compiled(folder: Path, output: str) -> None:
    from linkwork.kernel_cache import CACHE, GROUPS

    assert all(CACHE.ready(group) for group in GROUPS)  # the marker lists every group of kernels as compiled


#: README command pattern -> the check of what its comment (or the sentence after it) says it shows.
CLAIMS: dict[str, Check] = {
    r"^linkwork linkages$": _linkages,
    r"^linkwork trace hedgepeth-rods --set n=6 --until A=128\.6822 --html$": _bundle_to_flat_hexagon,
    r"--steps 200 -o out/hexagon-200$": _paper_steps,
    r"^linkwork trace hedgepeth --set n=6 --until A=87\.0067$": _printed_not_flat,
    r"^linkwork trace guest-frame --branches$": _guest_branches,
    r"^linkwork show bennett > my-bennett\.toml$": _spec_file,
    r"^linkwork trace my-bennett\.toml$": _spec_file_traced,
    r"^linkwork trace four-bar --drive A --until A=420$": _coupler_curve,
    r"^linkwork export stl .* -o hexagon\.3mf$": _flat_hexagon_solids,
    r"^linkwork export mjcf .* -o four-bar\.xml$": _mjcf_four_bar,
    r"^linkwork export dxf .* -o four-bar\.dxf$": _dxf_four_bar,
    r"^linkwork synth wing$": _wing,
    r"^linkwork synth wing/mechanize\.toml": _mechanized,
    r"^linkwork trace out/wing-mech/mechanism\.toml": _mechanism_traced,
    r"^linkwork mechanize out/wing-mech .*-o out/wing-short$": _short_links,
    r"^linkwork search examples/studies/rect-frame-search\.toml -o out/rect-frame-search$": _search,
    r"^linkwork compile$": _compiled,
    r"^linkwork robustness hedgepeth-rods": _robustness,
    r"^linkwork sweep examples/studies/bennett-twists\.toml$": _sweep,
}

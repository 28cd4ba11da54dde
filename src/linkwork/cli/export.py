"""``linkwork export``: a traced mechanism as solids to print (STL, 3MF), as a MuJoCo model (MJCF), as a DXF
drawing of its links and pivots (planar mechanisms)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from linkwork.cli import help
from linkwork.cli import options as opt
from linkwork.cli.common import check_word, friendly_errors, parse_assignments
from linkwork.outputs.staging import check_output_file, console

if TYPE_CHECKING:
    from linkwork.kinematics.mechanism import Mechanism
    from linkwork.names import NameMap

app = typer.Typer(
    cls=help.Group,
    help="Export a mechanism: solids to 3-D print (stl, 3mf), a MuJoCo model (mjcf), a DXF drawing (dxf).",
    no_args_is_help=True,
)

Out = Annotated[Path, typer.Option("--out", "-o", help="The file to write.", show_default=False)]
Branch = Annotated[int, typer.Option("--branch", help="Branch of the trace (see report.json).")]
Point = Annotated[
    int, typer.Option("--point", help="Point (step) on that branch; negative counts from its end.")
]


@app.command("stl", cls=help.Command)
@friendly_errors
def stl(
    trace_dir: Annotated[Path, typer.Argument(help="A folder written by `linkwork trace --out`.")],
    out: Out,
    branch: Branch = 0,
    point: Point = 0,
    scale: Annotated[
        float, typer.Option("--scale", help="Multiply every length (e.g. to millimetres).")
    ] = 1.0,
) -> None:
    """Every part of a traced mechanism at one point as a separate closed solid (STL, or 3MF by suffix).

    Parts are the links or rods and a pin on every joint; an STL has one `solid` per part, a 3MF one object."""
    from linkwork.errors import SpecError
    from linkwork.export.files import write_whole
    from linkwork.export.solids import parts, renamed_parts, write_3mf, write_stl
    from linkwork.export.trace_folder import read_trace_folder

    suffix = out.suffix.lower()
    if suffix not in (".stl", ".3mf"):
        raise SpecError(f"{out}: expected a file name ending in .stl or .3mf")
    if not 0.0 < scale < float("inf"):
        raise SpecError(f"--scale: expected a positive finite factor, got {scale}")
    check_output_file(out)
    folder = read_trace_folder(trace_dir)
    meshes = parts(folder.mechanism, folder.point(branch, point), scale)
    write_whole(out, lambda tmp: (write_3mf if suffix == ".3mf" else write_stl)(tmp, meshes))
    console.print(f"wrote {out}: {len(meshes)} parts (branch {branch}, point {point})")
    _report_names(renamed_parts(meshes))


@app.command("mjcf", cls=help.Command)
@friendly_errors
def mjcf(
    spec: Annotated[
        str, typer.Argument(help="A built-in name, a TOML spec file or a `linkwork trace --out` folder.")
    ],
    out: Out,
    set_: opt.SetParams = None,
    drive: Annotated[
        str | None,
        typer.Option("--drive", help="Joint the position actuator turns (default: the trace's drive)."),
    ] = None,
) -> None:
    """The mechanism as a MuJoCo model (MJCF).

    A body per link, hinges named after our joints, one weld closing each loop, a position actuator on the drive."""
    from linkwork.export.files import write_whole
    from linkwork.export.mjcf import mjcf as to_mjcf
    from linkwork.export.mjcf import mjcf_names

    check_output_file(out)
    mech, traced_drive = _mechanism(spec, set_)
    text = to_mjcf(mech, drive or traced_drive)
    write_whole(out, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    console.print(
        f"wrote {out}: {len(mech.bodies)} bodies, {mech.n_joints} joints, {len(mech.loops)} loop(s)"
    )
    _report_names(*mjcf_names(mech))


@app.command("dxf", cls=help.Command)
@friendly_errors
def dxf(
    spec: Annotated[
        str,
        typer.Argument(
            help="A `linkwork trace --out` or `linkwork synth` folder, a spec file or a built-in."
        ),
    ],
    out: Out,
    branch: Branch = 0,
    point: Point = 0,
    units: Annotated[
        str | None, typer.Option("--units", help="Length unit of the drawing: mm, cm, m, um, in or ft.")
    ] = None,
    set_: opt.SetParams = None,
) -> None:
    """A planar mechanism's links and pivots as a DXF drawing.

    At a traced point for a trace folder, else at its start; $INSUNITS from --units or the problem's `units`."""
    from linkwork.errors import SpecError
    from linkwork.export.dxf import write_mechanism_dxf
    from linkwork.export.files import write_whole
    from linkwork.export.trace_folder import read_trace_folder
    from linkwork.io.profiles import LENGTH_UNITS

    check_output_file(out)
    path = Path(spec)
    if units is None and (path / "chain.json").is_file():
        from linkwork.io.readback import read_chain

        units = read_chain(path / "chain.json").get("units")
    if units is not None:
        check_word("--units", units, tuple(LENGTH_UNITS))
    if (path / "path.csv").is_file():
        if set_:
            raise SpecError("--set applies to built-in linkages only, not to a trace folder", key="--set")
        folder = read_trace_folder(path)
        mech, angles = folder.mechanism, folder.point(branch, point)
    else:
        mech = _mechanism(spec, set_)[0]
        angles = mech.offsets
    write_whole(out, lambda tmp: write_mechanism_dxf(tmp, mech, angles, units))
    console.print(f"wrote {out}: {len(mech.bodies)} links, {mech.n_joints} joints ({units or 'unitless'})")


def _mechanism(spec: str, set_: list[str] | None) -> tuple[Mechanism, str | None]:
    """The mechanism of SPEC (built-in, file or trace folder) and the drive the trace used, if any."""
    from linkwork.errors import SpecError
    from linkwork.export.trace_folder import read_mechanism
    from linkwork.io.readback import read_report
    from linkwork.io.spec import resolve_spec

    path = Path(spec)
    if path.is_dir() and not (path / "mechanism.toml").is_file():
        unmechanized = (path / "chain.json").is_file()  # a synth folder holds a mechanism once mechanized
        raise SpecError(
            f"{path}: no mechanism.toml; expected a folder written by linkwork trace, or a synth folder after "
            "its mechanization (linkwork mechanize FOLDER, or synth --mechanize)"
            + ("; this synth folder has a chain but no mechanism yet" if unmechanized else "")
        )
    if path.is_dir():
        if set_:
            raise SpecError("--set applies to built-in linkages only, not to a trace folder", key="--set")
        report = path / "report.json"
        drive = read_report(report).get("drive") if report.is_file() else None
        mech = read_mechanism(path)
        if drive is not None and not mech.has_joint(drive):
            raise SpecError(
                f"expected one of the joints {', '.join(mech.joint_names)} of mechanism.toml, got {drive!r}",
                source=str(report),
                key="drive",
            )
        return mech, drive
    return resolve_spec(spec, parse_assignments(set_, "--set")).mechanism, None


def _report_names(*maps: NameMap) -> None:
    """Print the names the file format made us write differently (the name policy's report)."""
    from linkwork.names import describe

    line = describe(*maps)
    if line:
        console.print(line)

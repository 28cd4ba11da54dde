"""Solids for 3-D printing: every part (link, rod, hinge pin) of a mechanism at one traced point as a separate
closed mesh, written as ASCII STL (one ``solid`` per part) or 3MF (one ``object`` per part).

The meshes are those of :mod:`linkwork.viz.solids` (Hedgepeth's rods, Guest's rods, round bars and pins), each
closed and outward-oriented. Coordinates are the mechanism's lengths times ``scale``; 3MF declares millimetres.
"""

from __future__ import annotations

import zipfile
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from linkwork.errors import SpecError
from linkwork.io.writer import require_finite
from linkwork.kinematics.mechanism import Mechanism
from linkwork.names import NameMap, stl_names, xml_attribute
from linkwork.viz.solids import Mesh, posed_meshes


def parts(mech: Mechanism, angles: ArrayLike, scale: float = 1.0) -> list[Mesh]:
    """Every body's solid, then a pin on every joint, at the joint values ``angles`` (radians), scaled."""
    T = np.diag([scale, scale, scale, 1.0])
    meshes = [mesh.transformed(T) for mesh in posed_meshes(mech, angles)]
    what = f"--scale {scale:g}: the solids' coordinates (the mechanism's lengths times it)"
    for mesh in meshes:
        require_finite(mesh.vertices, what)
    size = max((float(np.max(np.abs(m.vertices))) for m in meshes if m.vertices.size), default=0.0)
    # Below this a float has lost digits to underflow (subnormal numbers): --scale 1e-320 wrote vertices
    # with two or three significant digits, every facet degenerate.
    smallest = float(np.finfo(float).tiny / np.finfo(float).eps)
    if 0.0 < size < smallest:
        raise SpecError(f"{what}: the largest is {size:.3g}; expected a size of at least {smallest:.3g}")
    return meshes


def part_labels(meshes: Sequence[Mesh]) -> list[str]:
    """The label of every part: the body's name, or ``pin_<joint>`` (two parts may share one)."""
    return [f"pin_{m.name}" if m.kind == "pin" else m.name for m in meshes]


def part_names(meshes: Sequence[Mesh]) -> list[str]:
    """A unique STL solid name per part (:func:`linkwork.names.stl_names` of :func:`part_labels`): one word of
    printable ASCII."""
    return stl_names(part_labels(meshes))[0]


def renamed_parts(meshes: Sequence[Mesh]) -> NameMap:
    """The part labels written under another name in an STL (see :func:`part_names`)."""
    return stl_names(part_labels(meshes))[1]


def write_stl(file: str | Path, meshes: Sequence[Mesh]) -> None:
    """ASCII STL with one ``solid <name>`` per part (facet normals from the outward-oriented faces)."""
    out: list[str] = []
    for name, mesh in zip(part_names(meshes), meshes, strict=True):
        tri = require_finite(mesh.triangles, "the STL's coordinates")
        unit = tri / max(float(np.max(np.abs(tri), initial=0.0)), 1e-300)  # no overflow in the cross product
        normals = np.cross(unit[:, 1] - unit[:, 0], unit[:, 2] - unit[:, 0])
        normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
        out.append(f"solid {name}")
        for n, (a, b, c) in zip(normals, tri, strict=True):
            out.append(f"  facet normal {n[0]:.9g} {n[1]:.9g} {n[2]:.9g}\n    outer loop")
            out += [f"      vertex {p[0]:.9g} {p[1]:.9g} {p[2]:.9g}" for p in (a, b, c)]
            out.append("    endloop\n  endfacet")
        out.append(f"endsolid {name}")
    Path(file).write_text("\n".join(out) + "\n")


_CONTENT_TYPES = """<?xml version="1.0" encoding="UTF-8"?>
<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">
 <Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>
 <Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>
</Types>
"""
_RELS = """<?xml version="1.0" encoding="UTF-8"?>
<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">
 <Relationship Target="/3D/3dmodel.model" Id="rel0"
  Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>
</Relationships>
"""


def write_3mf(file: str | Path, meshes: Sequence[Mesh]) -> None:
    """3MF (core specification): one ``object`` per part, every part a build item, unit millimetre."""
    body = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        '<model unit="millimeter" xml:lang="en-US" '
        'xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">',
        "<resources>",
    ]
    for k, (name, mesh) in enumerate(zip(part_names(meshes), meshes, strict=True), start=1):
        body.append(f'<object id="{k}" type="model" name={xml_attribute(name)}><mesh><vertices>')
        require_finite(mesh.vertices, "the 3MF's coordinates")
        body += [f'<vertex x="{x:.9g}" y="{y:.9g}" z="{z:.9g}"/>' for x, y, z in mesh.vertices]
        body.append("</vertices><triangles>")
        body += [f'<triangle v1="{a}" v2="{b}" v3="{c}"/>' for a, b, c in mesh.faces]
        body.append("</triangles></mesh></object>")
    body.append("</resources><build>")
    body += [f'<item objectid="{k}"/>' for k in range(1, len(meshes) + 1)]
    body.append("</build></model>")
    with zipfile.ZipFile(file, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("[Content_Types].xml", _CONTENT_TYPES)
        zf.writestr("_rels/.rels", _RELS)
        zf.writestr("3D/3dmodel.model", "\n".join(body) + "\n")

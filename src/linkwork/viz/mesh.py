"""Closed triangle meshes for drawing: the :class:`Mesh` record, its checks, and the prisms and round bars every
drawing style of :mod:`linkwork.viz.solids` is built from.

A mesh is closed and consistently oriented: every face counter-clockwise seen from outside (outward normals), so
its signed volume (divergence theorem) is positive and each edge is used once in each direction.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]

__all__ = [
    "BAR_COLORS",
    "PIN_COLOR",
    "ROD_COLORS",
    "SEGMENTS",
    "Mesh",
    "cut_prism",
    "cylinder",
    "edge_counts",
    "merge",
    "prism_faces",
    "signed_volume",
    "unit",
]

#: Colours (hex) of the drawing styles.
ROD_COLORS = ("#4878a8", "#d08a3c")  # two rod types / long and short sides
BAR_COLORS = ("#4878a8", "#d08a3c", "#5a9e5a", "#b8534f", "#8a6fb0", "#8c7a5b", "#c27aa9", "#6f8f9f")
PIN_COLOR = "#5c5c5c"
SEGMENTS = 12  # sides of a round bar or pin


@dataclass(frozen=True)
class Mesh:
    """A closed triangle mesh.

    Attributes
    ----------
    vertices
        ``(V, 3)`` coordinates.
    faces
        ``(F, 3)`` vertex indices, counter-clockwise seen from outside (outward normals).
    color
        Fill colour, a hex string ``"#rrggbb"``.
    kind
        ``"rod"`` (a shaped link of a built-in linkage), ``"bar"`` (a link drawn as bars), or ``"pin"``.
    name
        The body's name (rods, bars) or the joint's name (pins).
    """

    vertices: Array
    faces: IntArray
    color: str = BAR_COLORS[0]
    kind: str = "bar"
    name: str = ""

    def __post_init__(self) -> None:
        vertices = np.asarray(self.vertices, dtype=float)
        faces = np.asarray(self.faces, dtype=np.int64)
        if vertices.ndim != 2 or vertices.shape[1] != 3:
            raise ValueError(f"Expected vertices of shape (V, 3), got {vertices.shape}")
        if faces.ndim != 2 or faces.shape[1] != 3:
            raise ValueError(f"Expected faces of shape (F, 3), got {faces.shape}")
        object.__setattr__(self, "vertices", vertices)
        object.__setattr__(self, "faces", faces)

    def transformed(self, T: ArrayLike) -> Mesh:
        """The mesh moved by the 4x4 rigid transform ``T``."""
        T = np.asarray(T, dtype=float)
        return replace(self, vertices=self.vertices @ T[:3, :3].T + T[:3, 3])

    @property
    def triangles(self) -> Array:
        """``(F, 3, 3)`` corner coordinates of every face."""
        return self.vertices[self.faces]

    @property
    def volume(self) -> float:
        """Signed volume by the divergence theorem (positive for outward-oriented closed meshes)."""
        a, b, c = (self.vertices[self.faces[:, k]] for k in range(3))
        return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def signed_volume(mesh: Mesh) -> float:
    """Signed volume of a closed mesh (divergence theorem); same as ``mesh.volume``."""
    return mesh.volume


def edge_counts(mesh: Mesh) -> tuple[int, int]:
    """``(bad_undirected, bad_directed)``: edges not shared by exactly two faces, and directed edges repeated.

    Both are zero for a closed, consistently oriented mesh (each edge used once in each direction).
    """
    f = mesh.faces
    directed = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    undirected = np.sort(directed, axis=1)
    _, counts = np.unique(undirected, axis=0, return_counts=True)
    _, dcounts = np.unique(directed, axis=0, return_counts=True)
    return int(np.sum(counts != 2)), int(np.sum(dcounts != 1))


def cut_prism(
    section: ArrayLike, axis: ArrayLike, start: tuple[Array, Array], end: tuple[Array, Array]
) -> Array:
    """Vertices ``(2k, 3)`` of a prism: edges through the ``section`` points along ``axis``, cut by two planes.

    ``start`` and ``end`` are ``(point, normal)`` planes. The first ``k`` vertices lie on the start plane, the
    next ``k`` on the end plane, in section order. Faces come from :func:`prism_faces`.
    """
    section = np.asarray(section, dtype=float)
    u = np.asarray(axis, dtype=float)
    out = []
    for point, normal in (start, end):
        t = ((point - section) @ normal) / float(u @ normal)
        out.append(section + t[:, None] * u)
    return np.concatenate(out)


def prism_faces(k: int) -> IntArray:
    """Faces of a prism from :func:`cut_prism` whose section is counter-clockwise about the axis."""
    faces = []
    for i in range(1, k - 1):
        faces.append((0, i + 1, i))  # start cap, normal against the axis
        faces.append((k, k + i, k + i + 1))  # end cap
    for i in range(k):
        j = (i + 1) % k
        faces.append((i, j, k + j))
        faces.append((i, k + j, k + i))
    return np.array(faces, dtype=np.int64)


def cylinder(a: ArrayLike, b: ArrayLike, radius: float, segments: int = SEGMENTS, **fields: str) -> Mesh:
    """A closed round bar (a ``segments``-sided prism) from ``a`` to ``b``."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    u = b - a
    length = float(np.linalg.norm(u))
    u = u / length if length > 0 else np.array([0.0, 0.0, 1.0])
    e1, e2 = _perpendiculars(u)
    t = 2.0 * np.pi * np.arange(segments) / segments
    section = a + radius * (np.cos(t)[:, None] * e1 + np.sin(t)[:, None] * e2)  # CCW about u
    vertices = cut_prism(section, u, (a, u), (a + max(length, 1e-12 * radius) * u, u))
    return Mesh(vertices, prism_faces(segments), **fields)


def merge(meshes: list[Mesh], **fields: str) -> Mesh:
    """Several closed meshes as one (their union as a set of faces)."""
    vertices, faces, offset = [], [], 0
    for m in meshes:
        vertices.append(m.vertices)
        faces.append(m.faces + offset)
        offset += len(m.vertices)
    return Mesh(np.concatenate(vertices), np.concatenate(faces), **fields)


def _perpendiculars(u: Array) -> tuple[Array, Array]:
    """Two unit vectors completing ``u`` to a right-handed frame ``(e1, e2, u)``."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(u[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(helper, u)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(u, e1)


def unit(x: Array) -> Array:
    return x / np.linalg.norm(x)

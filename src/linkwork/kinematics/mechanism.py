"""The one model of a mechanism: bodies joined by revolute and prismatic joints, each a unit twist.

A :class:`Mechanism` is an assembled reference configuration (product of exponentials, POE): joint ``j`` is the
unit twist ``xi_j`` of its axis in the base frame at the reference, and its coordinate ``q_j`` is measured from
the reference, so that the value a user reads is ``offset_j + q_j``. Loops come from a cycle basis of the body
graph; each loop is an ordered list of (joint, sign) and closes when ``prod exp(sign * xi_j * q_j) = I``. A single
hoop, Guest's frame and a multi-loop mechanized chain are the same object.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Hashable, Mapping, Sequence
from dataclasses import dataclass, field, fields, replace
from functools import cached_property
from typing import Any, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.errors import SpecError
from linkwork.geometry import line_twist
from linkwork.names import canonical

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Rows of a twist kept for a planar mechanism (rotation about z, translation in x and y).
PLANAR_ROWS = (2, 3, 4)

T = TypeVar("T")


@dataclass(frozen=True)
class Loop:
    """One closed loop: joint indices in loop order, and +1/-1 for the direction each joint is traversed."""

    joints: tuple[int, ...]
    signs: tuple[int, ...]


@dataclass(frozen=True)
class Mechanism:
    """An assembled mechanism in the product-of-exponentials form.

    Attributes
    ----------
    name
        A label for reports.
    joint_names
        One name per joint, e.g. ``("A", "B", ...)``.
    joint_types
        ``"R"`` (revolute, coordinate an angle in radians) or ``"P"`` (prismatic, a length) per joint.
    twists
        ``(n, 6)`` unit twists ``(omega, v)`` of the joints in the base frame at the reference configuration.
    offsets
        ``(n,)`` the value of each joint's coordinate at the reference configuration (what users read is
        ``offsets + q``).
    loops
        The independent loops (a cycle basis of the body graph).
    bodies
        Body names; ``joint_bodies[j]`` is the (before, after) pair joint ``j`` connects: the body after moves
        relative to the body before by ``exp(xi_j q_j)``.
    planar
        Keep only the three planar closure equations per loop (rotation about z, translation in x and y).
    groups
        ``(n,)`` the unknown each joint follows (joint couplings make several joints share one), ``-1`` for a
        fixed joint, which stays at its reference value.
    meta
        Free-form provenance (constructor name and parameters, drawing hints); never used by the numerics.
    hinge_points
        ``(n, 3)`` the point written for each joint (a point on its line in the reference configuration: where
        the physical hinge is), or ``(0, 3)`` when the description gave none (a ``dh`` or ``rods`` loop). A line
        carries no position along itself; manufacturing errors tilt a hinge about this point
        (:mod:`linkwork.studies.imperfections`). A point that no longer lies on its line (the twists replaced,
        moved or re-referenced) is not used.
    ground_name
        The body held fixed when it is not called ``ground`` (:meth:`from_joints`'s ``ground``), else ``None``:
        read it as :attr:`ground`.

    A mechanism is a value: its fields cannot be reassigned and its arrays are read-only copies (the arrays a
    caller passed in are not kept), and a changed mechanism is a new one (:func:`dataclasses.replace`,
    :meth:`with_couplings`, :meth:`with_reference`). What is derived from it alone (the number of unknowns, the
    flattened loops the compiled kernels read, a tracer's plan of it) is therefore computed once, on first use,
    and kept on it (:meth:`derived`); a copy or an unpickled mechanism starts without those and freezes its
    arrays again.
    """

    name: str
    joint_names: tuple[str, ...]
    joint_types: tuple[str, ...]
    twists: Array
    offsets: Array
    loops: tuple[Loop, ...]
    bodies: tuple[str, ...] = ()
    joint_bodies: tuple[tuple[str, str], ...] = ()
    planar: bool = False
    groups: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    meta: Mapping[str, Any] = field(default_factory=dict)
    hinge_points: Array = field(default_factory=lambda: np.zeros((0, 3)))
    ground_name: str | None = None

    def __post_init__(self) -> None:
        """Check the shapes and keep private, read-only copies of the arrays (a frozen value in full)."""
        n = len(self.joint_names)
        # names in one Unicode form (names.canonical): "é" typed two ways is one joint or body
        object.__setattr__(self, "joint_names", tuple(canonical(str(j)) for j in self.joint_names))
        object.__setattr__(self, "bodies", tuple(canonical(str(b)) for b in self.bodies))
        object.__setattr__(
            self, "joint_bodies", tuple((canonical(str(a)), canonical(str(b))) for a, b in self.joint_bodies)
        )
        twists = _frozen(self.twists, float)
        if twists.shape != (n, 6):
            raise ValueError(f"Expected twists of shape ({n}, 6), got {twists.shape}")
        object.__setattr__(self, "twists", twists)
        object.__setattr__(self, "offsets", _frozen(np.asarray(self.offsets, dtype=float).reshape(n), float))
        groups = np.asarray(self.groups, dtype=np.int64)
        if groups.size == 0:
            groups = np.arange(n, dtype=np.int64)
        if groups.shape != (n,):
            raise ValueError(f"Expected groups of shape ({n},), got {groups.shape}")
        object.__setattr__(self, "groups", _frozen(groups, np.int64))
        points = np.asarray(self.hinge_points, dtype=float).reshape(-1, 3)
        if len(points) not in (0, n):
            raise ValueError(f"Expected hinge_points of shape ({n}, 3) or (0, 3), got {points.shape}")
        object.__setattr__(self, "hinge_points", _frozen(points, float))
        if len(set(self.joint_names)) != n:
            raise SpecError(f"joint names must be unique, got {list(self.joint_names)}")
        if self.ground_name is not None:
            object.__setattr__(self, "ground_name", canonical(str(self.ground_name)))
            if self.ground_name not in self.bodies:
                raise SpecError(
                    f"ground {self.ground_name!r} is not a body of any joint; bodies: {list(self.bodies)}"
                )
            if self.ground_name != "ground" and "ground" in self.bodies:
                raise SpecError(
                    f"ground {self.ground_name!r}: another body is called 'ground'; expected the body called "
                    "'ground' to be the ground, or no body of that name"
                )

    def __getstate__(self) -> dict[str, Any]:
        """The fields only (for pickle and :mod:`copy`): the derived values are rebuilt where it is used."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def __setstate__(self, state: Mapping[str, Any]) -> None:
        """The fields of :meth:`__getstate__`, checked and frozen again as by the constructor (numpy unpickles
        arrays writable)."""
        for name, value in state.items():
            object.__setattr__(self, name, value)
        self.__post_init__()

    def derived(self, key: Hashable, build: Callable[[], T]) -> T:
        """A value that depends on this mechanism alone, ``build()`` on the first request for ``key`` and kept
        for the next ones (the mechanism cannot change: see the class's docstring).

        ``key`` names what is kept, including whatever besides the mechanism it depends on (a joint, the kernels'
        backend). The value is shared by every caller: it must not be changed (arrays in it read-only).
        """
        store: dict[Hashable, Any] | None = self.__dict__.get("_derived")
        if store is None:
            store = self.__dict__["_derived"] = {}
        try:
            return store[key]
        except KeyError:
            value = store[key] = build()
            return value

    def __repr__(self) -> str:
        """One line: name, joints by type and name, bodies, loops, planar or spatial (not the arrays)."""
        from linkwork.viz.mechanism_card import summary

        return summary(self)

    def _repr_html_(self) -> str:
        """In Jupyter: the joints and bodies as tables beside a small drawing of the start (inline SVG)."""
        from linkwork.viz.mechanism_card import card

        return card(self)

    # ----------------------------------------------------------------------------------------------------
    # sizes and index helpers
    @property
    def n_joints(self) -> int:
        """Number of joints ``n``."""
        return len(self.joint_names)

    @cached_property
    def n_unknowns(self) -> int:
        """Number of independent unknowns ``m`` after couplings and fixed joints."""
        return int(self.groups.max()) + 1 if np.any(self.groups >= 0) else 0

    @property
    def ground(self) -> str | None:
        """The body held fixed, the frame every pose, drawing and export is in: the body named by
        :meth:`from_joints`'s ``ground``, else the body called ``ground``, else the first body (``None`` without
        bodies: a loop given by its twists alone)."""
        if self.ground_name is not None:
            return self.ground_name
        if "ground" in self.bodies:
            return "ground"
        return self.bodies[0] if self.bodies else None

    @property
    def grounded(self) -> bool:
        """Whether a body is named as the ground (:attr:`ground_name`, or a body called ``ground``), rather than
        the first body taken for it."""
        return self.ground_name is not None or "ground" in self.bodies

    @property
    def rows(self) -> tuple[int, ...]:
        """Closure equations kept per loop: all six, or the three planar ones."""
        return PLANAR_ROWS if self.planar else (0, 1, 2, 3, 4, 5)

    @cached_property
    def n_equations(self) -> int:
        """Number of scalar closure equations (loops x rows)."""
        return len(self.loops) * len(self.rows)

    def plane_normal(self, tol: float = 1e-9) -> Array | None:
        """The unit normal of the plane the mechanism moves in, however it is written; None for a spatial one.

        A mechanism is planar when every revolute axis is parallel to one direction ``n`` (to ``tol`` in the sine
        of the angle between them) and every prismatic direction is normal to it: then every link moves parallel
        to the plane normal to ``n``, whether it was written as a ``planar`` mechanism (``n`` is z), as a ``dh``
        loop with zero twists, or as hinge lines that happen to be parallel. Rotation about parallel axes keeps
        them parallel, so the reference configuration decides for the whole motion.
        """
        if self.planar:
            return np.array([0.0, 0.0, 1.0])
        w, v = self.twists[:, :3], self.twists[:, 3:]
        revolute = np.einsum("ij,ij->i", w, w) > 0.5
        if not np.any(revolute):
            return None
        normal = w[np.flatnonzero(revolute)[0]]
        normal = normal / np.linalg.norm(normal)
        if np.any(np.linalg.norm(np.cross(w[revolute], normal), axis=1) > tol):
            return None
        if np.any(np.abs(v[~revolute] @ normal) > tol):
            return None
        return normal

    @property
    def moves_in_plane(self) -> bool:
        """Whether the mechanism is planar however it is written (:meth:`plane_normal`)."""
        return self.plane_normal() is not None

    @property
    def moves_in_xy(self) -> bool:
        """Whether the mechanism moves in the x-y plane however it is written (a ``planar`` mechanism, a ``dh``
        loop with zero twists, parallel hinge lines along z): what the drawings and the viewer show from above."""
        normal = self.plane_normal()
        return normal is not None and abs(float(normal[2])) > 1.0 - 1e-12

    def index(self, joint: str | int) -> int:
        """Index of a joint given by name or index; a clear :class:`SpecError` for an unknown one."""
        if isinstance(joint, int | np.integer):
            if not 0 <= int(joint) < self.n_joints:
                raise SpecError(f"joint index {joint} out of range 0..{self.n_joints - 1}")
            return int(joint)
        try:
            return self.joint_names.index(canonical(joint) if isinstance(joint, str) else joint)
        except ValueError:
            raise SpecError(f"unknown joint {joint!r}; joints are {', '.join(self.joint_names)}") from None

    def has_joint(self, name: str) -> bool:
        """Whether a joint is called ``name`` (compared as :func:`linkwork.names.canonical` names, as
        :meth:`index` finds it)."""
        return isinstance(name, str) and canonical(name) in self.joint_names

    def group_members(self) -> list[list[int]]:
        """Joint indices sharing each unknown, in unknown order."""
        return [list(np.flatnonzero(self.groups == g)) for g in range(self.n_unknowns)]

    def coupling_matrix(self) -> Array:
        """``(n, m)`` matrix ``C`` with ``q = C u`` for the free joints (fixed joints give zero rows)."""
        C = np.zeros((self.n_joints, self.n_unknowns))
        free = self.groups >= 0
        C[np.flatnonzero(free), self.groups[free]] = 1.0
        return C

    def loop_arrays(self) -> tuple[IntArray, IntArray, IntArray]:
        """Flattened loops for the compiled kernels: ``(joint, sign, ptr)`` with loop ``k`` in ``ptr[k]:ptr[k+1]``."""
        joints = np.array([j for loop in self.loops for j in loop.joints], dtype=np.int64)
        signs = np.array([s for loop in self.loops for s in loop.signs], dtype=np.int64)
        ptr = np.cumsum([0] + [len(loop.joints) for loop in self.loops]).astype(np.int64)
        return joints, signs, ptr

    @cached_property
    def kernel_arrays(self) -> tuple[Array, IntArray, IntArray, IntArray, IntArray, IntArray]:
        """The mechanism tuple every tracing kernel takes, read-only and built once: ``(twists, loop_joint,
        loop_sign, loop_ptr, rows, groups)`` (:meth:`loop_arrays`, :attr:`rows` as an array; the layout of
        :data:`linkwork.kinematics.march.MECHANISM`)."""
        joints, signs, ptr = (_frozen(a, np.int64) for a in self.loop_arrays())
        rows = _frozen(self.rows, np.int64)
        return self.twists, joints, signs, ptr, rows, self.groups

    @cached_property
    def first_joints(self) -> tuple[int, ...]:
        """The first joint of each unknown, in unknown order (``group_members()[g][0]`` for every ``g``)."""
        first: list[int] = []
        for j, g in enumerate(self.groups.tolist()):
            if g >= len(first):
                first.extend([-1] * (g + 1 - len(first)))
            if g >= 0 and first[g] < 0:
                first[g] = j
        return tuple(first)

    # ----------------------------------------------------------------------------------------------------
    # coordinates
    def q_from_angles(self, values: ArrayLike) -> Array:
        """Joint displacements ``q`` from the reported joint values (``offsets + q``)."""
        return np.asarray(values, dtype=float) - self.offsets

    def angles_from_q(self, q: ArrayLike) -> Array:
        """Reported joint values from displacements."""
        return np.asarray(q, dtype=float) + self.offsets

    def q_from_u(self, u: ArrayLike) -> Array:
        """Joint displacements of the unknowns ``u`` (fixed joints stay at 0, i.e. at their reference value)."""
        u = np.asarray(u, dtype=float)
        q = np.zeros((*u.shape[:-1], self.n_joints))
        free = self.groups >= 0
        q[..., free] = u[..., self.groups[free]]
        return q

    def u_from_q(self, q: ArrayLike) -> Array:
        """Unknowns from joint displacements (the first joint of each group)."""
        q = np.asarray(q, dtype=float)
        first = [members[0] for members in self.group_members()]
        return q[..., first]

    # ----------------------------------------------------------------------------------------------------
    # derived mechanisms
    def with_couplings(
        self, couple: Sequence[Sequence[str | int]] = (), fixed: Sequence[str | int] = ()
    ) -> Mechanism:
        """A copy whose joints in each ``couple`` group are forced equal and whose ``fixed`` joints are held."""
        parent = list(range(self.n_joints))

        def find(i: int) -> int:
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        # Start from the existing couplings.
        for members in self.group_members():
            for j in members[1:]:
                parent[find(j)] = find(members[0])
        for group in couple:
            idx = [self.index(j) for j in group]
            if len(idx) < 2:
                raise SpecError(f"a coupling needs at least two joints, got {list(group)}")
            kinds = {self.joint_types[i] for i in idx}
            if len(kinds) > 1:
                raise SpecError(f"cannot couple revolute and prismatic joints: {list(group)}")
            for j in idx[1:]:
                parent[find(j)] = find(idx[0])
        fixed_idx = {self.index(j) for j in fixed} | set(np.flatnonzero(self.groups < 0).tolist())
        roots: dict[int, int] = {}
        groups = np.empty(self.n_joints, dtype=np.int64)
        fixed_roots = {find(j) for j in fixed_idx}
        for j in range(self.n_joints):
            r = find(j)
            if r in fixed_roots:
                groups[j] = -1
                continue
            groups[j] = roots.setdefault(r, len(roots))
        # Coupled joints must start equal: they share one unknown measured from the reference.
        return replace(self, groups=groups)

    def with_reference(self, q: ArrayLike) -> Mechanism:
        """The same mechanism re-referenced at displacement ``q``: twists carried there, offsets advanced.

        ``q`` should close every loop; the new reference is then an exactly assembled configuration.
        """
        from linkwork.kinematics.closure import body_poses, spatial_twists

        q = np.asarray(q, dtype=float)
        poses = body_poses(self, q=q)
        twists = spatial_twists(self, q, poses)
        return replace(self, twists=twists, offsets=self.offsets + q)

    # ----------------------------------------------------------------------------------------------------
    # constructors
    @classmethod
    def from_joints(
        cls,
        name: str,
        joints: Sequence[Mapping[str, Any]],
        *,
        planar: bool = False,
        ground: str = "ground",
        meta: Mapping[str, Any] | None = None,
    ) -> Mechanism:
        """A mechanism from joints between named bodies, each given by its axis in the start configuration.

        Each joint is a mapping with ``name``, ``type`` (``"R"`` or ``"P"``), ``bodies`` (before, after),
        ``point`` and ``direction`` (3-vectors; 2-vectors are lifted to z = 0 for planar mechanisms) and an
        optional ``value`` (the joint's reading at the start). The loops are a cycle basis of the body graph
        (fundamental cycles of a breadth-first spanning tree rooted at ``ground``), and ``ground`` the body held
        fixed (:attr:`ground`): the frame of every pose, drawing and export. A ``ground`` other than ``"ground"``
        must be one of the bodies, and then no other body may be called ``ground``.
        """
        names, types, twists, offsets, pairs, points = [], [], [], [], [], []
        for j in joints:
            point = np.asarray(j.get("point", (0.0, 0.0, 0.0)), dtype=float)
            direction = np.asarray(j["direction"], dtype=float)
            if point.shape == (2,):
                point = np.append(point, 0.0)
            points.append(point)
            if direction.shape == (2,):
                direction = np.append(direction, 0.0)
            kind = str(j.get("type", "R"))
            names.append(str(j["name"]))
            types.append(kind)
            twists.append(line_twist(point, direction, kind))
            offsets.append(float(j.get("value", 0.0)))
            a, b = j["bodies"]
            pairs.append((str(a), str(b)))
        loops, bodies = cycle_basis(pairs, ground)
        return cls(
            name=name,
            joint_names=tuple(names),
            joint_types=tuple(types),
            twists=np.array(twists).reshape(len(names), 6),
            offsets=np.array(offsets),
            loops=tuple(loops),
            bodies=tuple(bodies),
            joint_bodies=tuple(pairs),
            planar=planar,
            meta=dict(meta or {}),
            hinge_points=np.array(points).reshape(len(names), 3),
            ground_name=None if ground == "ground" else ground,
        )

    @classmethod
    def single_loop(
        cls,
        name: str,
        joint_names: Sequence[str],
        twists: ArrayLike,
        offsets: ArrayLike | None = None,
        joint_types: Sequence[str] | None = None,
        *,
        meta: Mapping[str, Any] | None = None,
        hinge_points: ArrayLike | None = None,
    ) -> Mechanism:
        """A single closed loop of joints in loop order: link ``i`` lies between joint ``i`` and ``i + 1``
        (``hinge_points``: the point written for each joint, if any)."""
        n = len(joint_names)
        bodies = tuple(f"link{i}" for i in range(n))
        pairs = tuple((bodies[i - 1], bodies[i]) for i in range(n))
        return cls(
            name=name,
            joint_names=tuple(joint_names),
            joint_types=tuple(joint_types or ("R",) * n),
            twists=np.asarray(twists, dtype=float),
            offsets=np.zeros(n) if offsets is None else np.asarray(offsets, dtype=float),
            loops=(Loop(tuple(range(n)), (1,) * n),),
            bodies=bodies,
            joint_bodies=pairs,
            meta=dict(meta or {}),
            hinge_points=np.zeros((0, 3)) if hinge_points is None else np.asarray(hinge_points, dtype=float),
        )


def _frozen(values: ArrayLike, dtype: type) -> Any:
    """A contiguous copy of ``values`` that cannot be written to, so that no caller's array aliases a field."""
    out: np.ndarray = np.array(values, dtype=dtype, order="C", copy=True)
    out.flags.writeable = False
    return out


def cycle_basis(pairs: Sequence[tuple[str, str]], ground: str = "ground") -> tuple[list[Loop], list[str]]:
    """Fundamental cycles of the body graph whose edges are the joints ``(before, after)``.

    A breadth-first spanning tree is grown from ``ground`` (or the first body); every joint not in the tree
    closes one loop, traversed from the lowest common ancestor down to the joint's ``before`` body, across the
    joint, and back up from its ``after`` body. A joint traversed against its (before -> after) direction gets
    sign -1.
    """
    bodies: list[str] = []
    for a, b in pairs:
        for body in (a, b):
            if body not in bodies:
                bodies.append(body)
    if not bodies:
        return [], []
    root = ground if ground in bodies else bodies[0]
    for j, (a, b) in enumerate(pairs):
        if a == b:
            raise SpecError(f"joint {j} connects body {a!r} to itself")
    parent: dict[str, tuple[str, int] | None] = {root: None}
    depth = {root: 0}
    for body, j, other, _ in spanning_tree(pairs, root):
        parent[other] = (body, j)
        depth[other] = depth[body] + 1
    unreached = [b for b in bodies if b not in parent]
    if unreached:
        raise SpecError(f"bodies {unreached} are not connected to {root!r} by any joint")
    tree_edges = {edge[1] for edge in parent.values() if edge is not None}
    loops = [_fundamental_loop(pairs, parent, depth, j) for j in range(len(pairs)) if j not in tree_edges]
    return loops, bodies


def spanning_tree(pairs: Sequence[tuple[str, str]], root: str) -> list[tuple[str, int, str, int]]:
    """The breadth-first spanning tree from ``root`` of the body graph whose edges are the joints
    ``(before, after)``: its edges ``(body, joint, other, sign)`` in the order they are reached, ``other`` reached
    from ``body`` through ``joint`` (``sign`` -1 when walked from the joint's ``after`` body to its ``before``)."""
    adjacency: dict[str, list[tuple[int, str, int]]] = {}
    for j, (a, b) in enumerate(pairs):
        adjacency.setdefault(a, []).append((j, b, 1))
        adjacency.setdefault(b, []).append((j, a, -1))
    edges = []
    seen = {root}
    queue = deque([root])
    while queue:
        body = queue.popleft()
        for j, other, sign in adjacency.get(body, []):
            if other not in seen:
                seen.add(other)
                edges.append((body, j, other, sign))
                queue.append(other)
    return edges


def _fundamental_loop(
    pairs: Sequence[tuple[str, str]],
    parent: Mapping[str, tuple[str, int] | None],
    depth: Mapping[str, int],
    j: int,
) -> Loop:
    """The loop that joint ``j`` (not in the spanning tree ``parent``) closes: down from the lowest common ancestor
    of its bodies to ``before``, across ``j``, and up from ``after``."""

    def step_sign(jj: int, frm: str) -> int:
        return 1 if pairs[jj][0] == frm else -1

    a, b = pairs[j]
    # Walk a and b up to their lowest common ancestor.
    up_a: list[tuple[int, str]] = []  # (joint, body above) walking from a upward
    up_b: list[tuple[int, str]] = []
    x, y = a, b
    while depth[x] > depth[y]:
        p = parent[x]
        assert p is not None
        up_a.append((p[1], p[0]))
        x = p[0]
    while depth[y] > depth[x]:
        p = parent[y]
        assert p is not None
        up_b.append((p[1], p[0]))
        y = p[0]
    while x != y:
        pa, pb = parent[x], parent[y]
        assert pa is not None and pb is not None
        up_a.append((pa[1], pa[0]))
        up_b.append((pb[1], pb[0]))
        x, y = pa[0], pb[0]
    # Down from the ancestor to a: reverse of up_a, each joint traversed from its upper body.
    joints: list[int] = []
    signs: list[int] = []
    for jj, above in reversed(up_a):
        joints.append(jj)
        signs.append(step_sign(jj, above))
    joints.append(j)
    signs.append(1)  # from a (before) to b (after)
    below = b
    for jj, above in up_b:
        joints.append(jj)
        signs.append(step_sign(jj, below))
        below = above
    return Loop(tuple(joints), tuple(signs))

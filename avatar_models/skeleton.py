"""``Skeleton``: a rig as data (joint names, parents, rest offsets, optional DOF limits).

Shapes: ``J`` joints. ``parents (J,)`` int with ``-1`` for the root and ``parents[j] < j``
(topological order), ``offsets (J, 3)`` metres in the parent's frame (Z up, rest pose faces +X).
Leaf "sites" (BVH End Sites) are ordinary joints flagged in ``is_site``; they never rotate.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from avatarsim.avatar_models.errors import MotionValueError, UnknownJointError

# Left/right name patterns tried in order when mirroring or pairing joints.
_SIDE_PATTERNS: tuple[tuple[str, str], ...] = (
    (r"Left", "Right"),
    (r"left", "right"),
    (r"_L$", "_R$"),
    (r"_l$", "_r$"),
    (r"^L_", "^R_"),
    (r"^l_", "^r_"),
    (r"^L(?=[A-Z])", "^R(?=[A-Z])"),
    (r"^l(?=[a-z])", "^r(?=[a-z])"),
    (r" L ", " R "),
    (r"\.L$", r"\.R$"),
    (r"_LEFT$", "_RIGHT$"),  # Azure Kinect k4abt names (CLAVICLE_LEFT)
)


def _swap_side(name: str) -> str | None:
    """The opposite-side name of ``name`` by common naming patterns, or None."""
    for left, right in _SIDE_PATTERNS:
        for a, b in ((left, right), (right, left)):
            if re.search(a, name):
                repl = b.replace("^", "").replace("$", "").replace("(?=[A-Z])", "")
                repl = repl.replace("(?=[a-z])", "").replace("\\", "")
                return re.sub(a, repl, name, count=1)
    return None


@dataclass(frozen=True, eq=False)
class Skeleton:
    """A kinematic tree. See the module docstring for shapes and conventions.

    Attributes:
        names: joint names, unique, length ``J``.
        parents: ``(J,)`` parent index per joint, ``-1`` for the single root.
        offsets: ``(J, 3)`` rest offset of each joint from its parent (metres).
        is_site: ``(J,)`` bool, True for end sites (no rotation of their own).
        limits: per-joint DOF limits, ``{joint: {"rx"|"ry"|"rz": (lo, hi)}}`` radians about
            the joint's local axes; empty when the source gives none.
        name: the rig's name (``"cmu"``, ``"bandai"``, ``"avatar"``...) or ``""``.
    """

    names: tuple[str, ...]
    parents: np.ndarray
    offsets: np.ndarray
    is_site: np.ndarray | None = None
    limits: dict[str, dict[str, tuple[float, float]]] = field(default_factory=dict)
    name: str = ""

    def __post_init__(self) -> None:
        names = tuple(self.names)
        parents = np.asarray(self.parents, dtype=np.int64).reshape(-1)
        offsets = np.asarray(self.offsets, dtype=float).reshape(-1, 3)
        n = len(names)
        if n == 0:
            raise MotionValueError("a skeleton needs at least one joint")
        if parents.shape != (n,) or offsets.shape != (n, 3):
            raise MotionValueError(
                f"skeleton arrays disagree: {n} names, parents {parents.shape}, "
                f"offsets {offsets.shape}"
            )
        if len(set(names)) != n:
            dup = sorted({x for x in names if names.count(x) > 1})
            raise MotionValueError(f"duplicate joint names: {dup}")
        if parents[0] != -1 or np.any(parents[1:] < 0) or np.any(parents[1:] >= np.arange(1, n)):
            raise MotionValueError(
                "parents must list the root first (-1) and each parent before its child"
            )
        if not np.all(np.isfinite(offsets)):
            raise MotionValueError("skeleton offsets contain NaN or inf")
        is_site = np.zeros(n, bool) if self.is_site is None else np.asarray(self.is_site, bool)
        if is_site.shape != (n,):
            raise MotionValueError(
                f"is_site must hold one flag per joint ({n}), got {is_site.shape}"
            )
        for jname in self.limits:
            if jname not in names:
                raise UnknownJointError(jname, names)
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "parents", parents)
        object.__setattr__(self, "offsets", offsets)
        object.__setattr__(self, "is_site", is_site)
        object.__setattr__(self, "_index", {nm: i for i, nm in enumerate(names)})

    # -- lookup ---------------------------------------------------------------------------
    @property
    def n_joints(self) -> int:
        return len(self.names)

    def index(self, name: str) -> int:
        """Index of joint ``name``; raises :class:`UnknownJointError` if absent."""
        try:
            return self._index[name]  # type: ignore[attr-defined]
        except KeyError:
            raise UnknownJointError(name, self.names) from None

    def indices(self, names: list[str] | tuple[str, ...]) -> np.ndarray:
        return np.array([self.index(n) for n in names], dtype=np.int64)

    def __contains__(self, name: str) -> bool:
        return name in self._index  # type: ignore[attr-defined]

    def children(self, j: int) -> np.ndarray:
        return np.flatnonzero(self.parents == j)

    def chain(self, j: int) -> list[int]:
        """Indices from the root down to joint ``j`` inclusive."""
        out = []
        while j >= 0:
            out.append(int(j))
            j = int(self.parents[j])
        return out[::-1]

    # -- geometry -------------------------------------------------------------------------
    @property
    def bone_lengths(self) -> np.ndarray:
        """``(J,)`` length of each joint's offset (the bone to its parent); 0 for the root."""
        lengths = np.linalg.norm(self.offsets, axis=1)
        lengths[0] = 0.0
        return lengths

    def rest_positions(self) -> np.ndarray:
        """``(J, 3)`` global joint positions in the rest pose with the root at the origin."""
        pos = np.zeros((self.n_joints, 3))
        for j in range(1, self.n_joints):
            pos[j] = pos[self.parents[j]] + self.offsets[j]
        return pos

    def mirror_map(self) -> np.ndarray:
        """``(J,)`` index of each joint's left/right counterpart (itself if unpaired)."""
        out = np.arange(self.n_joints)
        for j, nm in enumerate(self.names):
            other = _swap_side(nm)
            if other is not None and other in self:
                out[j] = self.index(other)
        return out

    def scaled(self, factor: float) -> Skeleton:
        """Uniformly scaled copy (offsets times ``factor``)."""
        return Skeleton(
            self.names,
            self.parents,
            self.offsets * float(factor),
            self.is_site,
            self.limits,
            self.name,
        )

    def with_offsets(self, offsets: np.ndarray) -> Skeleton:
        return Skeleton(self.names, self.parents, offsets, self.is_site, self.limits, self.name)

    def same_topology(self, other: Skeleton) -> bool:
        return self.names == other.names and np.array_equal(self.parents, other.parents)

    def __repr__(self) -> str:
        return f"Skeleton(name={self.name!r}, joints={self.n_joints})"

"""``BodyDescription``: one body, from a skeleton, for MuJoCo (MJCF) and for rendering (trimesh).

A capsule per bone between two simulated joints, a box (or capsule) per foot, a capsule per
hand and a sphere for the skull, laid out on the skeleton's rest pose by
:class:`~avatar_models.body.layout.Layout` (masses and centres of mass from de Leva (1996),
radii from ANSUR II, see :mod:`avatar_models.body.anthropometry`); anatomical hinge ranges from
:mod:`avatar_models.body.joint_ranges`. Lengths come from the skeleton itself, so a motion on
the same skeleton replays exactly (:meth:`BodyDescription.qpos_from_motion`).
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from avatarsim.avatar_models.body import anthropometry as anthro
from avatarsim.avatar_models.body.anatomy import Anatomy, classify
from avatarsim.avatar_models.body.errors import BodyError, RestPoseNotUprightError
from avatarsim.avatar_models.body.geometry import Segment
from avatarsim.avatar_models.body.joint_ranges import euler_order, is_shared, joint_ranges
from avatarsim.avatar_models.body.layout import Layout
from avatarsim.avatar_models.errors import RigError
from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.rigs import Rig, identify_rig
from avatarsim.avatar_models.skeleton import Skeleton

MAX_HEIGHT_M = 3.0
FOOT_SHAPES = ("box", "capsule")


@dataclass(frozen=True, eq=False)
class BodyDescription:
    """A humanoid body on a skeleton. Build it with :func:`build_body`.

    Attributes:
        skeleton: the (possibly scaled) skeleton whose rest offsets are the bones.
        rig: the rig it was recognised as (gives the body17 map).
        mass_kg: total mass.
        foot: ``"box"`` or ``"capsule"``.
        segment_scale: length factor per segment kind that was applied to the skeleton.
        anatomy: joint classification (simulated joints, roles, bone kinds).
        stature: sole to top of the skull in the rest pose (metres).
        segments: every primitive with its mass, in body frames.
        root_height: height of the root joint above the floor when standing in the rest pose.
        source_skeleton: the skeleton given to :func:`build_body`, before any scaling.
    """

    skeleton: Skeleton
    rig: Rig
    mass_kg: float
    foot: str
    segment_scale: Mapping[str, float]
    anatomy: Anatomy
    stature: float
    segments: tuple[Segment, ...]
    root_height: float
    source_skeleton: Skeleton = field(repr=False)

    # -- structure ------------------------------------------------------------------------
    @property
    def simulated_joints(self) -> np.ndarray:
        """Indices of the joints that have a MuJoCo body, in topological order."""
        return np.flatnonzero(self.anatomy.simulated)

    @property
    def fixed_joints(self) -> np.ndarray:
        """Indices of the joints fixed into their parent (fingers, toes, jaw, end sites...)."""
        return np.flatnonzero(~self.anatomy.simulated)

    @cached_property
    def body_order(self) -> tuple[int, ...]:
        """Simulated joints in MuJoCo's body order: depth first, children by joint index
        (the order :meth:`to_mjcf` nests them in, hence the order of qpos)."""
        sim = self.anatomy.simulated
        order, stack = [], [0]
        while stack:
            j = stack.pop()
            order.append(j)
            stack.extend(int(c) for c in self.skeleton.children(j)[::-1] if sim[c])
        return tuple(order)

    @property
    def hinges(self) -> list[tuple[int, str]]:
        """``(joint, axis)`` of every hinge in qpos order (after the root's 7 numbers)."""
        return [(j, a) for j in self.body_order[1:] for a in self.hinge_order(j).lower()]

    def hinge_order(self, joint: int) -> str:
        """Euler order (``"YXZ"``...) of the three hinges of simulated non-root ``joint``."""
        return euler_order(self.anatomy.roles[joint])

    @cached_property
    def hinge_ranges(self) -> dict[int, dict[str, tuple[float, float]]]:
        """Radians per axis for every simulated non-root joint (``{joint: {"x": (lo, hi)}}``)."""
        a = self.anatomy
        return {j: joint_ranges(role, a.sides[j]) for j, role in a.roles.items() if role != "root"}

    @cached_property
    def chains(self) -> tuple[tuple[int, ...], ...]:
        """Runs of two or more consecutive simulated joints (each the parent of the next) of
        one shared role, e.g. CMU's ``(Neck, Neck1, Head)``: one anatomical joint whose range
        (:attr:`hinge_ranges` of any of them) limits their total rotation (judged exactly by
        :mod:`sim.checks.joint_limits`; the MJCF limits the sum of their angles per axis)."""
        roles = self.anatomy.roles
        runs: dict[int, list[int]] = {}  # first joint of a run -> the run
        first: dict[int, int] = {}
        for j in self.body_order[1:]:
            p = int(self.skeleton.parents[j])
            if roles[j] == roles.get(p) and p in first and runs[first[p]][-1] == p:
                first[j] = first[p]
                runs[first[j]].append(j)
            elif is_shared(roles[j]):
                first[j] = j
                runs[j] = [j]
        return tuple(tuple(r) for r in runs.values() if len(r) > 1)

    @cached_property
    def subtree_mass(self) -> np.ndarray:
        """``(J,)`` mass (kg) of each joint's body plus everything below it."""
        mass = np.zeros(self.skeleton.n_joints)
        for s in self.segments:
            mass[s.body] += s.mass
        for j in range(self.skeleton.n_joints - 1, 0, -1):
            mass[self.skeleton.parents[j]] += mass[j]
        return mass

    def segment_masses(self) -> dict[str, float]:
        """Total mass per segment kind (both sides together for limbs)."""
        out: dict[str, float] = defaultdict(float)
        for s in self.segments:
            out[s.kind] += s.mass
        return dict(out)

    @cached_property
    def mesh_template(self):
        """Primitives tessellated in body frames (a :class:`~.mesh.MeshTemplate`)."""
        from avatarsim.avatar_models.body.mesh import mesh_template

        return mesh_template(self.segments)

    # -- outputs --------------------------------------------------------------------------
    @cached_property
    def spec(self):
        """The body's :class:`mujoco.MjSpec` (see :mod:`avatar_models.body.mjcf`), built once
        and shared: edit a ``spec.copy()`` (e.g. :func:`~avatar_models.body.control_spec`)."""
        from avatarsim.avatar_models.body.mjcf import body_spec

        return body_spec(self)

    @cached_property
    def model(self):
        """:attr:`spec` compiled once (a ``mujoco.MjModel``), shared by every user of the
        body: read it; simulations that change it work on their own copy."""
        return self.spec.compile()

    def to_mjcf(self) -> str:
        """MJCF XML of this body standing on a floor, for MuJoCo's viewer (MuJoCo writes 6
        significant digits: :attr:`model` is compiled from the spec, not from this text)."""
        return self.spec.to_xml()

    def qpos_from_motion(self, motion: Motion) -> np.ndarray:
        """``(T, nq)`` MuJoCo qpos for ``motion`` (see :mod:`avatar_models.body.qpos`)."""
        from avatarsim.avatar_models.body.qpos import qpos_from_motion

        return qpos_from_motion(self, motion)

    def to_trimesh(self, pose, global_rot: np.ndarray | None = None, frame: int = 0):
        """The body posed for one frame as a ``trimesh.Trimesh``.

        ``pose`` is either global joint positions ``(J, 3)`` with ``global_rot`` ``(J, 3, 3)``
        rotation matrices or ``(J, 4)`` wxyz quaternions, or a :class:`Motion` and ``frame``.
        """
        from avatarsim.avatar_models.body.mesh import posed_mesh

        return posed_mesh(self, pose, global_rot, frame)

    def scaled(
        self,
        height_m: float | None = None,
        segment_scale: Mapping[str, float] | None = None,
        mass_kg: float | None = None,
    ) -> BodyDescription:
        """A new body from the original skeleton with per-segment length factors (e.g.
        ``{"thigh": 1.05}``), then scaled uniformly to ``height_m``. Segment factors and
        mass are kept unless given; ``height_m=None`` keeps the skeleton's own size."""
        return build_body(
            self.source_skeleton,
            height_m=height_m,
            mass_kg=self.mass_kg if mass_kg is None else mass_kg,
            foot=self.foot,
            segment_scale=self.segment_scale if segment_scale is None else segment_scale,
        )


def build_body(
    skeleton: Skeleton,
    height_m: float | None = None,
    mass_kg: float = 75.0,
    foot: str = "box",
    segment_scale: Mapping[str, float] | None = None,
) -> BodyDescription:
    """Build the body of ``skeleton`` (any rig :func:`identify_rig` recognises).

    Args:
        skeleton: the rig's skeleton; its rest offsets are the bone lengths.
        height_m: stature to scale to uniformly (sole to top of skull); ``None`` keeps the
            skeleton's own size.
        mass_kg: total body mass, split over the segments by de Leva's fractions.
        foot: ``"box"`` or ``"capsule"``.
        segment_scale: length factor per segment kind (keys of
            :data:`avatar_models.body.anthropometry.SEGMENTS`), applied before ``height_m``.

    Raises:
        BodyError: unknown skeleton, height not in (0, 3] m, mass not positive, unknown foot
            shape or segment kind, non-positive scale factor, a rest pose that does not
            stand upright.
    """
    if not (np.isfinite(mass_kg) and mass_kg > 0):
        raise BodyError(f"body mass must be a positive number of kg, got {mass_kg!r}")
    if height_m is not None and not (np.isfinite(height_m) and 0 < height_m <= MAX_HEIGHT_M):
        raise BodyError(f"height must be in (0, {MAX_HEIGHT_M}] m, got {height_m!r}")
    if foot not in FOOT_SHAPES:
        raise BodyError(f"foot shape must be one of {FOOT_SHAPES}, got {foot!r}")
    scale = dict(segment_scale or {})
    for kind, factor in scale.items():
        if kind not in anthro.SEGMENTS:
            raise BodyError(f"unknown segment {kind!r}; known: {', '.join(anthro.SEGMENTS)}")
        if not (np.isfinite(factor) and factor > 0):
            raise BodyError(f"segment scale for {kind!r} must be positive, got {factor!r}")
    try:
        rig = identify_rig(skeleton)
    except RigError as exc:
        raise BodyError(f"cannot build a body: {exc}") from exc
    anatomy = classify(skeleton, rig)
    _check_upright(skeleton, anatomy)

    kind_factor = np.array([scale.get(k, 1.0) for k in anatomy.bone_kind])
    sized = skeleton.with_offsets(skeleton.offsets * kind_factor[:, None])
    if height_m is not None:
        sized = sized.scaled(height_m / Layout(sized, anatomy, scale).stature)
    layout = Layout(sized, anatomy, scale)
    segments = layout.segments(mass_kg, foot)
    lowest = min(s.lowest_z() + layout.rest[s.body, 2] for s in segments)
    return BodyDescription(
        skeleton=sized,
        rig=rig,
        mass_kg=float(mass_kg),
        foot=foot,
        segment_scale=scale,
        anatomy=anatomy,
        stature=layout.stature,
        segments=tuple(segments),
        root_height=-lowest,
        source_skeleton=skeleton,
    )


UPRIGHT_RATIO = 0.8


def _check_upright(skeleton: Skeleton, anatomy: Anatomy) -> None:
    """Raise unless the rest pose stands: the head must rise above each ankle by at least
    :data:`UPRIGHT_RATIO` of the bone path between them. Feet, skull and joint ranges are
    laid out in the rest frame, which is meaningless for rigs whose rest pose is not a
    standing pose (e.g. BVH files whose joint orientations are baked into the offsets)."""
    rest = skeleton.rest_positions()
    lengths = skeleton.bone_lengths
    head = anatomy.body17["head"]
    for side in ("l", "r"):
        ankle = anatomy.body17[f"{side}_ankle"]
        path = set(skeleton.chain(head)) ^ set(skeleton.chain(ankle))
        rise = rest[head, 2] - rest[ankle, 2]
        if rise < UPRIGHT_RATIO * lengths[list(path)].sum():
            raise RestPoseNotUprightError(
                f"the rest pose of skeleton {skeleton.name!r} is not upright (head "
                f"{rise:.3f} m above the {side} ankle along {lengths[list(path)].sum():.3f} m "
                "of bones); the body needs a rest pose that stands, Z up"
            )

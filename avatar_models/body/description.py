"""``BodyDescription``: one body, from a skeleton, for MuJoCo (MJCF) and for rendering (trimesh).

A capsule per bone between two simulated joints, a box (or capsule) per foot, a capsule per
hand and a sphere for the skull; masses and centres of mass from de Leva (1996), radii from
ANSUR II (see :mod:`avatar_models.body.anthropometry`); anatomical hinge ranges from
:mod:`avatar_models.body.joint_ranges`. Lengths come from the skeleton itself, so a motion on
the same skeleton replays exactly (:meth:`BodyDescription.qpos_from_motion`).
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import NamedTuple

import numpy as np

from avatar_models.body import anthropometry as anthro
from avatar_models.body.anatomy import Anatomy, classify
from avatar_models.body.errors import BodyError, RestPoseNotUprightError
from avatar_models.body.geometry import Segment
from avatar_models.body.joint_ranges import euler_order, is_shared, joint_ranges
from avatar_models.errors import RigError
from avatar_models.motion import Motion
from avatar_models.rigs import Rig, identify_rig
from avatar_models.skeleton import Skeleton

MAX_HEIGHT_M = 3.0
FOOT_SHAPES = ("box", "capsule")
CAPS_INSIDE = {"upper_arm": (True, False), "shank": (False, True)}
"""Segment kind -> (proximal, distal) caps that end at the joint rather than around it: the
upper arm does not start inside the chest (where it would touch the trunk in the rest pose
and have to be excluded from collisions with it), the shin never reaches below the foot."""


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
        from avatar_models.body.mesh import mesh_template

        return mesh_template(self.segments)

    # -- outputs --------------------------------------------------------------------------
    def to_mjcf(self) -> str:
        """MJCF XML of this body standing on a floor (see :mod:`avatar_models.body.mjcf`)."""
        from avatar_models.body.mjcf import body_mjcf

        return body_mjcf(self)

    def qpos_from_motion(self, motion: Motion) -> np.ndarray:
        """``(T, nq)`` MuJoCo qpos for ``motion`` (see :mod:`avatar_models.body.qpos`)."""
        from avatar_models.body.qpos import qpos_from_motion

        return qpos_from_motion(self, motion)

    def to_trimesh(self, pose, global_rot: np.ndarray | None = None, frame: int = 0):
        """The body posed for one frame as a ``trimesh.Trimesh``.

        ``pose`` is either global joint positions ``(J, 3)`` with ``global_rot`` ``(J, 3, 3)``
        rotation matrices or ``(J, 4)`` wxyz quaternions, or a :class:`Motion` and ``frame``.
        """
        from avatar_models.body.mesh import posed_mesh

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
        sized = sized.scaled(height_m / _Layout(sized, anatomy, scale).stature)
    layout = _Layout(sized, anatomy, scale)
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


class _FootFrame(NamedTuple):
    """A foot box in its ankle frame: heading about Z, heel (back) and toe tip (front) along
    the heading, sole (bottom) and top heights."""

    heading: float
    back: float
    front: float
    bottom: float
    top: float


class _Layout:
    """Rest-pose geometry of a skeleton: stature, head, feet, hands, bones, segments."""

    def __init__(self, skeleton: Skeleton, anatomy: Anatomy, scale: Mapping[str, float]):
        self.sk = skeleton
        self.an = anatomy
        self.scale = scale
        self.rest = skeleton.rest_positions()
        b = anatomy.body17
        head = b["head"]
        up = self.rest[head] - self.rest[skeleton.parents[head]]
        norm = np.linalg.norm(up)
        self.head_up = up / norm if norm > 1e-9 else np.array([0.0, 0.0, 1.0])
        frame_height = self.rest[head, 2] - self.rest[:, 2].min()
        rho = anthro.HEAD_RADIUS_RATIO
        # Skull top above the head joint: an end site above the head if the rig has one,
        # else a skull sphere resting on the head joint, 2 rho H with H = frame + 2 rho H.
        skull = 2 * rho * frame_height / (1 - 2 * rho) * scale.get("head", 1.0)
        tips = [j for j in range(skeleton.n_joints) if anatomy.body_of[j] == head and j != head]
        reach = max(((self.rest[j] - self.rest[head]) @ self.head_up for j in tips), default=0.0)
        self.head_extent = reach if reach >= 0.5 * skull else skull
        rough = frame_height + self.head_extent
        self.feet = {side: self._foot_frame(side, rough) for side in ("l", "r")}
        top = self.rest[head, 2] + self.head_extent * self.head_up[2]
        sole = min(self.rest[b[f"{s}_ankle"], 2] + f.bottom for s, f in self.feet.items())
        self.stature = float(top - sole)

    def _foot_frame(self, side: str, height: float) -> _FootFrame:
        """Where the foot of ``side`` (``"l"``/``"r"``) lies in its ankle frame: pointing at
        the toe joint; back to the rig's heel joint where it has one (the walk generator rolls
        the foot about it, so no sole may reach behind it), else a quarter of the ANSUR foot
        length behind the ankle; ANSUR foot length long, or up to the toe tip; top at the
        ankle, sole at the lowest foot joint but at least half a foot breadth below the
        ankle."""
        ankle = self.an.body17[f"{side}_ankle"]
        toe = self.rest[self.an.body17[f"{side}_foot"]] - self.rest[ankle]
        heading = float(np.arctan2(toe[1], toe[0])) if np.hypot(toe[0], toe[1]) > 1e-9 else 0.0
        fwd = np.array([np.cos(heading), np.sin(heading), 0.0])
        length = anthro.FOOT_LENGTH_RATIO * height * self.scale.get("foot", 1.0)
        foot_bodies = (ankle, self.an.body_of[self.an.body17[f"{side}_foot"]])
        inside = [j for j in range(self.sk.n_joints) if self.an.body_of[j] in foot_bodies]
        rel = self.rest[inside] - self.rest[ankle]
        heel = float((rel @ fwd).min(initial=0.0))
        back = heel if heel < 0.0 else -anthro.HEEL_FRACTION * length
        front = max(back + length, float((rel @ fwd).max(initial=0.0)))
        half_width = anthro.SEGMENTS["foot"].radius_ratio * height
        bottom = min(float(rel[:, 2].min(initial=0.0)), -half_width)
        return _FootFrame(heading, back, front, bottom, 0.0)

    # -- segments -------------------------------------------------------------------------
    def radius(self, kind: str, side: str = "center") -> float:
        """Capsule radius of a bone of ``kind``. Shoulder-girdle bones (torso bones off the
        midline) take the upper-arm radius, so they do not bury the upper arm."""
        if kind == "torso" and side != "center":
            kind = "upper_arm"
        return anthro.SEGMENTS[kind].radius_ratio * self.stature

    def segments(self, mass_kg: float, foot: str) -> list[Segment]:
        """All primitives with masses: each kind's de Leva mass (per side for limbs), split
        over its primitives in proportion to their volumes (uniform density in a segment)."""
        pieces = self._capsules() + self._hands() + self._feet(foot) + [self._skull()]
        groups: dict[tuple[str, str], list[Segment]] = defaultdict(list)
        for p in pieces:
            groups[(p.kind, "" if p.kind in anthro.SINGLE_SEGMENTS else p.side)].append(p)
        expected = {(k, "") for k in anthro.SINGLE_SEGMENTS} | {
            (k, s)
            for k in anthro.SEGMENTS
            if k not in anthro.SINGLE_SEGMENTS
            for s in ("left", "right")
        }
        missing = expected - set(groups)
        if missing:
            raise BodyError(
                f"skeleton {self.sk.name!r} has no bones for segments {sorted(missing)}"
            )
        out = []
        for (kind, _), group in groups.items():
            total = sum(p.volume() for p in group)
            share = anthro.SEGMENTS[kind].mass_fraction * mass_kg / total
            out.extend(replace(p, mass=share * p.volume()) for p in group)
        return out

    def _capsules(self) -> list[Segment]:
        """A capsule per bone between two simulated joints (zero-length bones have none),
        its CoM at de Leva's fraction from the proximal joint. Some caps end at their joint
        instead of around it (:data:`CAPS_INSIDE`)."""
        out = []
        for c in np.flatnonzero(self.an.simulated)[1:]:
            kind, side, bone = self.an.bone_kind[c], self.an.sides[c], self.sk.offsets[c]
            if kind == "foot":  # the foot is its boxes (ankle to toe joint), see _feet
                continue
            length = float(np.linalg.norm(bone))
            if length < 1e-9:
                continue
            r = self.radius(kind, side)
            inset = min(r / length, 0.5) * bone
            proximal, distal = CAPS_INSIDE.get(kind, (False, False))
            out.append(
                Segment(
                    name=f"{kind}:{self.sk.names[c]}",
                    kind=kind,
                    side=side,
                    body=int(self.sk.parents[c]),
                    shape="capsule",
                    start=inset if proximal else np.zeros(3),
                    end=bone - inset if distal else bone,
                    radius=r,
                    mass=0.0,
                    com=anthro.SEGMENTS[kind].com * bone,
                )
            )
        return out

    def _hands(self) -> list[Segment]:
        """A capsule from each wrist to the centroid of its children (the finger roots), or,
        without children, along the forearm by de Leva's hand/forearm length ratio."""
        out = []
        for s, side in (("l", "left"), ("r", "right")):
            wrist, elbow = self.an.body17[f"{s}_wrist"], self.an.body17[f"{s}_elbow"]
            children = self.sk.children(wrist)
            end = self.sk.offsets[children].mean(0) if children.size else np.zeros(3)
            forearm = self.rest[wrist] - self.rest[elbow]
            if np.linalg.norm(end) < 0.25 * anthro.HAND_LENGTH_RATIO * np.linalg.norm(forearm):
                end = forearm * anthro.HAND_LENGTH_RATIO * self.scale.get("hand", 1.0)
            out.append(
                Segment(
                    name=f"hand:{self.sk.names[wrist]}",
                    kind="hand",
                    side=side,
                    body=wrist,
                    shape="capsule",
                    start=np.zeros(3),
                    end=end,
                    radius=self.radius("hand"),
                    mass=0.0,
                    com=anthro.SEGMENTS["hand"].com * end,
                )
            )
        return out

    def _feet(self, shape: str) -> list[Segment]:
        """Per side a box (or a capsule) from heel to toe tip, top at the ankle, split at the
        ball of the foot when the toes have their own body: the hindfoot piece under the
        ankle, the toe piece under the toe joint, sharing one sole. de Leva's foot mass is
        spread at uniform density (:meth:`segments`), i.e. by length for boxes; the CoM of
        the whole foot stays at de Leva's fraction from the heel (:meth:`_with_foot_com`)."""
        out = []
        for s, side in (("l", "left"), ("r", "right")):
            ankle, toe = self.an.body17[f"{s}_ankle"], self.an.body17[f"{s}_foot"]
            f = self.feet[s]
            fwd = np.array([np.cos(f.heading), np.sin(f.heading), 0.0])
            r = 0.5 * (f.top - f.bottom)
            breaks = [f.back, f.front]
            bodies = [ankle]
            if self.an.simulated[toe]:
                breaks.insert(1, float(self.sk.offsets[toe] @ fwd))
                bodies.append(toe)
            pieces = []
            for body, back, front in zip(bodies, breaks[:-1], breaks[1:], strict=True):
                origin = self.rest[body] - self.rest[ankle]
                mid_z = np.array([0.0, 0.0, f.bottom + r]) - origin
                rear, fore = back * fwd + mid_z, front * fwd + mid_z
                common = dict(
                    name=f"foot:{self.sk.names[body]}", kind="foot", side=side, body=body, mass=0.0
                )
                if shape == "box":
                    centre = 0.5 * (rear + fore)
                    half = np.array([0.5 * (front - back), self.radius("foot"), r])
                    piece = Segment(
                        shape="box",
                        start=centre,
                        end=centre,
                        radius=float(half.min()),
                        half_extents=half,
                        heading=f.heading,
                        com=centre,
                        **common,
                    )
                else:
                    # The heel cap is centred over the heel, so the sole reaches the heel (the
                    # foot rolls about it); the toe cap ends at the toe tip.
                    start = rear
                    end = fore - r * fwd if front == f.front else fore
                    piece = Segment(
                        shape="capsule",
                        start=start,
                        end=end,
                        radius=r,
                        com=0.5 * (start + end),
                        **common,
                    )
                pieces.append(piece)
            out.extend(self._with_foot_com(pieces, f.back * fwd, f.front * fwd, ankle))
        return out

    def _with_foot_com(
        self, pieces: list[Segment], heel: np.ndarray, tip: np.ndarray, ankle: int
    ) -> list[Segment]:
        """Set the CoM of the first (hindfoot) piece so that the foot's CoM lies at de Leva's
        fraction from heel to toe tip (ankle frame, horizontal), the others at their centres.
        Masses follow volumes, as in :meth:`segments`."""
        volumes = np.array([p.volume() for p in pieces])
        weights = volumes / volumes.sum()
        origins = [self.rest[p.body] - self.rest[ankle] for p in pieces]
        target = heel + anthro.SEGMENTS["foot"].com * (tip - heel)
        target[2] = pieces[0].com[2]
        rest_of = sum(
            (w * (p.com + o) for w, p, o in zip(weights[1:], pieces[1:], origins[1:], strict=True)),
            np.zeros(3),
        )
        hind = (target - rest_of) / weights[0]
        return [replace(pieces[0], com=hind)] + pieces[1:]

    def _skull(self) -> Segment:
        """The skull sphere, its top at the head's extent along the neck direction."""
        r = anthro.HEAD_RADIUS_RATIO * self.stature * self.scale.get("head", 1.0)
        centre = self.head_up * (self.head_extent - r)
        return Segment(
            name="head:skull",
            kind="head",
            side="center",
            body=self.an.body17["head"],
            shape="sphere",
            start=centre,
            end=centre,
            radius=r,
            mass=0.0,
            com=centre,
        )

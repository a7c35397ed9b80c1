"""Rest-pose geometry of a skeleton for its body: stature, head, feet, hands, bones, and the
primitives (:class:`~avatar_models.body.geometry.Segment`) with their masses.

Capsules per bone, box or capsule feet split at the ball of the foot, hand capsules and a
skull sphere; masses and centres of mass from de Leva (1996), radii from ANSUR II (see
:mod:`avatar_models.body.anthropometry`). :func:`avatar_models.body.build_body` lays a
skeleton out with :class:`Layout`.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Mapping
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from avatarsim.avatar_models.body import anthropometry as anthro
from avatarsim.avatar_models.body.anatomy import Anatomy
from avatarsim.avatar_models.body.errors import BodyError
from avatarsim.avatar_models.body.geometry import Segment
from avatarsim.avatar_models.skeleton import Skeleton

CAPS_INSIDE = {"upper_arm": (True, False), "shank": (False, True)}
"""Segment kind -> (proximal, distal) caps that end at the joint rather than around it: the
upper arm does not start inside the chest (where it would touch the trunk in the rest pose
and have to be excluded from collisions with it), the shin never reaches below the foot."""


class FootFrame(NamedTuple):
    """A foot box in its ankle frame: heading about Z, heel (back) and toe tip (front) along
    the heading, sole (bottom) and top heights."""

    heading: float
    back: float
    front: float
    bottom: float
    top: float


class Layout:
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

    def _foot_frame(self, side: str, height: float) -> FootFrame:
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
        return FootFrame(heading, back, front, bottom, 0.0)

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

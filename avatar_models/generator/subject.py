"""Synthetic subjects: body size and proportions, tempo, amplitude and a movement style.

A :class:`Subject` scales the avatar rig per segment (:func:`subject_skeleton`) and modulates
every activity through its :class:`Style`. Segment factors vary around 1 with the spread of
adult anthropometry: a standard deviation of about 3 % of segment length relative to stature
(Drillis & Contini 1966; de Leva 1996, J. Biomech. 29(9), Table 1 ranges).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from functools import cache

import numpy as np

from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.avatar_models.skeleton import Skeleton

HEIGHT_RANGE_M = (1.5, 1.95)


@dataclass(frozen=True)
class Style:
    """How a style changes movement. Factors multiply the subject's own tempo and amplitude.

    Attributes:
        tempo: cadence factor (steps, strokes, punches per second).
        amplitude: range-of-motion factor (stride length, arm swing, punch reach, bounce).
        stoop_deg: extra forward flexion of the trunk, spread over the three spine joints.
        head_pitch_deg: extra head pitch (positive looks down).
        knee_bend: extra crouch, as a fraction of leg length the pelvis is lowered.
    """

    tempo: float = 1.0
    amplitude: float = 1.0
    stoop_deg: float = 0.0
    head_pitch_deg: float = 0.0
    knee_bend: float = 0.0


# Documented effects: "tired" is slow, small and slumped with the head down; "happy" is a bit
# quicker and bouncier with the chest up; "old" is slow, short-stepped, stooped and crouched;
# "energetic" is fast and large.
STYLES: dict[str, Style] = {
    "normal": Style(),
    "tired": Style(tempo=0.85, amplitude=0.8, stoop_deg=10.0, head_pitch_deg=12.0, knee_bend=0.01),
    "happy": Style(tempo=1.1, amplitude=1.15, stoop_deg=-4.0, head_pitch_deg=-6.0),
    "old": Style(tempo=0.88, amplitude=0.8, stoop_deg=16.0, head_pitch_deg=4.0, knee_bend=0.03),
    "energetic": Style(tempo=1.2, amplitude=1.25, stoop_deg=2.0, knee_bend=0.01),
}


@dataclass(frozen=True)
class Subject:
    """A synthetic performer.

    Attributes:
        height_m: standing height (floor to head top), 1.5 to 1.95 m.
        leg_factor, torso_factor, arm_factor: segment length factors around 1, applied before
            the whole body is scaled to ``height_m``.
        mass_kg: body mass (recorded for physics; does not change kinematics).
        tempo: personal speed factor around 1.
        amplitude: personal range-of-motion factor around 1.
        style: a key of :data:`STYLES`.
    """

    height_m: float = 1.75
    leg_factor: float = 1.0
    torso_factor: float = 1.0
    arm_factor: float = 1.0
    mass_kg: float = 70.0
    tempo: float = 1.0
    amplitude: float = 1.0
    style: str = "normal"

    def __post_init__(self) -> None:
        lo, hi = HEIGHT_RANGE_M
        if not lo <= self.height_m <= hi:
            raise MotionValueError(f"subject height {self.height_m} m is outside [{lo}, {hi}] m")
        if self.style not in STYLES:
            raise MotionValueError(f"unknown style {self.style!r}; known: {', '.join(STYLES)}")
        factors = (self.leg_factor, self.torso_factor, self.arm_factor, self.tempo, self.amplitude)
        if not all(0.5 <= f <= 1.5 for f in factors):
            raise MotionValueError(f"subject factors must lie in [0.5, 1.5], got {factors}")

    @property
    def effect(self) -> Style:
        """The style's effect with this subject's own tempo and amplitude folded in."""
        s = STYLES[self.style]
        return Style(
            s.tempo * self.tempo,
            s.amplitude * self.amplitude,
            s.stoop_deg,
            s.head_pitch_deg,
            s.knee_bend,
        )

    def as_dict(self) -> dict:
        return asdict(self)


def sample_subject(rng: np.random.Generator) -> Subject:
    """A random adult: height uniform in 1.5-1.95 m, BMI 19-29, factors within +-2 sd."""
    height = float(rng.uniform(*HEIGHT_RANGE_M))
    leg, torso, arm = np.clip(1.0 + 0.03 * rng.standard_normal(3), 0.94, 1.06)
    return Subject(
        height_m=height,
        leg_factor=float(leg),
        torso_factor=float(torso),
        arm_factor=float(arm),
        mass_kg=float(rng.uniform(19.0, 29.0) * height**2),
        tempo=float(rng.uniform(0.9, 1.1)),
        amplitude=float(rng.uniform(0.9, 1.1)),
        style=str(rng.choice(list(STYLES))),
    )


def rest_height(skeleton: Skeleton) -> float:
    """Standing height of a rest pose: highest minus lowest joint or site."""
    z = skeleton.rest_positions()[:, 2]
    return float(z.max() - z.min())


@cache
def _segment_groups() -> dict[str, np.ndarray]:
    """Joint masks of the avatar rig whose offsets belong to the legs, the arms, the torso."""
    sk = load_rig("avatar").skeleton
    leg_roots = [sk.index(f"Bip01 {s} Calf") for s in "LR"]
    arm_roots = [sk.index(f"Bip01 {s} Forearm") for s in "LR"]

    def below(roots: list[int]) -> np.ndarray:
        return np.array([any(r in sk.chain(j) for r in roots) for j in range(sk.n_joints)])

    legs, arms = below(leg_roots), below(arm_roots)
    return {"legs": legs, "arms": arms, "torso": ~(legs | arms)}


def subject_skeleton(subject: Subject) -> Skeleton:
    """The avatar rig scaled to ``subject``: segment factors first, then uniformly to its height.

    The root's rest offset is reset so that the lowest foot point of the rest pose is on the
    floor (z = 0) when the root sits at its rest offset.
    """
    sk = load_rig("avatar").skeleton
    groups = _segment_groups()
    factor = (
        groups["legs"] * subject.leg_factor
        + groups["arms"] * subject.arm_factor
        + groups["torso"] * subject.torso_factor
    )
    offsets = sk.offsets * factor[:, None]
    offsets[0] = 0.0
    scaled = sk.with_offsets(offsets)
    offsets *= subject.height_m / rest_height(scaled)
    offsets[0] = [0.0, 0.0, -sk.with_offsets(offsets).rest_positions()[:, 2].min()]
    return sk.with_offsets(offsets)

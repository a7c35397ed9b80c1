"""Built-in procedural motion generator: stylised activities for synthetic subjects.

Public API: :data:`ACTIVITIES`, :class:`Subject`, :data:`STYLES`, :func:`sample_subject`,
:func:`subject_skeleton`, :func:`generate`, :func:`generate_library`.

Method: each activity plans trajectories over all frames at once (planted feet that roll
heel-to-toe, swing arcs, pelvis bob and sway, hand targets, joint-angle curves); legs and,
where the hands have goals (punches, dribbling, rungs, waving), arms are solved by analytic
two-bone IK; the head is stabilised towards a planned gaze. See :mod:`.plan`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.avatar_models.generator import boxing, exercises, ladder, locomotion, study, swim
from avatarsim.avatar_models.generator.plan import Plan, Scene, realise
from avatarsim.avatar_models.generator.subject import (
    STYLES,
    Style,
    Subject,
    sample_subject,
    subject_skeleton,
)
from avatarsim.avatar_models.motion import Motion

_ACTIVITY_PLANS: dict[str, Callable[[Scene], Plan]] = {
    "walk": locomotion.walk,
    "run": locomotion.run,
    "box": boxing.box,
    "dribble": locomotion.dribble,
    "climb_ladder": ladder.climb_ladder,
    "swim": swim.swim,
    "arms": exercises.arms,
    "wave": exercises.wave,
    "squat": exercises.squat,
    "lunge": exercises.lunge,
    "kick": exercises.kick,
    "balance": exercises.balance,
    "controllerpose_study": study.controllerpose_study,
}
ACTIVITIES: tuple[str, ...] = tuple(_ACTIVITY_PLANS)

__all__ = [
    "ACTIVITIES",
    "STYLES",
    "Style",
    "Subject",
    "generate",
    "generate_library",
    "sample_subject",
    "subject_skeleton",
]


def generate(
    activity: str,
    subject: Subject | None = None,
    duration_s: float = 4.0,
    fps: float = 90.0,
    seed: int = 0,
) -> Motion:
    """A ``duration_s`` clip of ``activity`` at ``fps`` on ``subject``'s avatar skeleton.

    Deterministic: the same arguments give byte-identical arrays. ``meta`` holds
    ``activity``, ``seed``, ``subject`` (its parameters), ``generator`` and
    ``planned_contacts`` ``(T, 2)`` bool (left, right foot), plus activity facts such as
    ``rung_heights`` for the ladder.
    """
    if activity not in _ACTIVITY_PLANS:
        raise MotionValueError(f"unknown activity {activity!r}; known: {', '.join(ACTIVITIES)}")
    if not (np.isfinite(duration_s) and duration_s > 0 and np.isfinite(fps) and fps > 0):
        raise MotionValueError(f"duration and fps must be positive, got {duration_s!r}, {fps!r}")
    subject = Subject() if subject is None else subject
    n_frames = int(np.floor(duration_s * fps + 1e-9)) + 1
    # The seed jitters the start phase and small personal offsets inside each activity.
    scene = Scene(
        skeleton=subject_skeleton(subject),
        subject=subject,
        times=np.arange(n_frames) / fps + np.random.default_rng(seed).uniform(0.0, 2.0),
        rng=np.random.default_rng([seed, 1]),
    )
    plan = _ACTIVITY_PLANS[activity](scene)
    motion = realise(scene, plan)
    meta = {
        "generator": "avatarsim.avatar_models.generator",
        "activity": activity,
        "seed": int(seed),
        "subject": subject.as_dict(),
        "planned_contacts": plan.contacts.astype(bool),
        **plan.meta,
    }
    return motion.replace(fps=fps, meta=meta)


def generate_library(
    activities: Sequence[str] = ACTIVITIES,
    n_subjects: int = 4,
    duration_s: float = 4.0,
    fps: float = 90.0,
    seed: int = 0,
) -> list[Motion]:
    """Every activity for ``n_subjects`` sampled subjects (subject-major order), one seed each."""
    rng = np.random.default_rng(seed)
    subjects = [sample_subject(rng) for _ in range(n_subjects)]
    seeds = rng.integers(0, 2**31 - 1, size=(n_subjects, len(activities)))
    motions = []
    for i, subject in enumerate(subjects):
        for k, activity in enumerate(activities):
            motion = generate(activity, subject, duration_s, fps, int(seeds[i, k]))
            motions.append(motion.replace(meta={**motion.meta, "subject_id": i}))
    return motions

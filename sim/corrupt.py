"""The corruption suite: clean motions made physically wrong in one known way each.

Each generator returns a new :class:`Motion` on the same skeleton; the plausibility check
responsible for that defect must flag it (``tests/sim/test_corrupt.py``). Units: metres,
degrees only in argument names that say so. :func:`corrupt` applies one by the name of the
check that flags it; ``avatarsim check MOTION --corrupt DEFECT`` runs it on a user's motion,
to see that check fail.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.body import BodyDescription
from avatarsim.avatar_models.motion import Motion


def sink_feet(motion: Motion, depth_m: float = 0.10) -> Motion:
    """The whole motion lowered by ``depth_m``: the feet sink into the floor."""
    return motion.translated(np.array([0.0, 0.0, -depth_m]))


def float_body(motion: Motion, height_m: float = 0.15) -> Motion:
    """The whole motion raised by ``height_m``: the body floats above the floor."""
    return motion.translated(np.array([0.0, 0.0, height_m]))


def bend_knee(
    motion: Motion, body: BodyDescription, past_deg: float = 40.0, side: str = "l"
) -> Motion:
    """The ``side`` knee flexed ``past_deg`` beyond its flexion limit during the middle half
    of the clip (flexion is the knee hinge with the widest range)."""
    knee = body.anatomy.body17[f"{side}_knee"]
    order = body.hinge_order(knee)
    ranges = body.hinge_ranges[knee]
    axis = max(ranges, key=lambda a: ranges[a][1] - ranges[a][0])
    angles = quat.to_scipy(motion.local_rot[:, knee]).as_euler(order)
    n = motion.n_frames
    middle = slice(n // 4, max(n // 4 + 1, 3 * n // 4))
    angles[middle, order.lower().index(axis)] = ranges[axis][1] + np.radians(past_deg)
    local = motion.local_rot.copy()
    local[:, knee] = quat.from_scipy(Rotation.from_euler(order, angles))
    return motion.replace(local_rot=local)


def inject_sliding(motion: Motion, stance: np.ndarray, distance_m: float = 0.20) -> Motion:
    """The body drifts sideways (+Y) by ``distance_m`` during every run of ``stance (T,)``
    (a foot's contact frames), linearly over the run: that foot slides ``distance_m`` per
    stance while it should stay planted."""
    stance = np.asarray(stance, dtype=bool)
    edges = np.diff(np.concatenate([[0], stance.astype(np.int8), [0]]))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    rate = np.zeros(motion.n_frames)  # metres per frame, only inside stances
    for a, b in zip(starts, stops, strict=True):
        if b - a > 1:
            rate[a + 1 : b] = distance_m / (b - a - 1)
    drift = np.zeros((motion.n_frames, 3))
    drift[:, 1] = np.cumsum(rate)
    return motion.replace(root_pos=motion.root_pos + drift)


def add_jitter(motion: Motion, rng: np.random.Generator, sigma_m: float = 0.01) -> Motion:
    """White noise of ``sigma_m`` per axis on the root position every frame: high-frequency
    jitter as a noisy pose estimator produces."""
    noise = rng.normal(0.0, sigma_m, size=motion.root_pos.shape)
    return motion.replace(root_pos=motion.root_pos + noise)


DEFECTS = ("penetration", "floating", "joint_limits", "skating", "jitter")
"""The defects, named as the checks that flag them."""


def corrupt(
    defect: str,
    motion: Motion,
    body: BodyDescription,
    stance: np.ndarray,
    rng: np.random.Generator,
) -> Motion:
    """``motion`` with ``defect`` at each generator's default size (10 cm sunk, 15 cm up,
    knee 40 degrees past its limit, 20 cm slide per stance of ``stance (T,)``, 1 cm jitter).

    Raises:
        ValueError: an unknown defect.
    """
    if defect == "penetration":
        return sink_feet(motion)
    if defect == "floating":
        return float_body(motion)
    if defect == "joint_limits":
        return bend_knee(motion, body)
    if defect == "skating":
        return inject_sliding(motion, stance)
    if defect == "jitter":
        return add_jitter(motion, rng)
    raise ValueError(f"unknown defect {defect!r}; defects: {', '.join(DEFECTS)}")

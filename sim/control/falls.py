"""Fall criteria: when a controlled body has fallen or lost its reference.

A fall (after Peng et al. 2018, DeepMimic, whose episodes end when the character falls) is
the first frame where the head is below :attr:`ControlSettings.fall_head_ratio` of the
reference head height, or the root's up axis is tilted more than
:attr:`ControlSettings.fall_tilt_deg` away from the reference root's. A body that stays up
but loses the reference, its body17 sites on average more than
:attr:`ControlSettings.lost_error_m` from the reference's (the 0.5 m termination distance of
Luo et al. 2023, "Perpetual humanoid control"), has failed as well and counts as fallen there.
So does a frame after MuJoCo met a diverging simulation (``unstable``).

Shapes: ``T`` frames, ``nq`` MuJoCo size, 17 body17 sites.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.body17 import BODY17
from avatarsim.sim.control.settings import ControlSettings

HEAD = BODY17.index("head")
UP = np.array([0.0, 0.0, 1.0])


def up_axis(qpos: np.ndarray) -> np.ndarray:
    """``(T, 3)`` world direction of the root's local +Z in configurations ``qpos (T, nq)``."""
    return quat.rotate(qpos[:, 3:7], UP)


def tilt_deg(qpos: np.ndarray, qpos_ref: np.ndarray) -> np.ndarray:
    """``(T,)`` angle (degrees) between the root's up axes of ``qpos`` and ``qpos_ref
    (T, nq)``."""
    cos = np.sum(up_axis(qpos) * up_axis(qpos_ref), -1)
    return np.degrees(np.arccos(np.clip(cos, -1, 1)))


def fallen(
    settings: ControlSettings,
    qpos: np.ndarray,
    qpos_ref: np.ndarray,
    sites: np.ndarray,
    ref_sites: np.ndarray,
    unstable: np.ndarray,
) -> np.ndarray:
    """``(T,)`` whether each frame is fallen or lost (module docstring): ``qpos`` and
    ``qpos_ref (T, nq)``, body17 ``sites`` and ``ref_sites (T, 17, 3)``, ``unstable (T,)``
    (:meth:`sim.control.controller.Controller.unstable`)."""
    low = sites[:, HEAD, 2] < settings.fall_head_ratio * ref_sites[:, HEAD, 2]
    lost = np.linalg.norm(sites - ref_sites, axis=-1).mean(axis=1) > settings.lost_error_m
    return low | (tilt_deg(qpos, qpos_ref) > settings.fall_tilt_deg) | unstable | lost


def first_fall(fallen_frames: np.ndarray) -> int | None:
    """The first frame true in ``fallen_frames (T,)`` (:func:`fallen`), or ``None``."""
    frames = np.flatnonzero(fallen_frames)
    return int(frames[0]) if frames.size else None

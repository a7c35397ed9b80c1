"""Accuracy of a synthesiser as CoolMoves §4.1 measures it (the protocols that use it live in
:mod:`synthesis.evaluate`).

- Error: mean Euclidean distance (cm) between output and ground-truth ``body17`` joints,
  grouped as the paper groups them (hands; upper body = head, neck, arms; lower body =
  pelvis, legs, feet; full body), averaged over frames.
- Hand correlation: Pearson coefficient between the input and the output hands, "X, Y and Z
  positions of the hands as independent time series ... for the entire session", averaged
  over the three axes. We correlate head-relative positions (controller minus headset, the
  signal CoolMoves is given) so that walking forward cannot inflate the number. An axis along
  which the input hand does not move (standard deviation under ``STILL_AXIS_M``, e.g. the
  lateral axis of a generated ladder climb) has no defined coefficient and is left out of
  the mean; otherwise millimetre wobble of the output against a constant input reads as
  "no correlation".
- Both skip the first ``window - 1`` frames (89 ms), before the first full window exists,
  when any window-based method can only show a default pose.
"""

from __future__ import annotations

import numpy as np

from avatar_models import Motion, body17
from avatar_models.rigs import body17_positions
from render_cams import TrackingStream, VRSetup
from render_cams.device import motion_at_rate
from synthesis.base import SynthesisError, Synthesizer, on_clock, usable_mask
from synthesis.coolmoves import foot_contact
from synthesis.coolmoves.correlation import pearson
from synthesis.coolmoves.database import HANDS_DRIVE, Drivers, driver_positions
from synthesis.coolmoves.features import WINDOW_SAMPLES

PAPER_ACTIVITIES = ("box", "dribble", "climb_ladder", "run", "swim")
"""The generator's counterparts of the paper's Table 1 (boxing, basketball, climbing a ladder,
running, swimming)."""

WARM_UP = WINDOW_SAMPLES - 1
_ANKLES = ("l_ankle", "r_ankle")
STILL_AXIS_M = 1e-3
"""An input hand axis with less spread than this (1 mm) does not move (our choice)."""
_GROUPS = {
    "hands": body17.HANDS,
    "upper": body17.UPPER,
    "lower": body17.LOWER,
    "full": body17.BODY17,
}


def body17_errors_cm(output: Motion, truth: Motion, skip: int = WARM_UP) -> dict[str, float]:
    """Mean joint error in cm per group over the frames both motions have (at 90 Hz),
    after the first ``skip``."""
    truth = motion_at_rate(truth, output.fps)
    n = min(output.n_frames, truth.n_frames)
    err = np.linalg.norm(body17_positions(output)[:n] - body17_positions(truth)[:n], axis=-1)
    err = err[min(skip, n - 1) :]
    per_joint = 100.0 * err.mean(axis=0)
    return {g: float(per_joint[body17.group_indices(names)].mean()) for g, names in _GROUPS.items()}


def hand_correlation(
    output: Motion, stream: TrackingStream, drivers: Drivers = HANDS_DRIVE, skip: int = WARM_UP
) -> dict[str, float]:
    """Pearson correlation of input and output head-relative hands, mean over x, y, z."""
    clocked = on_clock(stream)
    idx = [clocked.device(d) for d in drivers.devices]
    ok = usable_mask(clocked)[:, idx].all(axis=1)
    n = min(output.n_frames, clocked.n_samples)
    ok = ok[:n].copy()
    ok[:skip] = False
    if ok.sum() < 3:
        raise SynthesisError(
            f"hand correlation needs at least 3 tracked frames after the first {skip} "
            f"(window warm-up); this stream has {int(ok.sum())}: use a longer clip"
        )
    given = clocked.positions[:n, idx[1:]] - clocked.positions[:n, idx[:1]]
    head, sides = driver_positions(output[:n], drivers)
    produced = sides - head[:, None]
    r = pearson(given[ok], produced[ok], axis=0)  # (2, 3)
    moving = np.std(given[ok], axis=0) >= STILL_AXIS_M
    mean = np.sum(r * moving, axis=1) / np.maximum(moving.sum(axis=1), 1)
    return {"left": float(mean[0]), "right": float(mean[1])}


def stance_skating_cm_s(output: Motion, standing_ankle_z: float) -> float:
    """Mean horizontal ankle speed (cm/s) over the frames where ``output``'s own ankles are in
    contact (:func:`~.foot_contact.contacts`, the UHC/PhysDiff height and velocity test against
    the ankles' standing height ``standing_ankle_z``, e.g.
    :attr:`CoolMoves.standing_ankle_height`)."""
    ankles = body17_positions(output)[:, body17.group_indices(_ANKLES)]
    contact = foot_contact.contacts(ankles, standing_ankle_z, output.fps)
    return foot_contact.skating_cm_s(ankles, contact, output.fps)


def evaluate(
    synthesizer: Synthesizer, truth: Motion, setup: VRSetup | None = None, seed: int = 0
) -> dict:
    """Errors and hand correlation of ``synthesizer`` on ``truth`` seen through ``setup``."""
    stream = (setup or VRSetup()).sample(truth, seed=seed)
    output = synthesizer.run(stream)
    return {
        "err_cm": body17_errors_cm(output, truth),
        "hand_corr": hand_correlation(output, stream),
        "frames": output.n_frames,
    }

"""Where MoveBox's body17 error comes from, per real clip (why CMU runs score several times
worse than the first Bandai clips).

    PYTHONPATH=. .venv/bin/python -m tests.measurements.movebox_error_sources \
        [SENSOR] CLIP.bvh...

Per clip (8 s at most, at 30 Hz, filmed on its humanoid as ``eval movebox`` does, seed 0):
``trk`` the share of Kinect frames tracking every body17 joint, ``root`` the share with the
spine base Tracked; ``kin`` the noisy Kinect joints' error (tracked frames); ``clean`` the
retargeting alone, noise-free, on the avatar MoveBox drives (every frame), ``uniform`` (unif) the
same on the paper's height-resized avatar; ``noisy`` the retargeting of the noisy stream
(tracked frames); then the whole method at 90 Hz: ``all`` every tick, ``tracked`` the ticks
showing a tracked frame, ``tau0`` without smoothing, ``rootrel`` pelvis-relative; ``v`` the
mean root speed (m/s). Errors: full-body body17, cm.

Measured (Kinect V2 unless "Az"; seed 0; the paper's smoothing, rotations only; ``clean``
0.0-0.1 on Bandai, whose avatar is sized to the clip segment by segment, 3.6-5.5 on CMU,
whose avatar is only resized to its height):

    clip        trk  root   kin clean  unif noisy    all tracked  tau0 rootrel   v
    06_06      0.61  0.91   3.2   5.2   5.2   6.3    9.5    7.0   9.2     8.1  1.19
    09_01      0.30  0.86   3.1   5.2   5.2   6.8   18.4    9.4  17.9    10.5  3.57
    102_01     0.23  0.53   3.2   3.6   3.6   5.3   99.3    8.7  98.6    18.1  2.11
    125_01     0.65  0.94   3.2   4.8   4.8   5.9    7.5    6.8   7.5     7.4  0.45
    126_01     0.00  0.92     -   4.9   4.9     -   13.6      -  13.7    13.1  0.07
    13_33      0.60  0.88   3.2   5.3   5.3   6.4    8.2    6.6   8.3     8.3  0.17
    14_33      0.95  1.00   3.2   5.0   5.0   6.1    6.1    6.0   6.1     6.2  0.17
    16_35      0.41  1.00   3.3   4.3   4.3   6.0    8.4    7.6   8.1     7.5  2.78
    35_17      0.43  0.83   3.1   5.5   5.5   6.6   22.8    8.6  22.3    10.8  3.18
    b1 run     0.79  1.00   3.3   0.0   3.2   3.8    6.2    6.3   5.6     5.0  2.61
    b2 walk    0.22  0.38   3.1   0.0   3.0   4.5  200.4    5.7 200.3    12.8  1.12
    b1 bow     0.41  0.75   3.3   0.1   3.2   3.9   18.5    4.0  19.2    17.8  0.14
    b2 raise   1.00  1.00   3.1   0.1   4.0   3.7    4.4    4.4   3.9     4.7  0.07
    16_35 Az   0.29  0.85   2.2   4.2   4.2   4.6   21.2    6.7  20.6     9.1  2.78

Where it enters: (1) ``all`` against ``tracked``: a performer leaving the view or range
(running, a basketball drive, a long walk) is NotTracked and MoveBox holds the pose where
they left, so the error grows with the distance run (102_01: 99 cm, 8.7 cm while tracked);
(2) ``tracked`` against ``noisy``: at 2.6-3.6 m/s the 30 Hz sample-and-hold costs 1-3 cm (the
paper smooths rotations only; smoothing the root too, the option ``smooth_root``, lags it
~50 ms and costs 5-9 cm: 16_35 tracked 12.0, 35_17 13.4, 09_01 15.6);
(3) ``clean``: the avatar's proportions against CMU's (4-5.5 cm; 3-4 on Bandai with the same
height-only resize, unif); (4) ``kin``: the sensor's joint noise, 2-3.3 cm everywhere.
(b1/b2: Bandai dataset-1/2 ``run_normal_001``, ``walk_normal_001``, and the first clip of
each folder, which ``eval movebox`` takes: ``bow_active_001``, ``raise-up-both-hands_active_001``.)
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from avatarsim.avatar_models import Motion
from avatarsim.avatar_models.formats import load_motion
from avatarsim.avatar_models.measure import standing_height
from avatarsim.avatar_models.rigs import body17_positions, load_rig
from avatarsim.render_cams.device import motion_at_rate
from avatarsim.render_cams.kinect import TrackingState, kinect_skeleton
from avatarsim.render_cams.vr import VRSetup
from avatarsim.scripts.movebox_eval import (
    body17_err_cm,
    body17_tracked,
    kinect_err_cm,
    retargeted,
    shown_tracked,
)
from avatarsim.sim.humanoid import humanoid_for
from avatarsim.synthesis.base import on_clock
from avatarsim.synthesis.movebox import MoveBox
from avatarsim.synthesis.movebox.resize import avatar_for, resized
from avatarsim.synthesis.scoring import body17_errors_cm

MAX_S = 8.0


def pelvis_relative(motion: Motion) -> Motion:
    """``motion`` with its root held at the origin (the pose without the translation)."""
    return Motion(motion.skeleton, motion.fps, np.zeros_like(motion.root_pos), motion.local_rot)


def clip_row(path: Path, sensor: str) -> dict:
    motion = load_motion(path)
    motion = motion[: min(motion.n_frames, int(MAX_S * motion.fps) + 1)]
    truth = motion.resample(30.0) if motion.fps > 30.0 else motion
    humanoid = humanoid_for(truth)
    film = (humanoid.motion, sensor)
    clean = kinect_skeleton(*film, seed=0, noise=None, body=humanoid.body)
    noisy = kinect_skeleton(*film, seed=0, body=humanoid.body)
    truth30 = motion_at_rate(truth, 30.0)
    tracked = body17_tracked(noisy)
    every = np.ones_like(tracked)
    height = standing_height(humanoid.motion)
    target = avatar_for(humanoid.body.skeleton, height)
    uniform = resized(load_rig("avatar").skeleton, height)
    stream = VRSetup().sample(truth, seed=0)
    out = MoveBox(noisy, target).run(stream)
    shown = shown_tracked(noisy, on_clock(stream).timestamps)
    root = load_rig(noisy.rig).body17_indices()[2]
    speed = np.diff(body17_positions(motion_at_rate(truth, 90.0))[:, 2, :2], axis=0)
    full = "full"
    return {
        "clip": path.name,
        "sensor": sensor,
        "trk": round(float(tracked.mean()), 2),
        "root": round(float(np.mean(noisy.states[:, root] == TrackingState.TRACKED)), 2),
        "kin": kinect_err_cm(noisy, truth30, tracked) if tracked.any() else None,
        "clean": body17_err_cm(retargeted(clean, target, "rest"), truth30, every),
        "uniform": body17_err_cm(retargeted(clean, uniform, "rest"), truth30, every),
        "noisy": body17_err_cm(retargeted(noisy, target, "rest"), truth30, tracked)
        if tracked.any()
        else None,
        "all": body17_errors_cm(out, truth)[full],
        "tracked": body17_errors_cm(out, truth, frames=shown)[full],
        "tau0": body17_errors_cm(MoveBox(noisy, target, tau_s=0.0).run(stream), truth)[full],
        "rootrel": body17_errors_cm(pelvis_relative(out), pelvis_relative(truth))[full],
        "v": float(np.linalg.norm(speed, axis=-1).mean() * 90.0),
    }


def main() -> None:
    args = sys.argv[1:]
    sensor = args.pop(0) if args and not args[0].endswith(".bvh") else "kinect-v2"
    for path in args:
        row = clip_row(Path(path), sensor)
        print(json.dumps({k: round(v, 2) if isinstance(v, float) else v for k, v in row.items()}))


if __name__ == "__main__":
    main()

"""How often a controller's composite sees the user (ControllerPose §3-4: the hands are in
front 68.3 % of the time; beside the body the cameras do not see it, Fig. 17).

A view is *usable* when a controller's composite has at least 12 of the 17 body17 joints
inside it and unoccluded (the rendered range image, :mod:`avatarsim.render_cams.fisheye.
line_of_sight`). Per built-in activity (4 s, 30 Hz, seeds 0 and 1, half-size images): the share
of frames where either controller's view is usable, where a hand is at least 30 cm ahead of
the body centre line (:func:`avatarsim.render_cams.hand_location.hand_measures`), and, for
those frames, the share with a usable view of that hand's controller. With ``--blazepose``, also the
share of those frames where MediaPipe BlazePose
finds a person in that composite (full-size images).

    python tests/measurements/controller_views.py [--blazepose] [ACTIVITY ...]
"""

from __future__ import annotations

import sys

import numpy as np

from avatarsim.avatar_models.generator import ACTIVITIES, generate
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams.fisheye.device import FisheyeRig
from avatarsim.render_cams.fisheye.rig import camera_pairs
from avatarsim.render_cams.hand_location import hand_measures

USABLE_JOINTS = 12
AHEAD_M = 0.30
SEEDS = (0, 1)


def measure(activity: str, seed: int, blazepose=None) -> dict[str, np.ndarray]:
    motion = generate(activity, duration_s=4.0, fps=30, seed=seed)
    scale = 1.0 if blazepose else 0.5
    rec = FisheyeRig(scale=scale, bad_frame_rate=0.0).sample(motion, seed)
    usable, ahead, person = {}, {}, {}
    in_front = hand_measures(body17_positions(motion), AHEAD_M)[0]  # (T, 2) left, right
    for controller, pair in camera_pairs(rec.cameras).items():
        comp = rec.views[controller].composite
        usable[controller] = (comp.in_image & comp.visible).sum(axis=1) >= USABLE_JOINTS
        ahead[controller] = in_front[:, 0 if controller.startswith("left") else 1]
        if blazepose is not None:
            params = rec.views[controller].params
            person[controller] = np.array(
                [
                    blazepose.detect(params.stitch([rec.images[c, t] for c in pair])).person
                    if ahead[controller][t]
                    else False
                    for t in range(motion.n_frames)
                ]
            )
    return {"usable": usable, "ahead": ahead, "person": person}


def main(argv: list[str]) -> None:
    detector = None
    if "--blazepose" in argv:
        from avatarsim.render_cams.fisheye.blazepose import BlazePoseDetector

        detector = BlazePoseDetector()
    print(
        "| activity | frames | usable view (either hand) | hand >= 30 cm ahead "
        "| usable when ahead |" + (" person found when ahead |" if detector else "")
    )
    for activity in [a for a in argv if not a.startswith("--")] or ACTIVITIES:
        any_usable, ahead_n, ahead_ok, found = [], 0, 0, 0
        for seed in SEEDS:
            m = measure(activity, seed, detector)
            any_usable.append(np.logical_or(*m["usable"].values()))
            for c in m["usable"]:
                ahead_n += int(m["ahead"][c].sum())
                ahead_ok += int((m["ahead"][c] & m["usable"][c]).sum())
                if detector:
                    found += int(m["person"][c].sum())
        frames = np.concatenate(any_usable)
        row = f"| {activity} | {frames.size} | {frames.mean():.0%} | {ahead_n} | " + (
            f"{ahead_ok / ahead_n:.0%} |" if ahead_n else "- |"
        )
        if detector:
            row += f" {found / ahead_n:.0%} |" if ahead_n else " - |"
        print(row, flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])

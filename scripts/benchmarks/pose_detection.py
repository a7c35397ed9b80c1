"""The real 2D detector on the rendered pixels, part of ``avatarsim bench sensing``
(ControllerPose §4.3; MediaPipe BlazePose standing in for the paper's OpenPose v1.7).

Per view kind and clip: the person rate (images where it finds a person, of those with at
least 4 joints in the image), the median keypoint error in pixels against the exact
projections, and PCK@0.2 of torso height (:mod:`render_cams.fisheye.pck`; a missed person or
joint counts as wrong; also up to a whole-body left/right swap), each next to the
``"error-model"`` approximation on the same images.
View kinds:

- ``raw camera``: each controller camera's fisheye image (640 x 480) that the image filter
  kept;
- ``composite``: each controller's stitched composite (§4.2);
- ``torso view``: the composite warped by the 4-point transform of the *detected* shoulders
  and hips, detected again (:func:`render_cams.fisheye.pixel_views.pixel_views`), its
  keypoints mapped back into the composite and scored there, on the frames with a torso view;
  the ``torso view gain`` row is its PCK minus the composite's on those same frames (§4.3
  claims the view makes the lower body "more proportionally correct");
- ``third person``: a pinhole camera 3 m in front of the body
  (:mod:`render_cams.third_person`), the control.

Clips: the built-in ControllerPose study activity (from 10 s), a built-in walk, and one
real clip of each source in the mocap folder (``bench --mocap``:
CMU basketball 06_06 from 1 s, after its T-pose; Bandai ``punch_normal_001``, hands in front of
the face), each seen through the simulated cameras. The time per image is BlazePose's on one core
(the process pinned to one CPU), on a 640 x 480 image with and without a person.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path

import numpy as np

from avatarsim.avatar_models import Motion
from avatarsim.avatar_models.body17 import BODY17
from avatarsim.avatar_models.formats import load_motion
from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams.device import motion_at_rate
from avatarsim.render_cams.fisheye.blazepose import BlazePoseDetector
from avatarsim.render_cams.fisheye.detector import MIN_PERSON_JOINTS, ErrorModelDetector
from avatarsim.render_cams.fisheye.device import FisheyeRig
from avatarsim.render_cams.fisheye.pck import keypoint_errors, mirror_tolerant, pck
from avatarsim.render_cams.fisheye.pixel_views import pixel_views
from avatarsim.render_cams.fisheye.pose2d import composite_keypoints
from avatarsim.render_cams.fisheye.pose_detector import PoseDetector, ViewTruth
from avatarsim.render_cams.fisheye.rig import camera_pairs
from avatarsim.render_cams.fisheye.stitch import stitch_params
from avatarsim.render_cams.scene import BodyScene
from avatarsim.render_cams.third_person import render_third_person
from avatarsim.scripts.benchmarks import BenchRow
from avatarsim.sim.humanoid import humanoid_for

CAMERA_FPS = 30.0
# clip name -> (built-in activity or path under the mocap folder, start s)
CLIPS: dict[str, tuple[str, float]] = {
    "study": ("builtin:controllerpose_study", 10.0),
    "walk": ("builtin:walk", 1.0),
    "cmu 06_06": ("cmu/06_06.bvh", 1.0),
    "bandai punch": ("bandai/dataset-1/data/dataset-1_punch_normal_001.bvh", 0.0),
}
KINDS = ("raw camera", "composite", "torso view", "third person")
TIMING_REPEAT = 10


def clip_motion(
    source: str, start_s: float, duration_s: float, mocap: Path | None
) -> Motion | None:
    """``duration_s`` of a clip from ``start_s`` at the cameras' 30 Hz; None for a mocap
    file that is absent (or no mocap folder)."""
    if source.startswith("builtin:"):
        motion = generate(source[8:], duration_s=start_s + duration_s, fps=CAMERA_FPS)
    else:
        path = None if mocap is None else mocap / source
        if path is None or not path.is_file():
            return None
        motion = load_motion(path)
    first = int(round(start_s * motion.fps))
    return motion_at_rate(motion[first : first + int(round(duration_s * motion.fps))], CAMERA_FPS)


class Scores:
    """Per view kind, what each detector scored on each image."""

    def __init__(self) -> None:
        self.rows: dict[tuple[str, str], list[tuple]] = {}

    def add(self, kind: str, name: str, report, truth: ViewTruth, extra=None) -> None:
        in_view = int(truth.in_image.sum()) >= MIN_PERSON_JOINTS
        self.rows.setdefault((kind, name), []).append(
            (
                in_view,
                report.person,
                keypoint_errors(report, truth),
                pck(report, truth),
                extra,
                pck(mirror_tolerant(report, truth), truth),
            )
        )

    def summary(self, kind: str, name: str) -> dict:
        """``images`` (with >= 4 joints in view), ``person_rate``, ``error_px`` (median over
        reported joints), ``joint_error_px`` ``(17,)`` (NaN: never reported) and ``pck``."""
        rows = [r for r in self.rows.get((kind, name), []) if r[0]]
        errors = np.array([r[2] for r in rows]).reshape(-1, len(BODY17))
        reported = np.isfinite(errors)
        pairs = zip(errors.T, reported.T, strict=True)
        joint = [np.median(e[k]) if k.any() else np.nan for e, k in pairs]
        return {
            "images": len(rows),
            "person_rate": float(np.mean([r[1] for r in rows])) if rows else np.nan,
            "error_px": float(np.median(errors[reported])) if reported.any() else np.nan,
            "joint_error_px": np.array(joint),
            "pck": float(np.nanmean([r[3] for r in rows])) if rows else np.nan,
            "pck_mirror": float(np.nanmean([r[5] for r in rows])) if rows else np.nan,
        }


def score_clip(motion: Motion, detectors: dict[str, PoseDetector], seed: int) -> Scores:
    """Render ``motion`` through the controller cameras and the third-person camera and score
    every detector on every view kind (module docstring)."""
    humanoid = humanoid_for(motion)
    rig = FisheyeRig(detector=None)
    recording = rig.sample(humanoid.motion, seed, humanoid.body)
    n_cams, n_frames = recording.images.shape[:2]
    rec = np.array(recording.records, dtype=object).reshape(n_frames, n_cams)
    uv, in_image, visible, score = (
        np.array([[r[key] for r in row] for row in rec], dtype)
        for key, dtype in (
            ("keypoints_px", float),  # (T, C, 17, 2)
            ("in_image", bool),  # (T, C, 17)
            ("visible", bool),
            ("confidence", float),
        )
    )
    usable = ~recording.filtered.T  # (T, C)
    rng = np.random.default_rng(seed)
    scores = Scores()
    for t in range(n_frames):
        for c in range(n_cams):
            if not usable[t, c]:
                continue
            truth = ViewTruth(uv[t, c], in_image[t, c], visible[t, c], score[t, c])
            for name, detector in detectors.items():
                report = detector.detect(recording.images[c, t], truth, rng)
                scores.add("raw camera", name, report, truth)
    for pair in camera_pairs(recording.cameras).values():
        params = stitch_params(recording.model, [recording.cameras[c] for c in pair])
        comp = composite_keypoints(
            params, *(a[:, pair] for a in (uv, in_image, visible, score, usable))
        )
        for t in range(n_frames):
            image = params.stitch([recording.images[c, t] for c in pair], usable[t, pair])
            truth = ViewTruth(comp.uv[t], comp.in_image[t], comp.visible[t], comp.score[t])
            for name, detector in detectors.items():
                views = pixel_views(image, truth, detector, rng)
                torso = bool(views.torso.valid)
                first = np.nanmean(pck(views.composite_detection, truth))
                scores.add("composite", name, views.composite_detection, truth)
                if torso:
                    back = replace(views.torso_detection, uv=views.torso_in_composite)
                    scores.add("torso view", name, back, truth, extra=first)
    joints = body17_positions(humanoid.motion)
    with BodyScene(humanoid.body) as scene:
        for t in range(humanoid.motion.n_frames):
            scene.update(humanoid.motion, t)
            image, truth = render_third_person(scene, joints[t])
            for name, detector in detectors.items():
                scores.add("third person", name, detector.detect(image, truth, rng), truth)
    return scores


@contextmanager
def one_core() -> Iterator[None]:
    """Pin this process to one CPU (threads created inside inherit it)."""
    before = os.sched_getaffinity(0)
    os.sched_setaffinity(0, {min(before)})
    try:
        yield
    finally:
        os.sched_setaffinity(0, before)


def timing_rows(person_image: np.ndarray, truth: ViewTruth) -> list[BenchRow]:
    """BlazePose's time per 640 x 480 image on one core, with and without a person, next to
    the error model's."""
    empty = np.full_like(person_image, 150)
    rows = []
    with one_core(), BlazePoseDetector() as blazepose:
        error_model = ErrorModelDetector()
        rng = np.random.default_rng(0)
        for label, image in (("with a person", person_image), ("without a person", empty)):
            ms = {}
            for name, detector in (("blazepose", blazepose), ("error-model", error_model)):
                detector.detect(image, truth, rng)  # warm-up
                start = time.perf_counter()
                for _ in range(TIMING_REPEAT):
                    detector.detect(image, truth, rng)
                ms[name] = 1e3 * (time.perf_counter() - start) / TIMING_REPEAT
            rows.append(
                BenchRow(
                    f"BlazePose per 640x480 image {label}, one core",
                    "ms",
                    ms["blazepose"],
                    ms["error-model"],
                    "error-model",
                    f"mean of {TIMING_REPEAT}; BlazePose stands in for OpenPose v1.7",
                )
            )
    return rows


def fmt_joints(errors: np.ndarray) -> str:
    return ", ".join(
        f"{n} {e:.0f}" if np.isfinite(e) else f"{n} -" for n, e in zip(BODY17, errors, strict=True)
    )


def clip_rows(clip: str, scores: Scores) -> list[BenchRow]:
    rows = []
    for kind in KINDS:
        real, model = scores.summary(kind, "blazepose"), scores.summary(kind, "error-model")
        if not real["images"]:
            rows.append(BenchRow(f"BlazePose {kind} person rate [{clip}]", "share", 0.0,
                                 note="no image with 4 joints in view"))  # fmt: skip
            continue
        n = f"{real['images']} images with >= 4 joints in view"
        rows += [
            BenchRow(f"BlazePose {kind} person rate [{clip}]", "share", real["person_rate"],
                     model["person_rate"], "error-model", n),
            BenchRow(f"BlazePose {kind} keypoint error median [{clip}]", "px", real["error_px"],
                     model["error_px"], "error-model",
                     "per joint: " + fmt_joints(real["joint_error_px"])),
            BenchRow(f"BlazePose {kind} PCK@0.2 torso [{clip}]", "share", real["pck"],
                     model["pck"], "error-model"),
            BenchRow(f"BlazePose {kind} PCK@0.2 torso up to a left/right swap [{clip}]",
                     "share", real["pck_mirror"], model["pck_mirror"], "error-model",
                     "the report or its mirror, whichever scores better"),
        ]  # fmt: skip
    torso = [r for r in scores.rows.get(("torso view", "blazepose"), []) if r[0]]
    if torso:
        gain = np.mean([np.nanmean(r[3]) - r[4] for r in torso])
        rows.append(
            BenchRow(
                f"BlazePose torso view gain in PCK@0.2 over the composite [{clip}]",
                "share",
                float(gain),
                note=f"on the {len(torso)} composites with a torso view (ControllerPose §4.3)",
            )
        )
    return rows


def run(quick: bool = False, mocap: Path | None = None) -> list[BenchRow]:
    duration_s = 0.3 if quick else 1.0
    rows: list[BenchRow] = []
    with BlazePoseDetector() as blazepose:
        detectors = {"blazepose": blazepose, "error-model": ErrorModelDetector()}
        for clip, (source, start_s) in CLIPS.items():
            motion = clip_motion(source, start_s, duration_s, mocap)
            if motion is None:
                rows.append(BenchRow(f"BlazePose [{clip}]", "", 0.0, note=f"{source} absent"))
                continue
            rows += clip_rows(clip, score_clip(motion, detectors, seed=0))
    walk = generate("walk", duration_s=1.0, fps=CAMERA_FPS)
    with BodyScene(walk.skeleton) as scene:
        scene.update(walk, 15)
        image, truth = render_third_person(scene, body17_positions(walk)[15])
    return rows + timing_rows(image, truth)

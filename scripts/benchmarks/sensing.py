"""Honest-sensing measurements, ``avatarsim bench sensing`` (ControllerPose §4.2-4.3).

- the image filter's precision and recall per defect: the analog faults it was designed for
  and three it was not (motion blur, the other hand filling the view, saturation), injected
  at 15 % into rendered frames over seeds 0-5;
- the detector error model's keypoint error against the exact projections, in pixels at the
  paper's 640 x 480, per camera, on the composite and in the torso-normal view, with its miss
  and swap shares;
- the composite's coverage (185 x 150 deg, baseline: the former 130 deg-wide composite);
- the real 2D detector (MediaPipe BlazePose, standing in for OpenPose v1.7) on the rendered
  raw camera images, composites, torso-normal views and a third-person control view
  (:mod:`scripts.benchmarks.pose_detection`);
- time per recorded frame (four cameras) with the filter, detector and composite views, against
  the same rig without the detector (the exact keypoints the records held before), and the
  stitch time per composite against the 130 deg-wide one.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from avatarsim.avatar_models.generator import generate
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams.fisheye import bad_frames
from avatarsim.render_cams.fisheye.detector import ErrorModelDetector
from avatarsim.render_cams.fisheye.device import FisheyeRig
from avatarsim.render_cams.fisheye.keypoints import confidence, project_joints
from avatarsim.render_cams.fisheye.model import FisheyeModel
from avatarsim.render_cams.fisheye.pose2d import controller_views
from avatarsim.render_cams.fisheye.render import FisheyeRenderer
from avatarsim.render_cams.fisheye.rig import camera_poses, controller_cameras
from avatarsim.render_cams.fisheye.stitch import stitch_params
from avatarsim.render_cams.scene import BodyScene
from avatarsim.scripts.benchmarks import BenchRow, best_of, pose_detection

FORMER_HALF_WIDTH_DEG = 65.0  # the composite before the 150 deg one
SEEDS = range(6)
RATE = 0.15


def filter_rows(quick: bool) -> list[BenchRow]:
    """The filter runs on each camera's sequence (its robust levels are per camera), as
    :class:`~render_cams.fisheye.device.FisheyeRig` runs it."""
    motion = generate("box", duration_s=0.5 if quick else 1.5, fps=30)
    poses = camera_poses(motion, controller_cameras())
    n_frames, n_cams = poses.shape[:2]
    with BodyScene(motion.skeleton) as scene:
        renderer = FisheyeRenderer(scene, FisheyeModel.from_fov().scaled(0.25))
        frames = []
        for t in range(n_frames):
            scene.update(motion, t)
            frames.append([renderer.render(poses[t, c])[0] for c in range(n_cams)])
    per_camera = np.swapaxes(np.array(frames), 0, 1)  # (C, T, H, W, 3)
    rows = []
    for kind in bad_frames.KINDS + bad_frames.UNSEEN_KINDS:
        truth, flagged = [], []
        for seed in SEEDS:
            rng = np.random.default_rng(seed)
            for camera in per_camera:
                corrupted, flags, _ = bad_frames.inject(camera, rng, RATE, (kind,))
                truth.append(flags)
                flagged.append(bad_frames.detect(corrupted))
        scores = bad_frames.precision_recall(np.concatenate(truth), np.concatenate(flagged))
        designed = "designed for" if kind in bad_frames.KINDS else "not designed for"
        total = n_frames * n_cams * len(SEEDS)
        note = (
            f"{scores['flagged']} flagged, {scores['injected']} injected in {total} frames; "
            f"{designed}"
        )
        # No frame flagged: precision is undefined; the row says 0 and the note why.
        rows.append(
            BenchRow(f"bad-frame filter precision ({kind})", "", scores["precision"], note=note)
        )
        rows.append(BenchRow(f"bad-frame filter recall ({kind})", "", scores["recall"]))
    return rows


def _errors(detection, exact: np.ndarray) -> np.ndarray:
    found = detection.detected
    return np.linalg.norm(detection.uv - np.nan_to_num(exact), axis=-1)[found]


def detector_rows(quick: bool) -> list[BenchRow]:
    """Keypoint error of the detector model on projected keypoints (no rendering: visibility
    is 'in the image'), three activities, both controllers."""
    model = FisheyeModel.from_fov()
    detector = ErrorModelDetector()
    rng = np.random.default_rng(0)
    per_camera, on_composite, in_torso, missed, swapped, sizes = [], [], [], [], [], []
    cameras = controller_cameras()
    for activity in ("box", "squat", "controllerpose_study"):
        motion = generate(activity, duration_s=1.0 if quick else 4.0, fps=30)
        poses = camera_poses(motion, cameras)
        n, c = poses.shape[:2]
        uv, in_image, _ = project_joints(
            model, poses.reshape(-1, 4, 4), np.repeat(body17_positions(motion), c, 0)
        )
        uv, in_image = uv.reshape(n, c, 17, 2), in_image.reshape(n, c, 17)
        score = confidence(model, uv, in_image)
        detection = detector.detect_projected(uv, in_image, in_image, score, rng)
        per_camera.append(_errors(detection, uv))
        sizes.append(detection.scale_px[detection.scale_px > 0])
        missed.append(1.0 - detection.detected[in_image].mean())
        swapped.append(detection.swapped[detection.scale_px > 0].mean())
        usable = np.ones((n, c), bool)
        views = controller_views(
            model, cameras, uv, in_image, in_image, score, usable, detector, rng
        )
        for view in views.values():
            on_composite.append(_errors(view.composite_detection, view.composite.uv))
            in_torso.append(_errors(view.torso_detection, view.torso_uv))
    rows = []
    for label, errors in (
        ("per camera", per_camera),
        ("on the composite", on_composite),
        ("in the torso view", in_torso),
    ):
        e = np.concatenate(errors)
        note = f"{e.size} detected keypoints; p90 {np.percentile(e, 90):.1f} px"
        rows.append(
            BenchRow(
                f"detector keypoint error {label} (median)", "px", float(np.median(e)), note=note
            )
        )
    rows.append(
        BenchRow(
            "person size s in a camera (median)",
            "px",
            float(np.median(np.concatenate(sizes))),
            note="sqrt of the keypoints' box area; errors scale with it",
        )
    )
    rows.append(BenchRow("detector missed share of in-image joints", "", float(np.mean(missed))))
    rows.append(
        BenchRow("detector left/right swap share (limb pairs)", "", float(np.mean(swapped)))
    )
    return rows


def composite_rows(quick: bool) -> list[BenchRow]:
    model = FisheyeModel.from_fov()
    pair = controller_cameras(("right_controller",))
    now = stitch_params(model, pair)
    before = stitch_params(model, pair, max_half_width_deg=FORMER_HALF_WIDTH_DEG)
    new, old = now.coverage(), before.coverage()
    size = f"{new['width']}x{new['height']} px (was {old['width']}x{old['height']})"
    images = [np.full((model.height, model.width, 3), 128, np.uint8)] * 2
    repeat = 2 if quick else 5
    t_new = best_of(lambda: now.stitch(images), repeat)
    t_old = best_of(lambda: before.stitch(images), repeat)
    return [
        BenchRow(
            "composite horizontal field of view",
            "deg",
            new["horizontal_deg"],
            old["horizontal_deg"],
            "former composite",
            size,
        ),
        BenchRow(
            "composite vertical field of view",
            "deg",
            new["vertical_deg"],
            old["vertical_deg"],
            "former composite",
        ),
        BenchRow(
            "composite pixels seen by a camera",
            "share",
            new["seen_fraction"],
            old["seen_fraction"],
            "former composite",
        ),
        BenchRow("stitch one composite", "ms", 1e3 * t_new, 1e3 * t_old, "former composite", size),
    ]


def pipeline_rows(quick: bool) -> list[BenchRow]:
    motion = generate("box", duration_s=0.3 if quick else 1.0, fps=30)
    rigs = {"after": FisheyeRig(scale=0.25), "before": FisheyeRig(scale=0.25, detector=None)}
    frames = rigs["after"].sample(motion, 0).summary["frames"]  # also the warm-up (GL, shaders)
    ms = {
        name: 1e3 * best_of(lambda rig=rig: rig.sample(motion, 0), 1 if quick else 2) / frames
        for name, rig in rigs.items()
    }
    return [
        BenchRow(
            "fisheye recording per frame, 4 cameras 160x120, filter + detector + composite views",
            "ms",
            ms["after"],
            ms["before"],
            "without detector and views",
        )
    ]


def run(quick: bool = False, mocap: Path | None = None) -> list[BenchRow]:
    return (
        filter_rows(quick)
        + detector_rows(quick)
        + composite_rows(quick)
        + pipeline_rows(quick)
        + pose_detection.run(quick, mocap)
    )

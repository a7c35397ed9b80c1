"""``FisheyeRig``: the fisheye cameras on the VR controllers (ControllerPose §4) as one ``Device``.

``FisheyeRig(...).sample(motion, seed, body) -> FisheyeRecording`` renders every controller
camera over ``motion`` at 30 Hz (our choice, an analog camera's video rate; the paper gives no
camera rate, its pipeline runs at 7.2 FPS, §4.4), in memory: colour frames
with bad frames injected (§4.2, about 1 in 50) when ``bad_frame_rate > 0``, the range along
each pixel's ray, and one self-describing record per camera frame
(:mod:`render_cams.fisheye.records`), incl. the bad-frame ground truth and the occlusion flags
(a camera inside or against the body records a dark frame, :mod:`render_cams.fisheye.occlusion`).
Then, as the real pipeline does (§4.2-4.3), an image-only filter drops unusable frames
(:func:`render_cams.fisheye.bad_frames.detect`, on the pixels, not on the injection flag) and a
2D keypoint detector (:class:`render_cams.fisheye.detector.ErrorModelDetector`, on by default)
reports keypoints on the frames that pass. Records keep the exact projections
(``keypoints_px``, for re-projection) next to what the detector reported (``detected_px``).
:func:`render_cams.fisheye.sequence.write_fisheye_recording` writes a recording to a folder.

Everything random comes from one seed, split with ``numpy.random.SeedSequence`` into bad-frame
injection, detector errors and dark frames.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from avatarsim.avatar_models import Motion
from avatarsim.avatar_models.body import BodyDescription
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams.device import DeviceError, check_rate, motion_at_rate, resolve_seed
from avatarsim.render_cams.fisheye import bad_frames, occlusion
from avatarsim.render_cams.fisheye.detector import ErrorModelDetector
from avatarsim.render_cams.fisheye.keypoints import (
    confidence,
    project_joints,
    visibility,
    world_to_camera,
)
from avatarsim.render_cams.fisheye.line_of_sight import own_depth
from avatarsim.render_cams.fisheye.model import FisheyeModel
from avatarsim.render_cams.fisheye.pose2d import ControllerPose2D, controller_views
from avatarsim.render_cams.fisheye.records import frame_record
from avatarsim.render_cams.fisheye.render import FisheyeRenderer
from avatarsim.render_cams.fisheye.rig import (
    ControllerCamera,
    Mount,
    camera_poses,
    controller_cameras,
    inside_body,
)
from avatarsim.render_cams.scene import BodyScene, body_for_motion

CAMERA_RATE_HZ = 30.0
SCALE_RANGE = (0.05, 4.0)  # image size factors for quick looks (0.125: 80x60)


@dataclass(frozen=True, eq=False)
class FisheyeRecording:
    """What the controller cameras recorded: ``C`` cameras, ``T`` frames of ``H x W``.

    Attributes:
        cameras: ``(C,)`` the cameras, in rig order.
        names: ``(C,)`` their folder-safe names (e.g. ``left_controller-ring``).
        model: the camera model of every camera.
        images: ``(C, T, H, W, 3)`` uint8 RGB as recorded (bad frames injected, dark when
            occluded).
        range_mm: ``(C, T, H, W)`` uint16 range along each pixel's ray in millimetres (0: none).
        filtered: ``(C, T)`` bool: frames the image filter dropped (nothing is detected or
            composited from them).
        records: ``C * T`` frame records (:func:`~render_cams.fisheye.records.frame_record`),
            frame by frame, cameras in rig order within a frame.
        views: per controller with both cameras, the detector's view of its composite and
            torso-normal view (:mod:`render_cams.fisheye.pose2d`); empty without a detector.
        summary: ``{"frames", "cameras", "fps", "bad_frames", "filtered_frames",
            "occluded_frames", "detector", "composites", "seed", "model"}``; like ``records``,
            it depends on the motion and seed alone.
        fps_rendered: camera frames rendered per second of wall time (not part of the data).
    """

    cameras: tuple[ControllerCamera, ...]
    names: tuple[str, ...]
    model: FisheyeModel
    images: np.ndarray
    range_mm: np.ndarray
    filtered: np.ndarray
    records: list[dict[str, Any]]
    views: dict[str, ControllerPose2D]
    summary: dict[str, Any]
    fps_rendered: float


@dataclass(frozen=True, eq=False)
class FisheyeRig:
    """The controller cameras and how they record.

    Attributes:
        model: camera model (default :meth:`FisheyeModel.from_fov`: 150 x 120 degrees,
            640 x 480); after construction, the model as scaled by ``scale``.
        scale: image size factor in :data:`SCALE_RANGE`, for quick looks.
        rate_hz: frame rate of every camera.
        bad_frame_rate: share of frames corrupted (interference, sync loss).
        detector: the ``"error-model"`` detector, a fast approximation on the exact
            projections (None: report exact projections).
        controllers: controllers that carry cameras (two each, ring and grip).
        mount: where the cameras sit on a controller (default :class:`Mount`).
    """

    model: FisheyeModel | None = None
    scale: float = 1.0
    rate_hz: float = CAMERA_RATE_HZ
    bad_frame_rate: float = bad_frames.BAD_FRAME_RATE
    detector: ErrorModelDetector | None = ErrorModelDetector()
    controllers: Sequence[str] = ("left_controller", "right_controller")
    mount: Mount | None = None
    name: str = "fisheye"

    def __post_init__(self) -> None:
        lo, hi = SCALE_RANGE
        if not (np.isfinite(self.scale) and lo <= self.scale <= hi):
            raise DeviceError(f"scale must be in [{lo:g}, {hi:g}], got {self.scale}")
        model = self.model or FisheyeModel.from_fov()
        object.__setattr__(self, "model", model.scaled(self.scale) if self.scale != 1.0 else model)
        object.__setattr__(self, "rate_hz", check_rate(self.rate_hz))
        object.__setattr__(self, "controllers", tuple(self.controllers))

    def sample(
        self,
        motion: Motion,
        seed: int | np.random.Generator = 0,
        body: BodyDescription | None = None,
    ) -> FisheyeRecording:
        """Every controller camera over ``motion``.

        Args:
            body: the humanoid to render (built once by the caller for this motion);
                ``motion`` must be on its skeleton. Default: a body built from ``motion``'s
                skeleton.

        Raises:
            RigError: a skeleton without a body17 map.
            SceneError: ``motion`` is not on ``body``'s skeleton.
        """
        seed = resolve_seed(seed)
        model = self.model
        sampled = motion_at_rate(motion, self.rate_hz)
        body = body_for_motion(sampled, body)
        cameras = controller_cameras(self.controllers, self.mount)
        poses = camera_poses(sampled, cameras)  # (T, C, 4, 4)
        pose = sampled.fk()
        inside = inside_body(body, *pose, poses[..., :3, 3])  # (T, C): lens covered
        joints = body17_positions(sampled)  # (T, 17, 3)
        depth = np.stack(
            [own_depth(body, *pose, poses[:, c, :3, 3], joints) for c in range(poses.shape[1])],
            axis=1,
        )  # (T, C, 17)
        # A stream added later (dark frames, then composite detections) leaves the earlier
        # ones as they were.
        rng_inject, rng_noise, rng_dark, rng_views = (
            np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(4)
        )

        names = tuple(c.name.replace("/", "-") for c in cameras)
        n_frames, n_cams = poses.shape[:2]
        images = np.zeros((n_cams, n_frames, model.height, model.width, 3), np.uint8)
        range_mm = np.zeros((n_cams, n_frames, model.height, model.width), np.uint16)
        blocked = np.zeros((n_cams, n_frames))
        seen: list[tuple] = []
        start = time.perf_counter()
        with BodyScene(body) as scene:
            renderer = FisheyeRenderer(scene, model)
            circle = renderer.maps.range_scale > 0
            for t in range(n_frames):  # rendering is inherently per frame
                scene.update(sampled, t)
                for c in range(n_cams):
                    if inside[t, c]:
                        color = occlusion.dark_frame(model.height, model.width, rng_dark)
                        range_m = np.zeros((model.height, model.width), np.float32)
                        blocked[c, t] = 1.0
                    else:
                        color, range_m = renderer.render(poses[t, c])
                        color, blocked[c, t] = occlusion.block_lens(color, range_m, circle)
                    images[c, t] = color
                    range_mm[c, t] = np.clip(np.rint(range_m * 1000.0), 0, 65535)
                    uv, in_image, joint_range = project_joints(
                        model, poses[t, c][None], joints[t][None]
                    )
                    vis = visibility(uv[0], in_image[0], joint_range[0], range_m, depth[t, c])
                    seen.append((t, c, uv[0], in_image[0], vis & ~inside[t, c]))
        elapsed = time.perf_counter() - start

        truth = np.zeros((n_cams, n_frames), bool)
        for c in range(n_cams):
            images[c], truth[c], _ = bad_frames.inject(images[c], rng_inject, self.bad_frame_rate)
        filtered = np.stack([bad_frames.detect(images[c]) for c in range(n_cams)])  # (C, T)
        occluded = blocked >= occlusion.OCCLUDED_FRACTION  # (C, T)
        w2c = world_to_camera(poses)
        uv, in_image, vis = (np.stack([s[k] for s in seen]) for k in (2, 3, 4))  # (T * C, ...)
        score = confidence(model, uv, vis)
        usable = ~filtered.T.reshape(-1)  # frame-major, as ``seen``
        # Filtered frames are dropped before detection: no keypoint of theirs is reported.
        reported = in_image & usable[:, None]
        if self.detector is None:
            detected = reported
            detected_px, detected_conf = np.where(detected[..., None], uv, 0.0), score * detected
        else:
            detection = self.detector.detect_projected(uv, reported, vis, score, rng_noise)
            detected_px, detected, detected_conf = (
                detection.uv,
                detection.detected,
                detection.confidence,
            )
        records = []
        for k, (t, c, *_) in enumerate(seen):
            records.append(
                frame_record(
                    names[c],
                    model,
                    t,
                    t / self.rate_hz,
                    w2c[t, c],
                    joints[t],
                    uv[k],
                    in_image[k],
                    vis[k],
                    score[k],
                    bad_frame=bool(truth[c, t]),
                    lens_blocked=blocked[c, t],
                    occluded=bool(occluded[c, t]),
                    mean_luminance=occlusion.mean_luminance(images[c, t], circle),
                    filtered=bool(filtered[c, t]),
                    detection=(detected_px[k], detected[k], detected_conf[k]),
                )
            )
        views = (
            {}
            if self.detector is None
            else controller_views(
                model,
                cameras,
                uv.reshape(n_frames, n_cams, 17, 2),
                in_image.reshape(n_frames, n_cams, 17),
                vis.reshape(n_frames, n_cams, 17),
                score.reshape(n_frames, n_cams, 17),
                ~filtered.T,
                self.detector,
                rng_views,
            )
        )
        # Occluded frames are dark for a reason the injected faults do not cover: the filter
        # is scored on the other frames only.
        clear = ~occluded
        summary = {
            "frames": int(n_frames),
            "cameras": list(names),
            "fps": self.rate_hz,
            "bad_frames": bad_frames.precision_recall(truth[clear], filtered[clear]),
            "filtered_frames": {name: int(filtered[c].sum()) for c, name in enumerate(names)},
            "occluded_frames": {name: int(occluded[c].sum()) for c, name in enumerate(names)},
            "detector": None
            if self.detector is None
            else {
                "name": self.detector.name,
                "label": self.detector.label,
                **asdict(self.detector),
            },
            "composites": {
                controller: {
                    "frames_with_person": int(v.composite_detection.detected.any(axis=1).sum()),
                    "torso_views": int(v.torso.valid.sum()),
                }
                for controller, v in views.items()
            },
            "seed": seed,
            "model": model.as_dict(),
        }
        fps_rendered = n_frames * n_cams / max(elapsed, 1e-9)
        return FisheyeRecording(
            tuple(cameras),
            names,
            model,
            images,
            range_mm,
            filtered,
            records,
            views,
            summary,
            fps_rendered,
        )

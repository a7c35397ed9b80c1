"""Rendered device views of the ground truth for the report: the four controller fisheye
cameras (ControllerPose) and a Kinect depth frame, recorded over a short window mid-clip."""

from __future__ import annotations

import time

import cv2
import imageio.v3 as iio
import numpy as np

from avatarsim.avatar_models.fileio import write_atomic
from avatarsim.render_cams.kinect.depth import colourise, read_depth_png
from avatarsim.scripts.run_context import RunContext
from avatarsim.scripts.scenario import Scenario

METRICS = {
    "fisheye_fps_rendered": "fisheye camera frames rendered per second (all cameras)",
    "kinect_fps_rendered": "Kinect depth frames rendered per second",
}
WINDOW_S = 0.1  # a few frames at the cameras' 30 Hz, mid-clip
PANEL_H = 240


def metrics_for(scenario: Scenario) -> set[str]:
    spec = scenario.cameras
    if spec is None:
        return set()
    wanted = {"fisheye_fps_rendered": spec.fisheye, "kinect_fps_rendered": spec.kinect}
    return {name for name, on in wanted.items() if on}


def window(ctx: RunContext):
    """A few frames mid-clip of the motion on the humanoid (the ground truth itself on an own
    rig, its retargeting on a foreign one), and the humanoid's body to render."""
    motion, body = ctx.humanoid.motion, ctx.humanoid.body
    middle = motion.n_frames // 2
    return motion[middle : middle + max(2, int(round(WINDOW_S * motion.fps)))], body


def panel(image: np.ndarray, label: str) -> np.ndarray:
    """``image`` scaled to the panel height with ``label`` on it (RGB uint8)."""
    rgb = image if image.ndim == 3 else np.repeat(image[..., None], 3, axis=2)
    rgb = np.ascontiguousarray(rgb[..., :3])
    scaled = cv2.resize(
        rgb, (int(rgb.shape[1] * PANEL_H / rgb.shape[0]), PANEL_H), interpolation=cv2.INTER_AREA
    )
    cv2.putText(
        scaled, label, (6, 18), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (255, 255, 255), 1, cv2.LINE_AA
    )
    return scaled


def run(ctx: RunContext) -> None:
    spec = ctx.scenario.cameras
    if spec is None:
        return
    clip, body = window(ctx)
    panels = []
    if spec.fisheye:
        from avatarsim.render_cams.fisheye.device import FisheyeRig
        from avatarsim.render_cams.fisheye.sequence import write_fisheye_recording

        folder = ctx.out_dir / "cameras" / "fisheye"
        recording = FisheyeRig().sample(clip, ctx.scenario.seed, body)
        summary = write_fisheye_recording(recording, folder, video=False)
        ctx.metrics["fisheye_fps_rendered"] = float(recording.fps_rendered)
        for name, frames in zip(recording.names, recording.images, strict=True):
            panels.append(panel(frames[0], name))
        for stitched in summary["stitched"]:
            panels.append(panel(iio.imread(folder / stitched / "000000.png"), stitched))
        ctx.output("fisheye_keypoints", folder / "keypoints.json")
    if spec.kinect:
        from avatarsim.render_cams.kinect.device import Kinect
        from avatarsim.render_cams.kinect.sequence import write_kinect_recording

        folder = ctx.out_dir / "cameras" / spec.kinect
        t0 = time.perf_counter()
        recording = Kinect(spec.kinect).sample(clip, ctx.scenario.seed, body)
        write_kinect_recording(recording, folder)
        ctx.metrics["kinect_fps_rendered"] = len(recording.frames) / (time.perf_counter() - t0)
        first = read_depth_png(folder / "depth" / "000000.png")
        bgr = colourise(first, recording.sensor.range_m)
        panels.append(panel(bgr[..., ::-1], f"{spec.kinect} depth"))
        ctx.output("kinect_recording", folder / "recording.json")
    if panels:
        strip = np.hstack(panels)
        ctx.output(
            "cameras_png",
            write_atomic(
                ctx.out_dir / "cameras.png", iio.imwrite("<bytes>", strip, extension=".png")
            ),
        )

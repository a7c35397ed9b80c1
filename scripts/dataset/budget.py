"""The memory a dataset config plans to use, checked before anything is written.

Two terms (bytes), each scaling with a size of the config:

- the plan: every sample's :class:`scripts.dataset.plan.SampleSpec` and window, held in the
  generating process (:data:`PLAN_BYTES_PER_SAMPLE`), for subjects x activities x windows x
  device sets (a mocap source counts one clip: its folder is indexed later);
- one sample in flight: its ground-truth window of ``seconds x fps + 1`` frames
  (:data:`avatar_models.memory.FRAME_BYTES` a frame)
  plus the largest device set's raw images before encoding: the controller cameras
  (:func:`render_cams.fisheye.rig.controller_cameras`) at 640 x 480 x ``image_scale``^2
  (ControllerPose section 4.1), 5 bytes a pixel (RGB and the uint16 range of
  :class:`render_cams.fisheye.device.FisheyeRecording`), and Kinect depth of 16-bit pixels at
  the sensor's resolution, both at 30 Hz / ``image_stride``.
"""

from __future__ import annotations

from avatarsim.avatar_models.memory import FRAME_BYTES, format_bytes, require_memory
from avatarsim.render_cams.fisheye.device import CAMERA_RATE_HZ
from avatarsim.render_cams.fisheye.model import PAPER_SIZE
from avatarsim.render_cams.fisheye.rig import controller_cameras
from avatarsim.render_cams.kinect.sensors import get_sensor

PLAN_BYTES_PER_SAMPLE = 1024
FISHEYE_PIXEL_BYTES = 5


def plan_samples_count(config) -> float:
    """Samples the plan will hold (a float: a huge config must not make a huge int)."""
    windows = sum(
        float(s.windows) * (float(s.subjects) * len(s.activities) if s.kind == "builtin" else 1)
        for s in config.sources
    )
    return windows * len(config.devices)


def sample_bytes(config) -> float:
    """Bytes of one sample in flight (module docstring)."""
    frames = config.window.seconds * config.window.fps + 1
    images = 0.0
    for d in config.devices:
        shots = config.window.seconds * CAMERA_RATE_HZ / d.image_stride + 1
        pixels = 0.0
        if d.fisheye_images != "none":
            cameras = len(controller_cameras())
            size = PAPER_SIZE[0] * PAPER_SIZE[1] * d.image_scale**2
            pixels += cameras * FISHEYE_PIXEL_BYTES * size
        if d.kinect_depth:
            sensor = get_sensor(d.kinect)
            pixels += 2 * sensor.width * sensor.height
        images = max(images, shots * pixels)
    return frames * FRAME_BYTES + images


def check_budget(config) -> None:
    """Raises :class:`avatar_models.config.ConfigError` when the plan and one sample together
    need more memory than :func:`avatar_models.memory.memory_limit` allows."""
    samples = plan_samples_count(config)
    plan, sample = samples * PLAN_BYTES_PER_SAMPLE, sample_bytes(config)
    require_memory(
        plan + sample,
        f"{samples:.3g} samples (sources.subjects x activities x windows, x devices) of "
        f"window.seconds x window.fps = {config.window.seconds:g} s x {config.window.fps:g} fps "
        f"(plan {format_bytes(plan)} + one sample {format_bytes(sample)})",
    )

"""Headless pictures of a qpos trajectory with MuJoCo's own renderer (EGL, see avatar_models).

Shapes: frames ``(N, H, W, 3)`` uint8.
"""

from __future__ import annotations

import mujoco
import numpy as np


def render_frames(
    model: mujoco.MjModel,
    qpos: np.ndarray,
    frame_ids: np.ndarray,
    width: int = 320,
    height: int = 400,
    distance: float = 3.2,
    azimuth: float = 150.0,
    elevation: float = -12.0,
) -> np.ndarray:
    """Render ``qpos[frame_ids]`` from a camera that follows the root at a fixed offset."""
    data = mujoco.MjData(model)
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.distance, cam.azimuth, cam.elevation = distance, azimuth, elevation
    frames = []
    with mujoco.Renderer(model, height=height, width=width) as renderer:
        for t in np.asarray(frame_ids, dtype=np.int64):
            data.qpos[:] = qpos[t]
            mujoco.mj_forward(model, data)
            cam.lookat[:] = [data.qpos[0], data.qpos[1], 0.9]
            renderer.update_scene(data, camera=cam)
            frames.append(renderer.render().copy())
    return np.stack(frames)

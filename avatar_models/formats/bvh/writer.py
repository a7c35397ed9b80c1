"""Writing a :class:`Motion` as a BVH file (conventions: :mod:`..bvh`)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.avatar_models.fileio import atomic_file
from avatarsim.avatar_models.formats.units import Y_UP_TO_Z_UP, unit_scale
from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.skeleton import Skeleton


def _depth_first(skeleton: Skeleton) -> list[int]:
    """Joint indices in depth-first pre-order (the order BVH writes them)."""
    order, stack = [], [0]
    while stack:
        j = stack.pop()
        order.append(j)
        stack.extend(int(c) for c in skeleton.children(j)[::-1])
    return order


def _hierarchy_text(skeleton: Skeleton, offsets: np.ndarray, order: list[int], euler: str) -> str:
    depth = np.zeros(skeleton.n_joints, dtype=int)
    out = ["HIERARCHY"]
    open_depths: list[int] = []
    for j in order:
        p = int(skeleton.parents[j])
        depth[j] = depth[p] + 1 if p >= 0 else 0
        while open_depths and open_depths[-1] >= depth[j]:
            out.append("\t" * open_depths.pop() + "}")
        pad = "\t" * int(depth[j])
        off = " ".join(f"{v:.10g}" for v in (np.zeros(3) if p < 0 else offsets[j]))
        if skeleton.is_site[j]:
            out += [f"{pad}End Site", f"{pad}{{", f"{pad}\tOFFSET {off}"]
        else:
            rot_channels = " ".join(f"{a}rotation" for a in euler)
            if p < 0:
                header, channels = (
                    f"ROOT {skeleton.names[j]}",
                    f"6 Xposition Yposition Zposition {rot_channels}",
                )
            else:
                header, channels = f"JOINT {skeleton.names[j]}", f"3 {rot_channels}"
            out += [
                f"{pad}{header}",
                f"{pad}{{",
                f"{pad}\tOFFSET {off}",
                f"{pad}\tCHANNELS {channels}",
            ]
        open_depths.append(int(depth[j]))
    out += ["\t" * d + "}" for d in reversed(open_depths)]
    return "\n".join(out) + "\n"


def write_bvh(
    motion: Motion, path: str | Path, unit: str | float = "cm", up: str = "y", order: str = "ZYX"
) -> Path:
    """Write ``motion`` as BVH, atomically (a temp file renamed into place).

    The root gets 6 channels (OFFSET 0, position = ``root_pos``), other joints 3 rotation
    channels in the intrinsic Euler ``order``; site joints become End Sites. Values are in
    ``unit`` and degrees, axes Y up (``up="y"``, the inverse of the reader's conversion) or
    as they are (``up="z"``).
    """
    path = Path(path)
    sk = motion.skeleton
    if sorted(order) != ["X", "Y", "Z"]:
        raise MotionValueError(f"order must be a permutation of 'XYZ', got {order!r}")
    if up not in ("y", "z"):
        raise MotionValueError(f"up must be 'y' or 'z', got {up!r}")
    sites = np.flatnonzero(sk.is_site)
    if (
        sk.is_site[0]
        or any(sk.children(int(j)).size for j in sites)
        or np.any(sk.is_site[sk.parents[sites]])
    ):
        raise MotionValueError("BVH needs end sites as leaves under non-site joints")
    scale = unit_scale(unit, path)
    axes = Y_UP_TO_Z_UP.T if up == "y" else np.eye(3)  # world -> file
    joints = _depth_first(sk)
    rotating = [j for j in joints if not sk.is_site[j]]
    local = axes @ quat.to_matrix(motion.local_rot[:, rotating]) @ axes.T
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # gimbal lock: angles still reproduce R
        angles = Rotation.from_matrix(local.reshape(-1, 3, 3)).as_euler(order, degrees=True)
    data = np.concatenate(
        [motion.root_pos @ axes.T / scale, angles.reshape(motion.n_frames, -1)], axis=1
    )
    header = _hierarchy_text(sk, sk.offsets @ axes.T / scale, joints, order)
    header += f"MOTION\nFrames: {motion.n_frames}\nFrame Time: {1.0 / motion.fps:.10g}\n"
    with atomic_file(path, "w", encoding="utf-8") as fh:
        fh.write(header)
        np.savetxt(fh, data, fmt="%.10g", delimiter=" ")
    return path

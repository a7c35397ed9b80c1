"""Reading a BVH file into a :class:`Motion` (conventions: :mod:`..bvh`)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from avatarsim.avatar_models.errors import MotionFormatError, MotionValueError
from avatarsim.avatar_models.formats.bvh.channels import root_and_offsets, split_channels
from avatarsim.avatar_models.formats.bvh.frames import motion_header, motion_values
from avatarsim.avatar_models.formats.bvh.hierarchy import parse_hierarchy
from avatarsim.avatar_models.formats.units import Y_UP_TO_Z_UP, detect_unit, unit_scale
from avatarsim.avatar_models.measure import standing_height
from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.skeleton import Skeleton

_MOTION_LINE = re.compile(r"^[ \t]*MOTION[ \t\r]*$", re.MULTILINE)
# A whole-body turn rate (rad/s, mean over the joints) no person reaches: the joints of a
# single limb peak near 20-40 rad/s in a throw, the mean over the body stays far lower (real
# Bandai takes: at most 2). The cgspeed CMU T-pose frames jump at 28-54.
_MAX_MEAN_JOINT_SPEED_RAD_S = 10.0


def _decode(raw: bytes, path: Path) -> str:
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise MotionFormatError(f"not UTF-8 text (byte {exc.start})", path, line) from None


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rotation angle (rad) between unit quaternions ``a`` and ``b`` (same shape ``(..., 4)``)."""
    return 2.0 * np.arccos(np.clip(np.abs(np.sum(a * b, axis=-1)), 0.0, 1.0))


def prepended_rest_frame(rot: np.ndarray, fps: float) -> str | None:
    """Why frame 0 of local rotations ``rot (T, J, 4)`` is a rest pose put before the take
    (the cgspeed CMU conversions' T-pose), or ``None`` when it looks like part of the take.

    All three must hold (angles are means over the joints): from frame 0 to 1 the joints
    turn faster than :data:`_MAX_MEAN_JOINT_SPEED_RAD_S`; that turn is over 5 times the
    largest frame-to-frame turn of the next half second; and frame 0 is less than half as far
    from the rest pose as frame 1. The CMU clips in ``shared/mocap`` give ratios of 10-200,
    Bandai's (no prepended frame) turn 100 times slower."""
    n = rot.shape[0]
    if n < 3:
        return None
    jump = float(_angle(rot[0], rot[1]).mean())
    ahead = rot[1 : min(n, 2 + int(0.5 * fps))]
    steady = float(_angle(ahead[:-1], ahead[1:]).mean(axis=-1).max())
    rest = np.array([1.0, 0.0, 0.0, 0.0])
    rest0, rest1 = (float(_angle(rot[i], rest).mean()) for i in (0, 1))
    if jump * fps > _MAX_MEAN_JOINT_SPEED_RAD_S and jump > 5.0 * steady and rest0 < 0.5 * rest1:
        return (
            f"a rest pose before the take (the joints turn {np.degrees(jump):.0f} deg on "
            f"average from it to the next frame, in {1000.0 / fps:.1f} ms)"
        )
    return None


def _snap_fps(frame_time: float) -> float:
    """``1 / frame_time``, rounded to an integer when the file printed it to ~6 digits."""
    fps = 1.0 / frame_time
    return float(round(fps)) if abs(fps - round(fps)) < 1e-5 * fps else fps


def read_bvh(
    path: str | Path,
    unit: str | float | None = None,
    up: str = "y",
    drop_rest_frame: bool = True,
) -> Motion:
    """Read a BVH file into a :class:`Motion` (metres, Z up). See the module docstring.

    Args:
        path: the ``.bvh`` file.
        unit: ``"m"``, ``"cm"``, ``"mm"``, ``"inch"``, ``"cmu"`` or metres per unit; ``None``
            guesses from the skeleton's standing height.
        up: ``"y"`` (the BVH convention) or ``"z"`` for files already Z up.
        drop_rest_frame: drop a rest pose put before the take as frame 0 (module docstring).
    """
    path = Path(path)
    if up not in ("y", "z"):
        raise MotionValueError(f"up must be 'y' or 'z', got {up!r}")
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise MotionFormatError(f"cannot read: {exc.strerror}", path) from None
    text = _decode(raw, path)
    if not text.strip():
        raise MotionFormatError("empty file", path, 1)
    found = _MOTION_LINE.search(text)
    if found is None:
        raise MotionFormatError("no MOTION line", path, text.count("\n") + 1)
    joints = parse_hierarchy(text[: found.start()], path)
    n_channels = sum(len(j.channels) for j in joints)
    motion_line = text.count("\n", 0, found.start()) + 1
    if n_channels == 0:
        raise MotionFormatError("the hierarchy declares no channels", path, motion_line)
    frames, frame_time, start, first_line = motion_header(
        text, found.end() + 1, motion_line + 1, path
    )
    values = motion_values(text[start:], frames, n_channels, path, first_line)
    positions, has_position, rot = split_channels(joints, values)
    root_pos, offsets, folded = root_and_offsets(joints, positions, has_position, rot, path)

    axes = Y_UP_TO_Z_UP if up == "y" else np.eye(3)
    offsets, root_pos = offsets @ axes.T, root_pos @ axes.T
    rot = np.concatenate([rot[..., :1], rot[..., 1:] @ axes.T], axis=-1)  # C R C^T
    names = [j.name for j in joints]
    parents = [j.parent for j in joints]
    is_site = [j.is_site for j in joints]
    try:
        skeleton = Skeleton(names, parents, offsets, is_site)
        if unit is None:
            unit, scale = detect_unit(standing_height(skeleton), path)
        else:
            scale = unit_scale(unit, path)
        meta = {
            "source": str(path),
            "format": "bvh",
            "unit": unit if isinstance(unit, str) else "custom",
            "unit_scale_m": scale,
            "frame_time_s": frame_time,
            "up": up,
        }
        if folded:
            meta["folded_root_into"] = folded
        reason = prepended_rest_frame(rot, _snap_fps(frame_time)) if drop_rest_frame else None
        if reason is not None:
            meta["dropped_frames"] = {"frames": [0], "reason": reason}
            root_pos, rot = root_pos[1:], rot[1:]
        return Motion(
            skeleton.scaled(scale),
            _snap_fps(frame_time),
            root_pos * scale,
            rot,
            meta,
        )
    except MotionValueError as exc:
        raise MotionFormatError(str(exc), path, motion_line) from None

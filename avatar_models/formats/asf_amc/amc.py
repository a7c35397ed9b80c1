"""The AMC motion file and the :class:`Motion` of an AMC on its ASF skeleton (conventions:
:mod:`..asf_amc`). Shapes: ``T`` frames, ``J`` joints."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models import quat
from avatarsim.avatar_models.errors import MotionFormatError, MotionValueError
from avatarsim.avatar_models.formats.asf_amc.asf import Asf, asf_skeleton, parse_floats, read_asf
from avatarsim.avatar_models.formats.units import Y_UP_TO_Z_UP
from avatarsim.avatar_models.motion import Motion

CMU_FPS = 120.0  # the CMU database is captured at 120 Hz; AMC files do not say.
_AMC_KEYWORDS = (":fully-specified", ":degrees", ":radians")
_CMU_TRIAL = re.compile(r"^(\d+)_\d+$")


def _amc_rows(path: Path) -> tuple[list[tuple[int, str, str]], str | None]:
    """Data rows ``(line, head, rest)`` after the header, and the header's angle unit if any."""
    try:
        text = path.read_bytes().decode("utf-8", errors="replace")
    except OSError as exc:
        raise MotionFormatError(f"cannot read: {exc.strerror}", path) from None
    rows = []
    angle = None
    for i, raw in enumerate(text.splitlines(), start=1):
        parts = raw.split(None, 1)
        if not parts or parts[0].startswith("#"):
            continue
        if parts[0].startswith(":"):
            key = parts[0].lower()
            if rows or key not in _AMC_KEYWORDS or len(parts) > 1:
                raise MotionFormatError(f"unexpected AMC keyword line {raw.strip()!r}", path, i)
            angle = {":degrees": "deg", ":radians": "rad"}.get(key, angle)
            continue
        rows.append((i, parts[0], parts[1] if len(parts) > 1 else ""))
    if not rows:
        raise MotionFormatError("no frames (empty or truncated file)", path)
    return rows, angle


def _channel_values(
    path: Path, lines: list[int], rests: list[str], n: int, what: str
) -> np.ndarray:
    """``(len(lines), n)`` floats of one bone's rows; errors name the first bad line."""
    tokens = [r.split() for r in rests]
    counts = np.fromiter(map(len, tokens), dtype=np.int64, count=len(tokens))
    bad = np.flatnonzero(counts != n)
    if bad.size:
        k = bad[0]
        raise MotionFormatError(f"{what} needs {n} values, got {counts[k]}", path, lines[k])
    try:
        values = np.array(tokens, dtype=float).reshape(len(lines), n)
    except ValueError:
        # Find the offending row for the message; numpy rejects a few spellings Python's
        # float() takes (e.g. "1_0"), so fall back to the first row when none is found.
        for line, toks in zip(lines, tokens, strict=True):
            parse_floats(toks, n, what, path, line)
        raise MotionFormatError(f"{what}: unparsable number", path, lines[0]) from None
    bad = np.flatnonzero(~np.isfinite(values).all(axis=1))
    if bad.size:
        raise MotionFormatError(f"{what}: NaN or infinite value", path, lines[bad[0]])
    return values


def read_amc_channels(
    path: str | Path, asf: Asf
) -> tuple[np.ndarray, dict[str, np.ndarray], str | None]:
    """Frame numbers ``(T,)`` and per-bone DOF values ``{bone: (T, n_dof)}`` in file units.

    ``"root"`` holds the ASF root ``order`` channels. Bones absent in a frame read as zeros.
    Also returns the angle unit the AMC header declares (``:DEGREES``/``:RADIANS``) or None.
    """
    path = Path(path)
    rows, angle = _amc_rows(path)
    line_no = [r[0] for r in rows]
    heads = [r[1] for r in rows]
    # A frame line is a lone integer (ASCII digits only: str.isdigit also accepts e.g. "²").
    is_frame = np.array(
        [
            h.isascii() and h.isdigit() and len(h) < 10 and not r[2]
            for h, r in zip(heads, rows, strict=True)
        ]
    )
    if not is_frame[0]:
        raise MotionFormatError(f"expected a frame number, got {heads[0]!r}", path, line_no[0])
    frame_rows = np.flatnonzero(is_frame)
    numbers = np.array([int(heads[i]) for i in frame_rows])
    jumps = np.flatnonzero(np.diff(numbers) != 1)
    if jumps.size:
        k = frame_rows[jumps[0] + 1]
        raise MotionFormatError(
            f"frame {heads[k]} out of sequence (after {numbers[jumps[0]]})", path, line_no[k]
        )
    frame_of_row = np.cumsum(is_frame) - 1
    n_frames = numbers.size
    grouped: dict[str, list[int]] = {}
    for i in np.flatnonzero(~is_frame):
        grouped.setdefault(heads[i], []).append(int(i))
    dof_count = {"root": len(asf.root_order)} | {b: len(v.dofs) for b, v in asf.bones.items()}
    for head, idx in grouped.items():
        if head not in dof_count:
            raise MotionFormatError(
                f"unknown bone {head!r} (not in the ASF)", path, line_no[idx[0]]
            )
    rows_per_frame = np.bincount(frame_of_row[~is_frame], minlength=n_frames)
    if np.any(rows_per_frame == 0):
        k = frame_rows[np.argmax(rows_per_frame == 0)]
        raise MotionFormatError(f"frame {heads[k]} has no data (truncated file?)", path, line_no[k])
    channels = {}
    for bone, n in dof_count.items():
        idx = grouped.get(bone, [])
        frames = frame_of_row[idx]
        dup = np.flatnonzero(np.diff(frames) == 0)
        if dup.size:
            raise MotionFormatError(
                f"{bone} given twice in one frame", path, line_no[idx[dup[0] + 1]]
            )
        values = np.zeros((n_frames, n))
        if idx:
            lines = [line_no[i] for i in idx]
            values[frames] = _channel_values(path, lines, [rows[i][2] for i in idx], n, bone)
        channels[bone] = values
    return numbers, channels, angle


def _rotations(angles: np.ndarray, dofs: tuple[str, ...], frame: np.ndarray) -> np.ndarray:
    """``(T, 3, 3)`` ``F M F^T`` for Euler ``angles (T, k)`` (radians) about ``dofs`` of ``F``."""
    if not dofs:
        return np.broadcast_to(np.eye(3), (angles.shape[0], 3, 3))
    m = Rotation.from_euler("".join(d[1] for d in dofs), angles).as_matrix()
    return frame @ m.reshape(-1, 3, 3) @ frame.T


def find_asf(amc_path: str | Path) -> Path:
    """The ASF beside ``amc_path``: same stem, or the subject's ``SS.asf`` for CMU ``SS_TT.amc``."""
    amc_path = Path(amc_path)
    stems = [amc_path.stem]
    trial = _CMU_TRIAL.match(amc_path.stem)
    if trial:
        stems.append(trial.group(1))
    for stem in stems:
        for suffix in (".asf", ".ASF"):
            candidate = amc_path.with_name(stem + suffix)
            if candidate.is_file():
                return candidate
    raise MotionFormatError(
        f"no skeleton beside it: put its ASF file in the same folder, named "
        f"{' or '.join(s + '.asf' for s in stems)} (from Python: read_asf_amc(path, asf=...))",
        amc_path,
    )


def read_asf_amc(
    amc_path: str | Path,
    asf: str | Path | None = None,
    unit: str | float = "asf",
    fps: float = CMU_FPS,
) -> Motion:
    """Read an AMC motion with its ASF skeleton into a Z-up, metre :class:`Motion`.

    Args:
        amc_path: the ``.amc`` file.
        asf: the ``.asf`` file; by default found beside the AMC (:func:`find_asf`).
        unit: ``"asf"`` (use the ASF's ``:units length``), a unit name or metres per unit.
        fps: frame rate; AMC files do not store one (CMU: 120).

    ``meta`` records ``source``, ``asf``, ``format``, ``metres_per_unit``, ``first_frame``,
    ``asf_name`` and ``limit_axes`` (see the module docstring).
    """
    amc_path = Path(amc_path)
    asf_path = find_asf(amc_path) if asf is None else Path(asf)
    if not asf_path.is_file():
        raise MotionFormatError("no such ASF file", asf_path)
    if not (isinstance(fps, int | float) and np.isfinite(fps) and fps > 0):
        raise MotionFormatError(f"fps must be a positive number, got {fps!r}", amc_path)
    skel_data = read_asf(asf_path, unit)
    skeleton, frames = asf_skeleton(skel_data)
    numbers, channels, amc_angle = read_amc_channels(amc_path, skel_data)
    angle = amc_angle or skel_data.units["angle"]
    to_rad = np.pi / 180.0 if angle == "deg" else 1.0

    n = numbers.size
    local = np.broadcast_to(np.eye(3), (n, skeleton.n_joints, 3, 3)).copy()
    root = channels["root"]
    order = skel_data.root_order
    rot_cols = [i for i, c in enumerate(order) if c[0] == "r"]
    local[:, 0] = _rotations(
        root[:, rot_cols] * to_rad, tuple(order[i] for i in rot_cols), frames["root"]
    )
    for name, bone in skel_data.bones.items():
        if bone.dofs:
            j = skeleton.index(name)
            local[:, j] = _rotations(channels[name] * to_rad, bone.dofs, frames[name])
    translation = np.zeros((n, 3))
    for i, c in enumerate(order):
        if c[0] == "t":
            translation[:, "xyz".index(c[1])] = root[:, i]
    root_pos = (translation + skel_data.root_position) @ Y_UP_TO_Z_UP.T * skel_data.metres_per_unit
    meta = {
        "source": str(amc_path),
        "format": "amc",
        "asf": str(asf_path),
        "asf_name": skel_data.name,
        "metres_per_unit": skel_data.metres_per_unit,
        "first_frame": int(numbers[0]),
        "limit_axes": {j: frames[j].tolist() for j in skeleton.limits},
    }
    try:
        return Motion(skeleton, fps, root_pos, quat.from_matrix(local), meta)
    except MotionValueError as exc:
        raise MotionFormatError(f"invalid motion: {exc}", amc_path) from None


def bone_tip_positions(motion: Motion) -> np.ndarray:
    """``(T, J, 3)`` the tip of the bone each joint rotates (an ASF reader's bone position).

    For an ASF-derived skeleton all children of a joint start at its bone's tip, so the tip is
    the position of the first child; sites and childless joints give their own position.
    """
    parents = motion.skeleton.parents
    first_child = np.arange(motion.skeleton.n_joints)
    for j in range(len(parents) - 1, 0, -1):  # reverse, so the lowest-index child wins
        first_child[parents[j]] = j
    return motion.global_positions()[:, first_child]

"""BVH (Biovision hierarchy) reader and writer.

Reading gives a :class:`Motion` in metres, Z up, rest pose facing +X:

- Channels: any subset of ``{X,Y,Z}position`` and ``{X,Y,Z}rotation`` per joint (3 and 6 are
  usual). The order of the rotation channels is the intrinsic Euler order (``Zrotation
  Yrotation Xrotation`` is ``R = Rz Ry Rx``), evaluated with scipy's ``Rotation.from_euler``.
- End Sites become site joints (``Skeleton.is_site``) named ``<parent>_end``.
- Root translation: ``Motion.root_pos`` is the root's OFFSET plus its position channels.
  Position channels of other joints *replace* their OFFSET (the Bandai Namco convention, see
  ``shared/mocap/README.md``). The core model translates the root only, so constant position
  channels become the joint's offset; a root that does not rotate and whose single child
  carries the translation (Bandai's ``joint_Root`` -> ``Hips``) is folded: the root follows
  the child (their bone becomes zero-length) and every other joint keeps its position. Anything else
  raises :class:`MotionFormatError`.
- Units: ``unit`` is a name in :data:`units.UNITS` or metres per unit; ``None`` picks the
  unit that gives a human standing height (:func:`measure.standing_height`).
- Axes: ``up="y"`` files are turned to Z up by ``C`` (:data:`units.Y_UP_TO_Z_UP`), positions
  ``p -> C p`` and rotations ``R -> C R C^T``; ``up="z"`` keeps the file's axes.
- A prepended rest pose: the cgspeed BVH conversions of the CMU database put the T-pose
  before the take as frame 0. Such a frame (:func:`prepended_rest_frame`: some joint turns
  faster than a person can from it to frame 1, an order of magnitude more than between the
  next frames, and it is much nearer the rest pose than frame 1) is dropped, and
  ``meta["dropped_frames"]`` records it (``drop_rest_frame=False`` keeps it).

The MOTION block is parsed in one vectorised pass (``np.loadtxt``'s C parser for plain
decimal data; otherwise one ``np.fromstring`` plus a byte-level count of values per line) and
Euler angles become quaternions by one closed-form product for all joints and frames, which
is what makes reading fast. Every malformed input raises :class:`MotionFormatError` naming
the file and line.
"""

from __future__ import annotations

import io
import re
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from avatar_models import quat
from avatar_models.errors import MotionFormatError, MotionValueError
from avatar_models.fileio import atomic_file
from avatar_models.formats.units import Y_UP_TO_Z_UP, detect_unit, unit_scale
from avatar_models.measure import standing_height
from avatar_models.motion import FPS_RANGE, Motion
from avatar_models.skeleton import Skeleton

_CHANNELS = {f"{a}{kind}": (kind, a) for a in "XYZ" for kind in ("position", "rotation")}
_MOTION_LINE = re.compile(r"^[ \t]*MOTION[ \t\r]*$", re.MULTILINE)
# Position channels whose peak-to-peak is below this fraction of their magnitude are constant
# (files print about 6 significant digits, so "constant" values jitter in the last digit).
_CONSTANT_RTOL = 1e-6
# Bytes of frame data that the np.loadtxt fast path reads exactly as the checked path does.
_DECIMAL_BYTES = b"0123456789.+-eE \t\r\n"
# A whole-body turn rate (rad/s, mean over the joints) no person reaches: the joints of a
# single limb peak near 20-40 rad/s in a throw, the mean over the body stays far lower (real
# Bandai takes: at most 2). The cgspeed CMU T-pose frames jump at 28-54.
_MAX_MEAN_JOINT_SPEED_RAD_S = 10.0


@dataclass
class _Joint:
    name: str
    parent: int
    offset: np.ndarray
    channels: tuple[str, ...]
    line: int
    is_site: bool = False


class _Tokens:
    """Whitespace tokens of the HIERARCHY block with their 1-based line numbers."""

    def __init__(self, text: str, path: Path):
        self.items = [(tok, n + 1) for n, ln in enumerate(text.split("\n")) for tok in ln.split()]
        self.pos = 0
        self.path = path
        self.last_line = text.count("\n") + 1  # the MOTION line

    def error(self, message: str, line: int | None = None) -> MotionFormatError:
        return MotionFormatError(message, self.path, line or self.last_line)

    def next(self, what: str) -> tuple[str, int]:
        if self.pos >= len(self.items):
            raise self.error(f"hierarchy ends early: expected {what} before MOTION")
        item = self.items[self.pos]
        self.pos += 1
        return item

    def name(self, what: str, keyword_line: int) -> str:
        """The rest of the keyword's line as one name: rigs such as 3ds Max Biped use names
        with spaces (``JOINT Bip01 L Thigh``)."""
        parts = []
        while self.pos < len(self.items) and self.items[self.pos][1] == keyword_line:
            parts.append(self.items[self.pos][0])
            self.pos += 1
        if not parts:
            raise self.error(f"{what} is missing after the keyword", keyword_line)
        return " ".join(parts)

    def expect(self, word: str) -> int:
        tok, line = self.next(repr(word))
        if tok != word:
            raise self.error(f"expected {word!r}, found {tok!r}", line)
        return line

    def number(self, what: str) -> float:
        tok, line = self.next(what)
        try:
            value = float(tok)
        except ValueError:
            raise self.error(f"{what}: {tok!r} is not a number", line) from None
        if not np.isfinite(value):
            raise self.error(f"{what}: {tok!r} is not finite", line)
        return value


def _decode(raw: bytes, path: Path) -> str:
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise MotionFormatError(f"not UTF-8 text (byte {exc.start})", path, line) from None


def _parse_joint_header(tok: _Tokens, name: str, parent: int, line: int) -> _Joint:
    tok.expect("{")
    tok.expect("OFFSET")
    offset = np.array([tok.number("OFFSET") for _ in range(3)])
    tok.expect("CHANNELS")
    count_tok, count_line = tok.next("channel count")
    if not count_tok.isdigit() or int(count_tok) > 6:
        raise tok.error(f"channel count must be 0-6, found {count_tok!r}", count_line)
    channels = tuple(tok.next("channel name")[0] for _ in range(int(count_tok)))
    unknown = [c for c in channels if c not in _CHANNELS]
    if unknown or len(set(channels)) != len(channels):
        raise tok.error(
            f"joint {name!r}: bad channel list {' '.join(channels)} (expected {count_tok} distinct "
            f"of {', '.join(_CHANNELS)})",
            count_line,
        )
    return _Joint(name, parent, offset, channels, line)


def _parse_hierarchy(text: str, path: Path) -> list[_Joint]:
    """Joints in file order (depth-first, parents first), End Sites included."""
    tok = _Tokens(text, path)
    tok.expect("HIERARCHY")
    line = tok.expect("ROOT")
    joints = [_parse_joint_header(tok, tok.name("root name", line), -1, line)]
    names = {joints[0].name}
    open_joints = [0]
    while open_joints:
        word, line = tok.next("'JOINT', 'End Site' or '}'")
        if word == "}":
            open_joints.pop()
        elif word == "JOINT":
            name = tok.name("joint name", line)
            if name in names or name in "{}":
                raise tok.error(f"duplicate or invalid joint name {name!r}", line)
            joints.append(_parse_joint_header(tok, name, open_joints[-1], line))
            names.add(name)
            open_joints.append(len(joints) - 1)
        elif word == "End":
            tok.expect("Site")
            parent = open_joints[-1]
            name = f"{joints[parent].name}_end"
            k = 1
            while name in names:
                name, k = f"{joints[parent].name}_end{k}", k + 1
            tok.expect("{")
            tok.expect("OFFSET")
            offset = np.array([tok.number("End Site OFFSET") for _ in range(3)])
            tok.expect("}")
            joints.append(_Joint(name, parent, offset, (), line, is_site=True))
            names.add(name)
        else:
            raise tok.error(f"unknown keyword {word!r} in the hierarchy", line)
    if tok.pos < len(tok.items):
        word, line = tok.items[tok.pos]
        raise tok.error(f"unexpected {word!r} after the root joint closed (expected MOTION)", line)
    return joints


def _header_line(text: str, start: int, path: Path, line: int) -> tuple[list[str], int, int]:
    """Tokens of the next non-blank line at ``text[start:]``, its line number, and its end."""
    while True:
        end = text.find("\n", start)
        end = len(text) if end < 0 else end
        tokens = text[start:end].split()
        if tokens:
            return tokens, line, end + 1
        if end >= len(text):
            raise MotionFormatError("file ends inside the MOTION header", path, line)
        start, line = end + 1, line + 1


def _motion_header(
    text: str, start: int, first_line: int, path: Path
) -> tuple[int, float, int, int]:
    """Frames and Frame Time; returns (frames, frame_time, data_start, data_first_line)."""
    tokens, line, start = _header_line(text, start, path, first_line)
    if len(tokens) != 2 or tokens[0] != "Frames:" or not tokens[1].isdigit() or int(tokens[1]) < 1:
        raise MotionFormatError(
            f"expected 'Frames: N' with N >= 1, found {' '.join(tokens)!r}", path, line
        )
    frames = int(tokens[1])
    tokens, line, start = _header_line(text, start, path, line + 1)
    frame_time = float("nan")
    if len(tokens) == 3 and tokens[:2] == ["Frame", "Time:"]:
        try:
            frame_time = float(tokens[2])
        except ValueError:
            pass
    if not (np.isfinite(frame_time) and frame_time > 0):
        raise MotionFormatError(
            f"expected 'Frame Time: SECONDS' (positive), found {' '.join(tokens)!r}", path, line
        )
    lo, hi = 1.0 / FPS_RANGE[1], 1.0 / FPS_RANGE[0]
    if not lo <= frame_time <= hi:
        raise MotionFormatError(
            f"Frame Time {tokens[2]} s is not a mocap frame time ({lo:g}-{hi:g} s, i.e. "
            f"{FPS_RANGE[0]:g}-{FPS_RANGE[1]:g} fps)",
            path,
            line,
        )
    return frames, frame_time, start, line + 1


def _motion_values(
    data: str, frames: int, n_channels: int, path: Path, first_line: int
) -> np.ndarray:
    """``(frames, n_channels)`` floats of the frame lines.

    Fast path: frame data of plain decimal numbers, spaces, tabs and newlines only is read by
    ``np.loadtxt`` (its C parser, a third faster than ``np.fromstring``, also checks that every
    line has as many values as the first). Anything it does not read into finite values of the
    declared shape, or any other byte, goes to :func:`_checked_motion_values`, which finds the
    offending line (or reads what the fast path declined, e.g. a lone carriage return).
    """
    if not data.encode("utf-8").translate(None, _DECIMAL_BYTES):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)  # no data: the checked path says so
                values = np.loadtxt(io.StringIO(data), comments=None, ndmin=2)
        except ValueError:
            values = None
        if values is not None and values.shape == (frames, n_channels):
            if np.isfinite(values).all():
                return values
    return _checked_motion_values(data, frames, n_channels, path, first_line)


def _checked_motion_values(
    data: str, frames: int, n_channels: int, path: Path, first_line: int
) -> np.ndarray:
    """``(frames, n_channels)`` floats of the frame lines, validated line by line (vectorised)."""
    raw = np.frombuffer(data.encode("utf-8"), dtype=np.uint8)
    space = raw <= 32  # ASCII whitespace and control bytes separate values
    token_starts = np.flatnonzero(~space & np.concatenate([[True], space[:-1]]))
    newlines = np.flatnonzero(raw == 10)
    # Tokens per line from where each newline falls among the (sorted) token starts: a search
    # of the few newlines among the many tokens, not the other way round.
    per_line = np.diff(np.searchsorted(token_starts, newlines), prepend=0, append=token_starts.size)
    rows = np.flatnonzero(per_line)
    if rows.size < frames:
        last = first_line + (int(rows[-1]) if rows.size else 0)
        raise MotionFormatError(
            f"truncated: 'Frames: {frames}' but only {rows.size} frame lines", path, last
        )
    if rows.size > frames:
        raise MotionFormatError(
            f"more frame lines than 'Frames: {frames}'", path, first_line + int(rows[frames])
        )
    wrong = rows[per_line[rows] != n_channels]
    if wrong.size:
        n = int(per_line[wrong[0]])
        raise MotionFormatError(
            f"frame line has {n} values, the hierarchy declares {n_channels} channels",
            path,
            first_line + int(wrong[0]),
        )
    try:
        values = np.fromstring(data, sep=" ")  # C parser; raises on any non-number
    except ValueError:
        for k, ln in enumerate(data.split("\n")):
            for t in ln.split():
                try:
                    float(t)
                except ValueError:
                    raise MotionFormatError(
                        f"{t!r} is not a number", path, first_line + k
                    ) from None
        raise MotionFormatError("unreadable frame data", path, first_line) from None
    if values.size != frames * n_channels:  # str.split knows more whitespace than the byte count
        raise MotionFormatError("frame data contains unexpected characters", path, first_line)
    values = values.reshape(frames, n_channels)
    finite = np.isfinite(values).all(axis=1)
    if not finite.all():
        bad = int(np.argmin(finite))
        raise MotionFormatError(
            "NaN or infinite value in frame data", path, first_line + int(rows[bad])
        )
    return values


def _euler_quaternions(half: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """``(T, J, 4)`` wxyz of the intrinsic rotations ``q = qa qb qc`` about ``axes (J, 3)`` (a
    permutation of 0, 1, 2 per joint) by the half angles ``half (T, J, 3)``, in closed form.

    With ``e = +1`` for cyclic orders (``e_a x e_b = e_c``) and -1 otherwise, expanding the two
    Hamilton products of elementary quaternions gives
    ``w = ca cb cc - e sa sb sc``, ``a = sa cb cc + e ca sb sc``, ``b = ca sb cc - e sa cb sc``,
    ``c = ca cb sc + e sa sb cc`` (for XYZ the textbook Tait-Bryan formula).
    """
    c, s = np.cos(half), np.sin(half)
    ca, cb, cc = c[..., 0], c[..., 1], c[..., 2]
    sa, sb, sc = s[..., 0], s[..., 1], s[..., 2]
    e = np.where((axes[:, 1] - axes[:, 0]) % 3 == 1, 1.0, -1.0)  # (J,) cyclic or not
    ca_cb, sa_sb, sa_cb, ca_sb = ca * cb, sa * sb, sa * cb, ca * sb
    n_frames, n_joints = half.shape[:2]
    out = np.empty((n_frames, n_joints, 4))
    out[..., 0] = ca_cb * cc - e * sa_sb * sc
    vec = np.stack(
        [sa_cb * cc + e * ca_sb * sc, ca_sb * cc - e * sa_cb * sc, ca_cb * sc + e * sa_sb * cc],
        axis=-1,
    )
    # Scatter slot k of joint j to component 1 + axes[j, k]: one flat fancy assignment
    # (take_along_axis over a small last axis costs ten times more).
    target = 4 * np.arange(n_joints)[:, None] + 1 + axes
    out.reshape(n_frames, -1)[:, target.ravel()] = vec.reshape(n_frames, -1)
    return out


def _split_channels(
    joints: list[_Joint], values: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per joint: its position ``(T, J, 3)`` (the OFFSET, with each position channel replacing
    its axis), which joints have position channels ``(J,)``, and the local rotations
    ``(T, J, 4)`` wxyz, composed as intrinsic Euler rotations in channel order
    (``q = q1 q2 q3``) in one vectorised pass over all joints. A joint with fewer than three
    rotation channels gets its missing axes last, at angle 0, so every joint's order is a
    permutation of XYZ (:func:`_euler_quaternions`).
    """
    n_frames = values.shape[0]
    zero_col = values.shape[1]  # an appended column of zeros: the angle of a missing axis
    slot_col = np.full((len(joints), 3), zero_col)
    slot_axis = np.zeros((len(joints), 3), dtype=int)
    pos_col, pos_slot = [], []  # value column -> flat (joint, axis) slot of the positions
    col = 0
    for j, joint in enumerate(joints):
        axes = []
        for name in joint.channels:
            kind, axis = _CHANNELS[name]
            if kind == "position":
                pos_col.append(col)
                pos_slot.append(3 * j + "XYZ".index(axis))
            else:
                slot_col[j, len(axes)] = col
                axes.append("XYZ".index(axis))
            col += 1
        slot_axis[j] = axes + [a for a in range(3) if a not in axes]
    offsets = np.array([j.offset for j in joints])
    positions = np.broadcast_to(offsets.ravel(), (n_frames, offsets.size)).copy()
    positions[:, pos_slot] = values[:, pos_col]
    has_position = np.zeros(len(joints), dtype=bool)
    has_position[np.array(pos_slot, dtype=int) // 3] = True
    padded = np.concatenate([values, np.zeros((n_frames, 1))], axis=1)
    half = padded[:, slot_col] * (np.pi / 360.0)  # (T, J, 3) half angles in radians
    rot = _euler_quaternions(half, slot_axis)
    return positions.reshape(n_frames, len(joints), 3), has_position, rot


def _is_constant(a: np.ndarray) -> np.ndarray:
    """``a (T, ..., k)`` -> ``(...)`` bool: every one of the ``k`` columns is constant over
    time up to print precision."""
    scale = np.maximum(1.0, np.abs(a).max(axis=0))
    return np.all(np.ptp(a, axis=0) <= _CONSTANT_RTOL * scale, axis=-1)


def _root_and_offsets(
    joints: list[_Joint],
    positions: np.ndarray,
    has_position: np.ndarray,
    rot: np.ndarray,
    path: Path,
) -> tuple[np.ndarray, np.ndarray, str]:
    """Root trajectory ``(T, 3)``, offsets ``(J, 3)`` (file units) and the folded joint's name.

    ``positions (T, J, 3)``, ``has_position (J,)``: from :func:`_split_channels`;
    ``rot (T, J, 4)``: local rotations in the file's axes.
    """
    offsets = np.array([j.offset for j in joints])
    root = joints[0]
    root_pos = positions[:, 0].copy()
    if has_position[0]:  # the root's channels add to its OFFSET
        present = np.isin(["Xposition", "Yposition", "Zposition"], root.channels)
        root_pos += root.offset * present
    folded = ""
    placed = np.flatnonzero(has_position[1:]) + 1
    stacked = positions[:, placed]
    constant = _is_constant(stacked)  # all joints in one pass: Bandai files place every joint
    offsets[placed] = np.where(constant[:, None], stacked.mean(axis=0), offsets[placed])
    for j in placed[~constant]:
        pos = positions[:, j]
        root_turns = not _is_constant(rot[:, 0])
        only_child = [k for k in range(len(joints)) if joints[k].parent == 0] == [j]
        if joints[j].parent == 0 and not root_turns and only_child:
            root_pos = root_pos + quat.rotate(rot[0, 0], pos)
            offsets[j] = 0.0
            folded = joints[j].name
            continue
        raise MotionFormatError(
            f"joint {joints[j].name!r} has moving position channels; only the root (or the single "
            "child of a root that does not rotate) may translate",
            path,
            joints[j].line,
        )
    return root_pos, offsets, folded


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
    joints = _parse_hierarchy(text[: found.start()], path)
    n_channels = sum(len(j.channels) for j in joints)
    motion_line = text.count("\n", 0, found.start()) + 1
    if n_channels == 0:
        raise MotionFormatError("the hierarchy declares no channels", path, motion_line)
    frames, frame_time, start, first_line = _motion_header(
        text, found.end() + 1, motion_line + 1, path
    )
    values = _motion_values(text[start:], frames, n_channels, path, first_line)
    positions, has_position, rot = _split_channels(joints, values)
    root_pos, offsets, folded = _root_and_offsets(joints, positions, has_position, rot, path)

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

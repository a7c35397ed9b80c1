"""The HIERARCHY block of a BVH file: joints, offsets, channels (see :mod:`..bvh`)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from avatarsim.avatar_models.errors import MotionFormatError

CHANNELS = {f"{a}{kind}": (kind, a) for a in "XYZ" for kind in ("position", "rotation")}
"""BVH channel name -> (``"position"`` | ``"rotation"``, axis letter)."""


@dataclass
class BvhJoint:
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


def _parse_joint_header(tok: _Tokens, name: str, parent: int, line: int) -> BvhJoint:
    tok.expect("{")
    tok.expect("OFFSET")
    offset = np.array([tok.number("OFFSET") for _ in range(3)])
    tok.expect("CHANNELS")
    count_tok, count_line = tok.next("channel count")
    if not count_tok.isdigit() or int(count_tok) > 6:
        raise tok.error(f"channel count must be 0-6, found {count_tok!r}", count_line)
    channels = tuple(tok.next("channel name")[0] for _ in range(int(count_tok)))
    unknown = [c for c in channels if c not in CHANNELS]
    if unknown or len(set(channels)) != len(channels):
        raise tok.error(
            f"joint {name!r}: bad channel list {' '.join(channels)} (expected {count_tok} distinct "
            f"of {', '.join(CHANNELS)})",
            count_line,
        )
    return BvhJoint(name, parent, offset, channels, line)


def parse_hierarchy(text: str, path: Path) -> list[BvhJoint]:
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
            joints.append(BvhJoint(name, parent, offset, (), line, is_site=True))
            names.add(name)
        else:
            raise tok.error(f"unknown keyword {word!r} in the hierarchy", line)
    if tok.pos < len(tok.items):
        word, line = tok.items[tok.pos]
        raise tok.error(f"unexpected {word!r} after the root joint closed (expected MOTION)", line)
    return joints

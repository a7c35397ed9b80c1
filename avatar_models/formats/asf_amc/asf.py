"""The ASF skeleton file: units, root, bone data and hierarchy, and the Z-up
:class:`~avatar_models.skeleton.Skeleton` it gives (conventions: :mod:`..asf_amc`)."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from avatarsim.avatar_models.errors import MotionFormatError, MotionValueError
from avatarsim.avatar_models.formats.units import UNITS, Y_UP_TO_Z_UP, unit_scale
from avatarsim.avatar_models.skeleton import Skeleton

_SECTIONS = (":version", ":name", ":units", ":documentation", ":root", ":bonedata", ":hierarchy")
_REQUIRED = (":units", ":root", ":bonedata", ":hierarchy")
_ROTATION_DOFS = ("rx", "ry", "rz")
_ROOT_CHANNELS = ("tx", "ty", "tz", "rx", "ry", "rz")
_AXIS_ORDER = re.compile(r"^[xyz]{3}$")


@dataclass(frozen=True)
class AsfBone:
    """One ``:bonedata`` block, in file units and the file's Y-up frame.

    Attributes:
        direction: ``(3,)`` bone direction in the world rest frame.
        length: bone length (file length units).
        axis: ``(3, 3)`` the bone's axis frame ``C``.
        dofs: rotation DOF names in AMC column order, e.g. ``("rx", "ry", "rz")``.
        limits: one ``(lo, hi)`` radian range per DOF (may be infinite).
    """

    name: str
    direction: np.ndarray
    length: float
    axis: np.ndarray
    dofs: tuple[str, ...]
    limits: tuple[tuple[float, float], ...]
    line: int


@dataclass(frozen=True)
class Asf:
    """A parsed ASF file. ``bones`` in hierarchy (depth-first) order, ``parent`` per bone
    (``"root"`` for the root's children); ``root_order`` the AMC root channels."""

    path: Path
    name: str
    version: str
    documentation: str
    units: dict[str, str | float]
    metres_per_unit: float
    root_order: tuple[str, ...]
    root_axis: np.ndarray
    root_position: np.ndarray
    bones: dict[str, AsfBone]
    parent: dict[str, str] = field(default_factory=dict)


def parse_floats(tokens: list[str], n: int, what: str, path: Path, line: int, finite: bool = True):
    """``n`` floats from ``tokens`` or a MotionFormatError naming ``what``."""
    if len(tokens) != n:
        raise MotionFormatError(f"{what} needs {n} numbers, got {len(tokens)}", path, line)
    try:
        values = np.array([float(t) for t in tokens])
    except ValueError:
        raise MotionFormatError(f"{what}: non-numeric value in {tokens}", path, line) from None
    if np.any(np.isnan(values)) or (finite and not np.all(np.isfinite(values))):
        raise MotionFormatError(f"{what}: NaN or infinite value in {tokens}", path, line)
    return values


def _euler_frame(values: np.ndarray, order: str, to_rad: float) -> np.ndarray:
    """``(3, 3)`` frame from Euler ``values`` listed in ``order`` (extrinsic, first applied
    first)."""
    return Rotation.from_euler(order, values * to_rad).as_matrix()


def _axis_order(token: str, path: Path, line: int) -> str:
    order = token.lower()
    if not _AXIS_ORDER.match(order) or len(set(order)) != 3:
        raise MotionFormatError(
            f"axis order must be a permutation of XYZ, got {token!r}", path, line
        )
    return order


def _read_lines(path: Path) -> list[tuple[int, list[str]]]:
    """Non-blank, non-comment lines as ``(1-based line number, tokens)``."""
    try:
        text = path.read_bytes().decode("utf-8", errors="replace")
    except OSError as exc:
        raise MotionFormatError(f"cannot read: {exc.strerror}", path) from None
    rows = []
    for i, raw in enumerate(text.splitlines(), start=1):
        tokens = raw.split()
        if tokens and not tokens[0].startswith("#"):
            rows.append((i, tokens))
    if not rows:
        raise MotionFormatError("file is empty", path)
    return rows


def _split_sections(path: Path, rows) -> dict[str, tuple[int, list[tuple[int, list[str]]]]]:
    """``{":keyword": (line, body rows)}``; the keyword's own line's extra tokens lead the body."""
    sections: dict[str, tuple[int, list]] = {}
    current = None
    for line, tokens in rows:
        if tokens[0].startswith(":"):
            key = tokens[0].lower()
            if key not in _SECTIONS:
                raise MotionFormatError(f"unknown ASF section {tokens[0]!r}", path, line)
            if key in sections:
                raise MotionFormatError(f"section {tokens[0]!r} appears twice", path, line)
            sections[key] = (line, [(line, tokens[1:])] if len(tokens) > 1 else [])
            current = key
        elif current is None:
            raise MotionFormatError(f"text before the first ':section': {tokens[0]!r}", path, line)
        else:
            sections[current][1].append((line, tokens))
    for key in _REQUIRED:
        if key not in sections:
            raise MotionFormatError(f"missing section {key}", path)
    return sections


def _parse_units(path: Path, body) -> dict[str, str | float]:
    units: dict[str, str | float] = {"mass": 1.0, "length": 1.0, "angle": "deg"}
    for line, tokens in body:
        key = tokens[0].lower()
        if key in ("mass", "length"):
            (value,) = parse_floats(tokens[1:], 1, f"units {key}", path, line)
            if value <= 0:
                raise MotionFormatError(f"units {key} must be positive, got {value}", path, line)
            units[key] = float(value)
        elif key == "angle":
            if len(tokens) != 2 or tokens[1].lower() not in ("deg", "rad"):
                raise MotionFormatError("units angle must be 'deg' or 'rad'", path, line)
            units["angle"] = tokens[1].lower()
        else:
            raise MotionFormatError(f"unknown units keyword {tokens[0]!r}", path, line)
    return units


def _parse_root(path: Path, body, to_rad: float):
    fields: dict[str, tuple[int, list[str]]] = {}
    for line, tokens in body:
        key = tokens[0].lower()
        if key not in ("order", "axis", "position", "orientation"):
            raise MotionFormatError(f"unknown root keyword {tokens[0]!r}", path, line)
        fields[key] = (line, tokens[1:])
    for key in ("order", "axis", "position", "orientation"):
        if key not in fields:
            raise MotionFormatError(f"root lacks '{key}'", path)
    line, order_tokens = fields["order"]
    order = tuple(t.lower() for t in order_tokens)
    if any(c not in _ROOT_CHANNELS for c in order) or len(set(order)) != len(order):
        raise MotionFormatError(
            f"root order must list distinct TX..RZ, got {order_tokens}", path, line
        )
    line, axis_tokens = fields["axis"]
    if len(axis_tokens) != 1:
        raise MotionFormatError("root axis must be one order string such as XYZ", path, line)
    axis_order = _axis_order(axis_tokens[0], path, line)
    position = parse_floats(fields["position"][1], 3, "root position", path, fields["position"][0])
    line, orient_tokens = fields["orientation"]
    orientation = parse_floats(orient_tokens, 3, "root orientation", path, line)
    return order, _euler_frame(orientation, axis_order, to_rad), position


def _parse_bone(path: Path, begin_line: int, body, to_rad: float) -> AsfBone:
    fields: dict[str, tuple[int, list[str]]] = {}
    limit_rows: list[tuple[int, list[str]]] = []
    in_limits = False
    for line, tokens in body:
        key = tokens[0].lower()
        if in_limits and tokens[0].startswith("("):
            limit_rows.append((line, tokens))
            continue
        in_limits = key == "limits"
        if key not in (
            "id",
            "name",
            "direction",
            "length",
            "axis",
            "dof",
            "limits",
            "bodymass",
            "cofmass",
        ):
            raise MotionFormatError(f"unknown bone keyword {tokens[0]!r}", path, line)
        if key in fields:
            raise MotionFormatError(f"bone keyword {key!r} given twice", path, line)
        fields[key] = (line, tokens[1:])
        if in_limits and len(tokens) > 1:
            limit_rows.append((line, tokens[1:]))
    for key in ("name", "direction", "length", "axis"):
        if key not in fields:
            raise MotionFormatError(f"bone block lacks '{key}'", path, begin_line)
    line, name_tokens = fields["name"]
    if len(name_tokens) != 1:
        raise MotionFormatError("bone name must be one word", path, line)
    name = name_tokens[0]
    direction = parse_floats(
        fields["direction"][1], 3, f"{name} direction", path, fields["direction"][0]
    )
    (length,) = parse_floats(fields["length"][1], 1, f"{name} length", path, fields["length"][0])
    line, axis_tokens = fields["axis"]
    if len(axis_tokens) != 4:
        raise MotionFormatError(f"{name} axis needs 3 angles and an order such as XYZ", path, line)
    axis_order = _axis_order(axis_tokens[3], path, line)
    axis = _euler_frame(
        parse_floats(axis_tokens[:3], 3, f"{name} axis", path, line), axis_order, to_rad
    )
    dofs: tuple[str, ...] = ()
    if "dof" in fields:
        line, dof_tokens = fields["dof"]
        dofs = tuple(t.lower() for t in dof_tokens)
        if not dofs or any(d not in _ROTATION_DOFS for d in dofs) or len(set(dofs)) != len(dofs):
            raise MotionFormatError(
                f"{name} dof must list distinct rx/ry/rz (translation and length DOFs are not "
                f"supported), got {dof_tokens}",
                path,
                line,
            )
    limits = []
    for line, tokens in limit_rows:
        inner = " ".join(tokens).replace("(", " ").replace(")", " ").replace(",", " ").split()
        lo, hi = parse_floats(inner, 2, f"{name} limits", path, line, finite=False)
        if lo > hi:
            raise MotionFormatError(f"{name} limits ({lo}, {hi}) are reversed", path, line)
        limits.append((float(lo * to_rad), float(hi * to_rad)))
    if limit_rows and len(limits) != len(dofs):
        raise MotionFormatError(
            f"{name} has {len(dofs)} DOFs but {len(limits)} limits", path, limit_rows[0][0]
        )
    return AsfBone(name, direction, float(length), axis, dofs, tuple(limits), begin_line)


def _parse_bonedata(path: Path, body, to_rad: float) -> dict[str, AsfBone]:
    bones: dict[str, AsfBone] = {}
    block: list | None = None
    begin_line = 0
    for line, tokens in body:
        key = tokens[0].lower()
        if key == "begin":
            if block is not None:
                raise MotionFormatError("'begin' inside a bone block (missing 'end')", path, line)
            block, begin_line = [], line
        elif key == "end":
            if block is None:
                raise MotionFormatError("'end' without 'begin'", path, line)
            bone = _parse_bone(path, begin_line, block, to_rad)
            if bone.name in bones or bone.name == "root":
                raise MotionFormatError(f"bone name {bone.name!r} used twice", path, begin_line)
            bones[bone.name] = bone
            block = None
        elif block is None:
            raise MotionFormatError(f"bone data outside begin/end: {tokens[0]!r}", path, line)
        else:
            block.append((line, tokens))
    if block is not None:
        raise MotionFormatError(
            "bone block not closed by 'end' (truncated file?)", path, begin_line
        )
    if not bones:
        raise MotionFormatError("no bones in :bonedata", path)
    return bones


def _parse_hierarchy(path: Path, body, bones: dict[str, AsfBone]) -> dict[str, str]:
    """``{bone: parent}`` for every bone; raises on unknown names, cycles and orphan bones."""
    if not body or body[0][1][0].lower() != "begin" or body[-1][1][0].lower() != "end":
        line = body[0][0] if body else None
        raise MotionFormatError(":hierarchy must be enclosed in begin ... end", path, line)
    parent: dict[str, str] = {}
    for line, tokens in body[1:-1]:
        if tokens[0] != "root" and tokens[0] not in bones:
            raise MotionFormatError(f"hierarchy names unknown bone {tokens[0]!r}", path, line)
        for child in tokens[1:]:
            if child not in bones:
                raise MotionFormatError(f"hierarchy names unknown bone {child!r}", path, line)
            if child in parent:
                raise MotionFormatError(f"bone {child!r} has two parents", path, line)
            parent[child] = tokens[0]
    orphans = [b for b in bones if b not in parent]
    if orphans:
        raise MotionFormatError(
            f"bones not in the hierarchy: {orphans}", path, bones[orphans[0]].line
        )
    for bone in bones:  # every chain must reach the root
        seen, b = set(), bone
        while b != "root":
            if b in seen:
                raise MotionFormatError(f"hierarchy has a cycle through {bone!r}", path)
            seen.add(b)
            b = parent[b]
    return parent


def _depth_first(parent: dict[str, str], bones: dict[str, AsfBone]) -> list[str]:
    children: dict[str, list[str]] = {}
    for child, par in parent.items():
        children.setdefault(par, []).append(child)
    order, stack = [], list(reversed(children.get("root", [])))
    while stack:
        b = stack.pop()
        order.append(b)
        stack.extend(reversed(children.get(b, [])))
    return order


def read_asf(path: str | Path, unit: str | float = "asf") -> Asf:
    """Parse an ASF skeleton file.

    Args:
        path: the ``.asf`` file.
        unit: ``"asf"`` to honour ``:units length`` (inches / length), or a unit name of
            :data:`~avatar_models.formats.units.UNITS` or metres per file unit.
    """
    path = Path(path)
    rows = _read_lines(path)
    sections = _split_sections(path, rows)
    units = _parse_units(path, sections[":units"][1])
    to_rad = np.pi / 180.0 if units["angle"] == "deg" else 1.0
    if unit == "asf":
        metres_per_unit = UNITS["inch"] / float(units["length"])
    else:
        metres_per_unit = unit_scale(unit, path)
    root_order, root_axis, root_position = _parse_root(path, sections[":root"][1], to_rad)
    bones = _parse_bonedata(path, sections[":bonedata"][1], to_rad)
    parent = _parse_hierarchy(path, sections[":hierarchy"][1], bones)
    order = _depth_first(parent, bones)

    def text(key: str) -> str:
        return " ".join(" ".join(t) for _, t in sections.get(key, (0, []))[1])

    return Asf(
        path=path,
        name=text(":name"),
        version=text(":version"),
        documentation="\n".join(" ".join(t) for _, t in sections.get(":documentation", (0, []))[1]),
        units=units,
        metres_per_unit=metres_per_unit,
        root_order=root_order,
        root_axis=root_axis,
        root_position=root_position,
        bones={b: bones[b] for b in order},
        parent={b: parent[b] for b in order},
    )


def asf_skeleton(asf: Asf) -> tuple[Skeleton, dict[str, np.ndarray]]:
    """The Z-up metre :class:`Skeleton` of ``asf`` and each rotating joint's frame ``K C``.

    Joints: ``root``, then the bones depth first, an end site ``<bone>_end`` after each leaf.
    """
    scale = asf.metres_per_unit
    names, parents, offsets, is_site = ["root"], [-1], [np.zeros(3)], [False]
    frames = {"root": Y_UP_TO_Z_UP @ asf.root_axis}
    index = {"root": 0}
    has_child = set(asf.parent.values())

    def add(name: str, par: str, offset: np.ndarray, site: bool) -> None:
        if name in index:
            raise MotionFormatError(f"joint name {name!r} clashes with an end site name", asf.path)
        index[name] = len(names)
        names.append(name)
        parents.append(index[par])
        offsets.append(Y_UP_TO_Z_UP @ offset * scale)
        is_site.append(site)

    def vector(bone: str) -> np.ndarray:
        return np.zeros(3) if bone == "root" else asf.bones[bone].direction * asf.bones[bone].length

    for name, bone in asf.bones.items():
        par = asf.parent[name]
        add(name, par, vector(par), False)
        frames[name] = Y_UP_TO_Z_UP @ bone.axis
        if name not in has_child:
            add(f"{name}_end", name, vector(name), True)
    limits = {
        name: {dof: lim for dof, lim in zip(bone.dofs, bone.limits, strict=True)}
        for name, bone in asf.bones.items()
        if bone.limits
    }
    try:
        skeleton = Skeleton(
            names, parents, np.array(offsets), np.array(is_site), limits, name="asf"
        )
    except MotionValueError as exc:
        raise MotionFormatError(f"invalid skeleton: {exc}", asf.path) from None
    return skeleton, frames

"""Rigs as data: TOML files under ``avatar_models/rigs/`` loaded into :class:`Rig`.

A rig file::

    name = "kinect_v2"
    description = "..."
    [[joints]]                      # in topological order, root first
    name = "SpineBase"
    parent = ""                     # "" for the root
    offset = [0.0, 0.0, 0.95]       # metres, Z up, rest pose facing +X
    site = false                    # optional: an end site
    [body17]                        # body17 name -> joint name (all 17 keys)
    head = "Head"
    [limits.SomeJoint]              # optional, degrees (converted to radians on load)
    rx = [-10.0, 10.0]

Skeletons read from files (BVH, ASF) are matched to a rig by their joint names
(:func:`identify_rig`), which gives them a ``body17`` map.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

from avatarsim.avatar_models.body17 import BODY17
from avatarsim.avatar_models.errors import RigError
from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.skeleton import Skeleton

RIG_DIR = Path(__file__).parent / "rigs"


@dataclass(frozen=True)
class Rig:
    """A named skeleton with its ``body17`` map (body17 name -> joint name)."""

    name: str
    skeleton: Skeleton
    body17: dict[str, str]
    description: str = ""

    def body17_indices(self, skeleton: Skeleton | None = None) -> np.ndarray:
        """``(17,)`` joint indices of the body17 joints in ``skeleton`` (default: the rig's)."""
        sk = self.skeleton if skeleton is None else skeleton
        return sk.indices([self.body17[b] for b in BODY17])


def available_rigs() -> list[str]:
    return sorted(p.stem for p in RIG_DIR.glob("*.toml"))


def parse_rig(data: dict, source: str = "<rig>") -> Rig:
    """Build a :class:`Rig` from the parsed TOML table ``data``."""
    try:
        joints = data["joints"]
        names = [str(j["name"]) for j in joints]
        index = {n: i for i, n in enumerate(names)}
        parents = [index[j["parent"]] if j.get("parent") else -1 for j in joints]
        offsets = np.array([j["offset"] for j in joints], dtype=float)
        is_site = np.array([bool(j.get("site", False)) for j in joints])
        limits = {
            jn: {
                ax: (float(np.radians(lo)), float(np.radians(hi))) for ax, (lo, hi) in axes.items()
            }
            for jn, axes in data.get("limits", {}).items()
        }
        skeleton = Skeleton(names, parents, offsets, is_site, limits, name=str(data["name"]))
        body17 = {str(k): str(v) for k, v in data["body17"].items()}
    except (KeyError, TypeError, ValueError) as exc:
        raise RigError(f"{source}: invalid rig description ({type(exc).__name__}: {exc})") from exc
    missing = [b for b in BODY17 if b not in body17]
    if missing:
        raise RigError(f"{source}: body17 map lacks {missing}")
    unknown = [v for v in body17.values() if v not in skeleton]
    if unknown:
        raise RigError(f"{source}: body17 map names joints the rig lacks: {unknown}")
    return Rig(str(data["name"]), skeleton, body17, str(data.get("description", "")))


@cache
def load_rig(name: str) -> Rig:
    """The rig ``name`` from ``avatar_models/rigs/NAME.toml``."""
    path = RIG_DIR / f"{name}.toml"
    if not path.is_file():
        raise RigError(f"unknown rig {name!r}; available: {', '.join(available_rigs())}")
    with path.open("rb") as fh:
        return parse_rig(tomllib.load(fh), str(path))


def identify_rig(skeleton: Skeleton) -> Rig:
    """The known rig whose body17 joints all exist in ``skeleton``, best name overlap first.

    Raises :class:`RigError` if no rig's body17 map fits the skeleton's joint names.
    """
    if skeleton.name in available_rigs():
        rig = load_rig(skeleton.name)
        if all(v in skeleton for v in rig.body17.values()):
            return rig
    best, best_score = None, -1.0
    names = set(skeleton.names)
    for rig_name in available_rigs():
        rig = load_rig(rig_name)
        if not all(v in names for v in rig.body17.values()):
            continue
        score = len(names & set(rig.skeleton.names)) / len(names | set(rig.skeleton.names))
        if score > best_score:
            best, best_score = rig, score
    if best is None:
        raise RigError(
            f"no known rig matches this skeleton ({skeleton.n_joints} joints: "
            f"{', '.join(skeleton.names[:8])}...); known rigs: {', '.join(available_rigs())}"
        )
    return best


def body17_positions(motion: Motion) -> np.ndarray:
    """``(T, 17, 3)`` world positions of the body17 joints of ``motion``."""
    rig = identify_rig(motion.skeleton)
    return motion.global_positions()[:, rig.body17_indices(motion.skeleton)]

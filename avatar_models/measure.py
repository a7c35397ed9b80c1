"""Body measures of skeletons and motions: standing height, lowest point, bone lengths in motion.

Standing height is estimated from bone lengths only, so it does not depend on the rest pose
(BVH rest poses are T-poses, A-poses or, as in the Bandai rig, not upright at all) nor on how
the character moves. Along the body17 joints of the skeleton's rig (:func:`rigs.identify_rig`)::

    M = leg + hip_drop + trunk + neck_to_head          (ankle joint -> head joint)
    H = (M + head_top) / (1 - ANKLE_FRAC)               when the head has an end site
    H = M / (1 - ANKLE_FRAC - HEAD_TOP_FRAC)            otherwise

``leg`` is the path length hip -> knee -> ankle (mean of both sides), ``hip_drop`` the rest
distance from the pelvis joint to the midpoint of the two hip joints, ``trunk`` and
``neck_to_head`` path lengths through the spine joints, ``head_top`` the longest end-site path
above the head joint. The allowances are fractions of the height after Drillis & Contini
(1966), as tabulated in D. A. Winter, *Biomechanics and Motor Control of Human Movement*,
4th ed., Fig. 4.1: the ankle joint is 0.039 H above the floor; the head joint of a rig sits
at the skull base, about 0.90 H (between chin 0.870 H and eye level 0.936 H), leaving
0.10 H to the top of the head. Check: the body17 rig (a 1.75 m adult) gives 1.765 m.

Skeletons that match no rig are assumed to stand upright in their rest pose; their height
is then the vertical extent of the rest pose.
"""

from __future__ import annotations

import numpy as np

from avatarsim.avatar_models.errors import MotionFormatError, MotionValueError, RigError
from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.rigs import identify_rig
from avatarsim.avatar_models.skeleton import Skeleton

ANKLE_FRAC = 0.039  # ankle joint height / standing height (Drillis & Contini 1966)
HEAD_TOP_FRAC = 0.10  # skull-base head joint to the top of the head / standing height


def path_length(skeleton: Skeleton, a: int, b: int) -> float:
    """Sum of bone lengths on the tree path between joints ``a`` and ``b``."""
    ca, cb = skeleton.chain(a), skeleton.chain(b)
    k = 0
    while k < min(len(ca), len(cb)) and ca[k] == cb[k]:
        k += 1
    lengths = skeleton.bone_lengths
    return float(lengths[ca[k:]].sum() + lengths[cb[k:]].sum())


def _head_top(skeleton: Skeleton, head: int) -> float:
    """Longest path from the head joint to an end site below it (0 when it has none)."""
    sites = [j for j in np.flatnonzero(skeleton.is_site) if head in skeleton.chain(int(j))]
    return max((path_length(skeleton, head, int(j)) for j in sites), default=0.0)


def standing_height(subject: Motion | Skeleton) -> float:
    """Estimated standing height (in the skeleton's length unit, metres for a ``Motion``).

    See the module docstring for the estimate; it uses bone lengths only.
    """
    sk = subject.skeleton if isinstance(subject, Motion) else subject
    try:
        rig = identify_rig(sk)
    except RigError:
        rest_z = sk.rest_positions()[:, 2]
        return float(rest_z.max() - rest_z.min())
    j = {b: sk.index(n) for b, n in rig.body17.items()}
    leg = 0.5 * sum(
        path_length(sk, j[f"{s}_hip"], j[f"{s}_knee"])
        + path_length(sk, j[f"{s}_knee"], j[f"{s}_ankle"])
        for s in ("l", "r")
    )
    rest = sk.rest_positions()
    hip_drop = float(
        np.linalg.norm(0.5 * (rest[j["l_hip"]] + rest[j["r_hip"]]) - rest[j["pelvis"]])
    )
    trunk = path_length(sk, j["pelvis"], j["neck"])
    neck_to_head = path_length(sk, j["neck"], j["head"])
    ankle_to_head = leg + hip_drop + trunk + neck_to_head
    head_top = _head_top(sk, j["head"])
    if head_top > 0:
        return (ankle_to_head + head_top) / (1.0 - ANKLE_FRAC)
    return ankle_to_head / (1.0 - ANKLE_FRAC - HEAD_TOP_FRAC)


def lowest_point(motion: Motion) -> np.ndarray:
    """``(T,)`` height (z) of the lowest joint or end site in each frame."""
    return motion.global_positions()[..., 2].min(axis=1)


def bone_lengths_over_time(motion: Motion) -> np.ndarray:
    """``(T, J)`` distance of each joint from its parent in world space (0 for the root)."""
    pos = motion.global_positions()
    parents = motion.skeleton.parents.copy()
    parents[0] = 0
    return np.linalg.norm(pos - pos[:, parents], axis=-1)


# Standing heights a motion of a person can have (metres): a small child to a very tall adult.
PLAUSIBLE_HEIGHT_M = (0.5, 2.5)


def check_plausible_height(motion: Motion) -> float:
    """The motion's standing height (m); a :class:`MotionValueError` when it is no person's,
    which after a unit conversion means the wrong unit (the message names the one that fits)."""
    from avatarsim.avatar_models.formats.units import detect_unit

    height = standing_height(motion)
    lo, hi = PLAUSIBLE_HEIGHT_M
    if lo <= height <= hi:
        return height
    unit = motion.meta.get("unit")
    scale = motion.meta.get("unit_scale_m") or motion.meta.get("metres_per_unit")
    used = f" with unit {unit!r}" if isinstance(unit, str) and unit != "custom" else ""
    hint = ""
    if scale:
        try:
            name, _ = detect_unit(height / scale)
            hint = f"; its lengths fit unit {name!r} (--unit {name})"
        except MotionFormatError:
            pass
    raise MotionValueError(
        f"the body is {height:.3g} m tall{used}, not a person's height ({lo:g}-{hi:g} m){hint}"
    )

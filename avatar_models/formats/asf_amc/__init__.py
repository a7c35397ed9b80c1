"""Acclaim ASF (skeleton) + AMC (motion) reader, as used by the CMU mocap database.

Modules: :mod:`.asf` (the skeleton file, :func:`read_asf`, :func:`asf_skeleton`) and
:mod:`.amc` (the motion file, :func:`read_asf_amc`).

References: the Acclaim ASF/AMC format description (J. Lander, "Working with Motion Capture
File Formats", Game Developer 1998; mirrored at research.cs.wisc.edu/graphics/Courses/
cs-838-1999/Jeff/ASF-AMC.html) and the readers it is checked against: CalciferZh/AMCParser
(``amc_parser.py``) and dm_control's CMU parser (``suite/utils/parse_amc.py``).

Conventions of the ASF, kept here:

- Each bone has a ``direction`` (unit vector in the world rest frame), a ``length`` and an
  ``axis`` frame ``C`` (Euler angles, order given by the trailing letters, e.g. ``XYZ``; the
  angles are listed in that order). Per frame the AMC gives Euler angles of a rotation ``M``
  about ``C``'s axes, in the order of the bone's ``dof`` line (``rx ry rz`` -> x first, then
  y, then z, i.e. ``M = Rz Ry Rx`` as in amc_parser's ``euler2mat(.., 'sxyz')``).
- The bone's world rotation is ``G = G_parent C M C^-1``, so its rotation relative to its
  parent is ``L = C M C^-1``; its tip is ``start + G direction length``.

Mapping onto a :class:`~avatar_models.skeleton.Skeleton` (offsets rotated by the parent's
rotation, as in BVH): the joint that *rotates* a bone has to sit where the bone starts, so
joint ``b`` is placed at the start of bone ``b`` (the tip of its parent bone) with
``L_b = C M C^-1``, its offset is the parent bone's ``direction * length`` (zero for the
children of ``root``), and every leaf bone ``b`` gets an end site ``b_end`` at its tip. This is
the layout of the CMU BVH conversions (``LeftUpLeg`` = ``lfemur`` sits at the hip). The
standard readers report the *tip* of each bone under the bone's name;
:func:`bone_tip_positions` gives exactly those (the position of a joint's first child or site).

Frames: the ASF's Y-up world (rest pose facing +Z) becomes Z up facing +X with
``K = [[0,0,1],[1,0,0],[0,1,0]]`` (as the BVH reader): offsets and translations ``K v``,
rotations ``K L K^T``. Lengths: ``:units length s`` means file values times ``1/s`` are inches,
so metres = value * (1/s) * 0.0254 (CMU: s = 0.45 -> 0.056444 m per unit).

Limits: ``Skeleton.limits[b]["rx"|"ry"|"rz"]`` are the ASF ranges of ``M``'s Euler angles in
radians, i.e. about the axes of bone ``b``'s frame ``C``, not of the Z-up world; those axes in
the Z-up rest frame (the columns of ``K C``) are in ``motion.meta["limit_axes"][b]``.
"""

from avatarsim.avatar_models.formats.asf_amc.amc import (
    CMU_FPS,
    bone_tip_positions,
    find_asf,
    read_amc_channels,
    read_asf_amc,
)
from avatarsim.avatar_models.formats.asf_amc.asf import Asf, AsfBone, asf_skeleton, read_asf

__all__ = [
    "CMU_FPS",
    "Asf",
    "AsfBone",
    "asf_skeleton",
    "bone_tip_positions",
    "find_asf",
    "read_amc_channels",
    "read_asf",
    "read_asf_amc",
]

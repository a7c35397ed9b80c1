"""BVH (Biovision hierarchy) reader and writer.

Modules: :mod:`.hierarchy` (the HIERARCHY block), :mod:`.frames` (the MOTION block),
:mod:`.channels` (channel values to joint positions and rotations), :mod:`.reader`
(:func:`read_bvh`), :mod:`.writer` (:func:`write_bvh`).

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

from avatarsim.avatar_models.formats.bvh.reader import prepended_rest_frame, read_bvh
from avatarsim.avatar_models.formats.bvh.writer import write_bvh

__all__ = ["prepended_rest_frame", "read_bvh", "write_bvh"]

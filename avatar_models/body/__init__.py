"""The body: one description of a humanoid that yields the MuJoCo model and the render mesh.

``build_body(skeleton)`` turns any skeleton :func:`avatar_models.rigs.identify_rig` recognises
into a :class:`BodyDescription`: capsules per bone with de Leva (1996) masses, box or capsule
feet split at the ball of the foot (the toes are a joint), a skull sphere, anatomical hinge
ranges. From it, ``spec`` is its ``mujoco.MjSpec`` (free root, three hinges and position
actuators per simulated joint, floor, contacts, body17 sites), ``model`` that spec compiled
once, ``to_mjcf()`` its MJCF text, :func:`control_spec` the physics-control variant of a
spec, ``qpos_from_motion(motion)`` the exact MuJoCo ``qpos`` of a motion on that skeleton,
and ``to_trimesh(...)`` the same primitives posed for one frame. MuJoCo is imported only in
:mod:`avatar_models.body.mjcf`, :mod:`avatar_models.body.control` and the IK.
"""

from avatarsim.avatar_models.body.control import control_spec
from avatarsim.avatar_models.body.description import BodyDescription, build_body
from avatarsim.avatar_models.body.errors import BodyError, RestPoseNotUprightError
from avatarsim.avatar_models.body.geometry import Segment
from avatarsim.avatar_models.body.mjcf import hinge_name

__all__ = [
    "BodyDescription",
    "BodyError",
    "RestPoseNotUprightError",
    "Segment",
    "build_body",
    "control_spec",
    "hinge_name",
]

"""Where the fisheye cameras sit: two per controller, on the upper ring and the grip's bottom.

ControllerPose §4.1 instruments each controller with one camera "on the upper ring" and one
"mounted to the bottom of the grip", both looking back at the user, and reports that the two
120 deg vertical fields of view composite to 185 deg: so their optical axes are 65 deg apart
in pitch. Here each looks back along the controller's -X (towards the user), the ring camera
pitched up by 20 deg and the grip camera down by 45 deg, with the image's x axis along the
controller's +Y, so the image is upright when the controller is held level with its ring up
(:mod:`render_cams.vr.placements`). The split of the 65 deg is our choice, not the paper's:
held in front of the chest, a controller has the head less than 45 deg above its back axis
and the feet up to 70 deg below, so the composite's 185 deg are centred 12.5 deg below it.
Mounting offsets in the controller frame (+X pointing, +Y left, +Z up; see
:mod:`render_cams.vr.placements`) are
plausible values for a Quest 2 controller chosen here, not measurements: the ring 6 cm above
and 2 cm in front of the palm centre, the grip's bottom 6 cm below and 2 cm behind it (the
palm closes round the middle of a grip about 11 cm long). A mount 8 cm below put the camera
inside the chest in a boxing guard and inside the hip in a short runner's arm swing, where
a real controller merely touches the body.

Camera poses ride on the controller pose of :mod:`render_cams.vr`: a camera is an
:class:`~render_cams.vr.Attachment` composed of the controller's grip and the mount.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from avatarsim.avatar_models import AvatarsimError, Motion, quat
from avatarsim.avatar_models.body import BodyDescription
from avatarsim.render_cams.vr import Attachment, attachment_poses, nominal_attachment

COMPOSITE_VERTICAL_FOV_DEG = 185.0  # ControllerPose §4.1
CAMERA_VERTICAL_FOV_DEG = 120.0  # ControllerPose §4.1
PITCH_APART_RAD = np.radians(COMPOSITE_VERTICAL_FOV_DEG - CAMERA_VERTICAL_FOV_DEG)
RING_PITCH_RAD = np.radians(20.0)  # module docstring
GRIP_PITCH_RAD = RING_PITCH_RAD - PITCH_APART_RAD
RING_OFFSET_M = np.array([0.02, 0.0, 0.06])
GRIP_BOTTOM_OFFSET_M = np.array([-0.02, 0.0, -0.06])
CONTROLLERS = ("left_controller", "right_controller")


class CameraInsideBodyError(AvatarsimError, ValueError):
    """A camera centre lies inside the body mesh (it would see only the inside of a limb)."""


def looking_back(pitch_rad: float) -> np.ndarray:
    """``(3, 3)`` camera axes (columns x right, y down, z forward; OpenCV) in the controller
    frame: looking along -X, pitched up by ``pitch_rad`` (down when negative)."""
    c, s = np.cos(pitch_rad), np.sin(pitch_rad)
    z = np.array([-c, 0.0, s])
    y = np.array([-s, 0.0, -c])
    return np.stack([np.cross(y, z), y, z], axis=1)


@dataclass(frozen=True, eq=False)
class ControllerCamera:
    """One camera rigidly mounted on a controller.

    Attributes:
        name: e.g. ``"left_controller/ring"``.
        controller: ``"left_controller"`` or ``"right_controller"``.
        position: ``(3,)`` mount in the controller frame (metres).
        axes: ``(3, 3)`` camera axes (OpenCV) in the controller frame.
    """

    name: str
    controller: str
    position: np.ndarray
    axes: np.ndarray

    def attachment(self, skeleton) -> Attachment:
        """The camera as an attachment to the controller's wrist joint."""
        grip = nominal_attachment(self.controller, skeleton)
        grip_rot = quat.to_matrix(grip.rotation)
        return Attachment(
            grip.joint,
            grip.position + grip_rot @ self.position,
            quat.from_matrix(grip_rot @ self.axes),
        )


class CameraMountError(AvatarsimError, ValueError):
    """A camera mount that no controller could have (far from it, NaN, pitched past vertical)."""


MAX_MOUNT_OFFSET_M = 0.25
"""A camera mounted on a controller (about 15 cm long) sits within this of the palm centre."""


@dataclass(frozen=True)
class Mount:
    """Where the two cameras of a controller sit, in the controller frame (+X pointing, +Y
    left, +Z up; metres) and how far each is pitched from looking straight back along -X
    (radians; up for the ring, down for the grip with the defaults). The same mount is used
    on both controllers (the left one is not mirrored: both controllers are built alike).

    Defaults: the plausible Quest 2 placement of the module docstring.
    """

    ring_offset_m: tuple[float, float, float] = tuple(RING_OFFSET_M)
    grip_offset_m: tuple[float, float, float] = tuple(GRIP_BOTTOM_OFFSET_M)
    ring_pitch_rad: float = float(RING_PITCH_RAD)
    grip_pitch_rad: float = float(GRIP_PITCH_RAD)

    def __post_init__(self) -> None:
        for name in ("ring_offset_m", "grip_offset_m"):
            offset = np.asarray(getattr(self, name), float)
            if offset.shape != (3,) or not np.all(np.isfinite(offset)):
                raise CameraMountError(f"{name} must be 3 finite numbers (metres), got {offset}")
            if np.linalg.norm(offset) > MAX_MOUNT_OFFSET_M:
                raise CameraMountError(
                    f"{name} {offset.tolist()} m is {np.linalg.norm(offset):.2f} m from the "
                    f"controller's grip; a camera on a controller is within "
                    f"{MAX_MOUNT_OFFSET_M} m of it"
                )
        for name in ("ring_pitch_rad", "grip_pitch_rad"):
            pitch = float(getattr(self, name))
            if not (np.isfinite(pitch) and abs(pitch) <= 0.5 * np.pi):
                raise CameraMountError(f"{name} must be in [-90, 90] deg, got {np.degrees(pitch)}")


def controller_cameras(
    controllers: Sequence[str] = CONTROLLERS, mount: Mount | None = None
) -> tuple[ControllerCamera, ...]:
    """The ring and grip cameras of each controller, in ``(controller, ring/grip)`` order,
    mounted as ``mount`` says (default :class:`Mount`)."""
    mount = mount or Mount()
    mounts = (
        ("ring", np.asarray(mount.ring_offset_m, float), mount.ring_pitch_rad),
        ("grip", np.asarray(mount.grip_offset_m, float), mount.grip_pitch_rad),
    )
    return tuple(
        ControllerCamera(f"{c}/{where}", c, offset, looking_back(pitch))
        for c in controllers
        for where, offset, pitch in mounts
    )


def camera_poses(motion: Motion, cameras: Sequence[ControllerCamera]) -> np.ndarray:
    """``(T, C, 4, 4)`` camera-to-world poses (OpenCV axes) of ``cameras`` over ``motion``."""
    positions, quaternions = attachment_poses(
        motion, [c.attachment(motion.skeleton) for c in cameras]
    )
    poses = np.zeros((*positions.shape[:2], 4, 4))
    poses[..., :3, :3] = quat.to_matrix(quaternions)
    poses[..., :3, 3] = positions
    poses[..., 3, 3] = 1.0
    return poses


def inside_segments(
    body: BodyDescription, positions: np.ndarray, rotations: np.ndarray, points: np.ndarray
) -> np.ndarray:
    """``(T, N, S)`` bool: point ``n`` of frame ``t`` lies inside body segment ``s``.

    Args:
        positions: ``(T, J, 3)`` global joint positions; rotations ``(T, J, 3, 3)``.
        points: ``(T, N, 3)`` world points.
    """
    seg = body.segments
    bodies = np.array([s.body for s in seg])
    start = np.stack([s.start for s in seg])
    end = np.stack([s.end for s in seg])
    radius = np.array([s.radius for s in seg])
    rot = rotations[:, bodies]  # (T, S, 3, 3)
    # Points in every segment's body frame: (T, N, S, 3).
    local = np.einsum("tsba,tnsb->tnsa", rot, points[:, :, None] - positions[:, None, bodies])
    axis = end - start
    length2 = np.maximum(np.einsum("sa,sa->s", axis, axis), 1e-12)
    along = np.clip(np.einsum("tnsa,sa->tns", local - start, axis) / length2, 0.0, 1.0)
    gap = np.linalg.norm(local - start - along[..., None] * axis, axis=-1)
    inside = gap < radius
    is_box = np.array([s.shape == "box" for s in seg])
    if np.any(is_box):
        half = np.stack([s.half_extents for s in seg])
        box_rot = np.stack([s.box_rotation for s in seg])
        in_box = np.einsum("sba,tnsb->tnsa", box_rot, local - start)
        inside = np.where(is_box, np.all(np.abs(in_box) < half, axis=-1), inside)
    return inside


def inside_body(
    body: BodyDescription, positions: np.ndarray, rotations: np.ndarray, points: np.ndarray
) -> np.ndarray:
    """``(T, N)`` bool: point ``n`` of frame ``t`` lies inside a body segment (arguments as
    :func:`inside_segments`)."""
    return np.any(inside_segments(body, positions, rotations, points), axis=-1)


def check_cameras_outside(body: BodyDescription, motion: Motion, poses: np.ndarray) -> None:
    """Raise :class:`CameraInsideBodyError` if a camera centre (``poses`` ``(T, C, 4, 4)``)
    is inside the body in any frame of ``motion``."""
    positions, rotations = motion.fk()
    inside = inside_body(body, positions, rotations, poses[..., :3, 3])
    if np.any(inside):
        t, c = np.argwhere(inside)[0]
        raise CameraInsideBodyError(
            f"camera {c} is inside the body at frame {t} (centre {poses[t, c, :3, 3].round(3)}); "
            "move its mount outside the hand and arm"
        )


def camera_pairs(cameras: Sequence[ControllerCamera]) -> dict[str, list[int]]:
    """``{controller: [ring, grip]}`` indices of the controllers that carry two cameras."""
    by_controller: dict[str, list[int]] = {}
    for c, camera in enumerate(cameras):
        by_controller.setdefault(camera.controller, []).append(c)
    return {k: pair for k, pair in by_controller.items() if len(pair) == 2}

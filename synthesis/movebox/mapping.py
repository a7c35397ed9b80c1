"""Which Kinect joints drive which avatar bones (MoveBox §III-A1: "each frame the Kinect joint
data is captured and then mapped to the corresponding joint in the RocketBox avatar skeleton").

A :class:`BoneDrive` says, for one avatar joint (whose rotation turns the bone to its
``child``): the Kinect joint the bone points at (``aim``), and the Kinect joint whose reported
orientation gives the bone's roll (``orient``), with the Kinect rest bone that orientation
turns (``orient_rest``: from, to). Kinect V2 reports, at each joint, the rotation of the bone
that *ends* there (a swing with no roll, paper §IV-A1); Azure Kinect the rotation of the bone
that *starts* there. The pelvis is set by its triad (spine base and both hips), which fixes
its heading on both sensors (V2's root orientation has none).

Spine and neck bones aim at their Kinect joints scaled about the Kinect root to the avatar's
torso (``torso``; :meth:`~synthesis.movebox.retarget.Retargeting.torso_scaled`): a
height-resized avatar's torso is not the user's length (pelvis to neck 38 cm on the avatar
resized to a CMU subject whose own is 24 cm), and a spine bone aimed from the avatar's start
at a Kinect joint that start has already passed folds down (the 9 CMU clips, noise-free:
Spine2 up to 118 degrees off the subject's own pelvis-neck line). Limbs and clavicles aim at
the joints themselves, so that the avatar's hands land on the user's whatever the arm
lengths.

Avatar bones without a drive (fingers, toes, jaw, eyelids, V2's head, stabilised wrists)
keep their rest rotation relative to their parent.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from avatarsim.synthesis.base import SynthesisError


@dataclass(frozen=True)
class BoneDrive:
    """One avatar joint driven by the Kinect.

    Attributes:
        joint: the avatar joint (its rotation turns the bone to ``child``).
        child: the avatar joint at the bone's far end.
        aim: the Kinect joint the bone points at, or None (orientation only).
        orient: the Kinect joint whose orientation gives the bone's roll.
        orient_rest: the Kinect rest bone (from, to) that ``orient``'s orientation turns.
        bend: for a bone whose child is a hinge (elbow, knee), the direction the child's far
            end moves when the hinge flexes, in this bone's rest frame; else None.
        torso: aim at ``aim`` scaled to the avatar's torso (spine and neck bones).
    """

    joint: str
    child: str
    aim: str | None
    orient: str
    orient_rest: tuple[str, str]
    bend: tuple[float, float, float] | None = None
    torso: bool = False

    @property
    def kinect_joints(self) -> tuple[str, ...]:
        """The Kinect joints this bone reads (their tracking state is the bone's)."""
        return tuple(j for j in (self.aim, self.orient) if j is not None)


@dataclass(frozen=True)
class RigMapping:
    """The mapping of one Kinect rig onto the avatar rig.

    Attributes:
        rig: ``"kinect_v2"`` or ``"azure_kinect"``.
        root: the Kinect joint at the avatar's pelvis (root position).
        neck: the Kinect joint at the avatar's neck (the top of the torso).
        hips: the Kinect (left, right) hip joints of the pelvis triad.
        drives: the driven bones, parents before children.
        hands: the avatar hand joints (wrist stabilisation, §IV-B2).
    """

    rig: str
    root: str
    neck: str
    hips: tuple[str, str]
    drives: tuple[BoneDrive, ...]
    hands: tuple[str, str] = ("Bip01 L Hand", "Bip01 R Hand")


PELVIS = "Bip01 Pelvis"
NECK = "Bip01 Neck"
PELVIS_TRIAD = ("Bip01 L Thigh", "Bip01 R Thigh")
"""The avatar's pelvis and neck joints (its torso), and the hip joints that fix the pelvis'
rotation with it."""


def _torso(drive: BoneDrive) -> BoneDrive:
    return replace(drive, torso=True)


def _v2_drive(joint: str, child: str, start: str, end: str) -> BoneDrive:
    """A V2 bone from Kinect ``start`` to ``end``: aims at ``end``, roll from ``end``."""
    return BoneDrive(joint, child, end, end, (start, end))


def _azure_drive(joint: str, child: str, start: str, end: str | None, rest_end: str) -> BoneDrive:
    """An Azure bone starting at Kinect ``start``: aims at ``end``, roll from ``start``."""
    return BoneDrive(joint, child, end, start, (start, rest_end))


ELBOW_BEND = (1.0, 0.0, 0.0)
KNEE_BEND = (-1.0, 0.0, 0.0)
"""Where the forearm and the calf swing when the elbow and knee flex, in the upper arm's and
thigh's rest frames: the avatar rig's flexion limits (avatar.toml: elbows flex about z
towards +x, forwards; knees about y towards -x, backwards)."""


def _limbs(side: str, names: dict[str, str], drive) -> tuple[BoneDrive, ...]:
    """Clavicle, arm, hand and leg drives of one side ``"L"``/``"R"``; ``names`` maps
    clavicle/shoulder/elbow/wrist/hand/hip/knee/ankle/foot to Kinect joints."""
    b = f"Bip01 {side} "
    n = names
    return (
        drive(b + "Clavicle", b + "UpperArm", n["clavicle"], n["shoulder"]),
        replace(drive(b + "UpperArm", b + "Forearm", n["shoulder"], n["elbow"]), bend=ELBOW_BEND),
        drive(b + "Forearm", b + "Hand", n["elbow"], n["wrist"]),
        drive(b + "Hand", b + "Finger2", n["wrist"], n["hand"]),
        replace(drive(b + "Thigh", b + "Calf", n["hip"], n["knee"]), bend=KNEE_BEND),
        drive(b + "Calf", b + "Foot", n["knee"], n["ankle"]),
        drive(b + "Foot", b + "Toe0", n["ankle"], n["foot"]),
    )


def _v2_side(side: str) -> dict[str, str]:
    s = "Left" if side == "L" else "Right"
    parts = ("Shoulder", "Elbow", "Wrist", "Hand", "Hip", "Knee", "Ankle", "Foot")
    return {"clavicle": "SpineShoulder", **{p.lower(): p + s for p in parts}}


def _azure_side(side: str) -> dict[str, str]:
    s = "LEFT" if side == "L" else "RIGHT"
    parts = ("CLAVICLE", "SHOULDER", "ELBOW", "WRIST", "HAND", "HIP", "KNEE", "ANKLE", "FOOT")
    return {p.lower(): f"{p}_{s}" for p in parts}


KINECT_V2 = RigMapping(
    rig="kinect_v2",
    root="SpineBase",
    neck="Neck",
    hips=("HipLeft", "HipRight"),
    drives=(
        _torso(_v2_drive("Bip01 Spine", "Bip01 Spine1", "SpineBase", "SpineMid")),
        _torso(_v2_drive("Bip01 Spine1", "Bip01 Spine2", "SpineMid", "SpineShoulder")),
        _torso(_v2_drive("Bip01 Spine2", "Bip01 Neck", "SpineShoulder", "Neck")),
        _torso(_v2_drive("Bip01 Neck", "Bip01 Head", "Neck", "Head")),
        *_limbs("L", _v2_side("L"), _v2_drive),
        *_limbs("R", _v2_side("R"), _v2_drive),
    ),
)


def _azure_limb_drive(joint: str, child: str, start: str, end: str) -> BoneDrive:
    return _azure_drive(joint, child, start, end, end)


AZURE_KINECT = RigMapping(
    rig="azure_kinect",
    root="PELVIS",
    neck="NECK",
    hips=("HIP_LEFT", "HIP_RIGHT"),
    drives=(
        *map(
            _torso,
            (
                _azure_drive(
                    "Bip01 Spine", "Bip01 Spine1", "SPINE_NAVAL", "SPINE_NAVAL", "SPINE_CHEST"
                ),
                _azure_drive("Bip01 Spine1", "Bip01 Spine2", "SPINE_CHEST", "SPINE_CHEST", "NECK"),
                _azure_drive("Bip01 Spine2", "Bip01 Neck", "SPINE_CHEST", "NECK", "NECK"),
                _azure_drive("Bip01 Neck", "Bip01 Head", "NECK", "HEAD", "HEAD"),
            ),
        ),
        # The head's roll and nod: Azure's HEAD orientation turns the neck-head bone.
        BoneDrive("Bip01 Head", "Bip01 HeadNub", None, "HEAD", ("NECK", "HEAD")),
        *_limbs("L", _azure_side("L"), _azure_limb_drive),
        *_limbs("R", _azure_side("R"), _azure_limb_drive),
    ),
)

MAPPINGS = {m.rig: m for m in (KINECT_V2, AZURE_KINECT)}


def mapping_for(rig: str) -> RigMapping:
    """The mapping of the Kinect rig ``rig``.

    Raises:
        SynthesisError: no mapping for that rig.
    """
    if rig not in MAPPINGS:
        raise SynthesisError(f"MoveBox maps {', '.join(MAPPINGS)} skeletons, not {rig!r}")
    return MAPPINGS[rig]

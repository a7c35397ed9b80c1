"""The registry of synthesis methods: one name per method, and how to build it for a user.

Every place that lets a user pick a method by name goes through :data:`METHODS`: the
``eval`` command and its leaderboard, the scenarios and the benchmarks. So what is called
``coolmoves`` is the same pipeline everywhere: the paper's (§3.1), hands from the blended
database poses only. What goes beyond the paper has its own name and is reported beside it.

A builder gets a :class:`MethodInputs` (the training motions' database, built on first use,
the user's height, and the rig the ground truth is scored on) and returns a fresh
:class:`~synthesis.base.Synthesizer`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property

from avatarsim.avatar_models import Skeleton
from avatarsim.render_cams.kinect import KinectSkeletonStream
from avatarsim.render_cams.vr import Attachment
from avatarsim.synthesis.avatargo import AvatarGo
from avatarsim.synthesis.base import SynthesisError, Synthesizer, TrackingFrame
from avatarsim.synthesis.controllerpose.synthesizer import (
    ControllerPose,
    KeypointRecording,
    default_checkpoint,
    model_missing,
)
from avatarsim.synthesis.coolmoves import CoolMoves, Database, Options
from avatarsim.synthesis.ik_baseline import IKBaseline
from avatarsim.synthesis.movebox import MoveBox
from avatarsim.synthesis.movebox.resize import avatar_for


@dataclass(eq=False)
class MethodInputs:
    """What a builder may use.

    Attributes:
        database: builds the motion database of the training motions (called once, on the
            first method that needs it).
        user_height_m: the user's standing height.
        rig: the rig the ground truth is scored on (the humanoid's: the truth's own rig, or
            the avatar rig a foreign rig was retargeted onto); the IK baseline drives it.
        calibration: device-on-joint attachments (hmd, left, right controller) on ``rig``,
            or None for the nominal ones; a calibration from another rig
            (:func:`~synthesis.ik_baseline.attachments_on_upright_rig`) is steered by
            position only (the rigs' hand frames differ).
        coolmoves: option overrides for every CoolMoves variant (e.g. a scenario's
            ``foot_contact``), applied on top of the variant's own.
        walk_in: AvatarGo's walk-in sample (§3.2): the six devices (headset, controllers,
            three Vive trackers) while the user stands in a T-pose, or None where the
            trackers are off.
        kinect: the Kinect skeleton stream of the same take (``[devices] kinect``), for
            MoveBox; None where no Kinect was recorded.
        fisheye: the controller cameras' keypoints (ControllerPose), or None when the
            scenario records none (``[devices] fisheye = true``).
    """

    database_factory: Callable[[], Database]
    user_height_m: float
    rig: Skeleton
    calibration: Sequence[Attachment] | None = None
    coolmoves: dict = field(default_factory=dict)
    walk_in: TrackingFrame | None = None
    kinect: KinectSkeletonStream | None = None
    fisheye: KeypointRecording | None = None

    @cached_property
    def database(self) -> Database:
        return self.database_factory()


@dataclass(frozen=True)
class Method:
    """A registered method: its ``name``, a one-line ``summary`` and its ``build``er; the
    CoolMoves variants also carry their :class:`~synthesis.coolmoves.Options` (the
    ablation switches them one at a time). ``sensors`` names the :class:`MethodInputs`
    fields beyond the VR stream that the builder reads (e.g. ``("kinect",)``): whoever
    runs the method by name (the leaderboard) records them for it. ``missing`` says what a
    method still needs before it can be built (a trained model), or None when it is ready."""

    name: str
    summary: str
    build: Callable[[MethodInputs], Synthesizer]
    options: Options | None = None
    sensors: tuple[str, ...] = ()
    missing: Callable[[], str | None] = lambda: None


def ready_methods() -> list[str]:
    """The registered methods that can be built now (the default set to compare)."""
    return [name for name, m in METHODS.items() if m.missing() is None]


def coolmoves(name: str, summary: str, options: Options) -> Method:
    """A CoolMoves variant on the inputs' database, named ``name``."""

    def build(inputs: MethodInputs) -> Synthesizer:
        synth = CoolMoves(
            inputs.database, inputs.user_height_m, replace(options, **inputs.coolmoves)
        )
        synth.name = name
        return synth

    return Method(name, summary, build, options)


def controllerpose(inputs: MethodInputs) -> Synthesizer:
    """ControllerPose (§4.3) with the trained model of :func:`default_checkpoint` on the
    scored rig, from the controller cameras' keypoints and the VR stream."""
    if inputs.fisheye is None:
        raise SynthesisError(
            "controllerpose needs the controller cameras' keypoints: enable [devices] "
            "fisheye = true in the scenario"
        )
    return ControllerPose(default_checkpoint(), inputs.fisheye, inputs.rig, inputs.user_height_m)


def ik_baseline(inputs: MethodInputs) -> Synthesizer:
    """The VRIK-like baseline on the scored rig (:class:`~synthesis.ik_baseline.IKBaseline`)."""
    own = inputs.calibration is None
    return IKBaseline(inputs.rig, inputs.user_height_m, inputs.calibration, own)


def avatargo(name: str, summary: str, offsets: str) -> Method:
    """AvatarGo with ``offsets`` on the scored rig as the avatar, calibrated on the inputs'
    walk-in sample (:class:`~synthesis.avatargo.AvatarGo`)."""

    def build(inputs: MethodInputs) -> Synthesizer:
        if inputs.walk_in is None:
            raise SynthesisError(
                f"{name} needs the three Vive trackers and their walk-in T-pose sample: "
                "enable [devices] trackers = true"
            )
        headset = inputs.calibration[0] if inputs.calibration else None
        synth = AvatarGo(inputs.rig, inputs.walk_in, offsets=offsets, headset=headset)
        synth.name = name
        return synth

    return Method(name, summary, build)


def movebox(name: str, roll: str) -> Callable[[MethodInputs], Synthesizer]:
    """A builder of MoveBox (:class:`~synthesis.movebox.MoveBox`) named ``name`` with
    ``roll``, on the inputs' Kinect stream, driving the scored rig when it is an avatar rig,
    else the avatar rig resized to the user; it raises :class:`SynthesisError` without a
    Kinect stream (saying which ``[devices]`` entry to set)."""

    def build(inputs: MethodInputs) -> Synthesizer:
        if inputs.kinect is None:
            raise SynthesisError(
                'movebox reads the Kinect skeleton stream: set [devices] kinect = "kinect-v2" '
                '(or "azure-kinect") in the scenario'
            )
        synth = MoveBox(inputs.kinect, avatar_for(inputs.rig, inputs.user_height_m), roll=roll)
        synth.name = name
        return synth

    return build


METHODS: dict[str, Method] = {
    m.name: m
    for m in (
        coolmoves("coolmoves", "CoolMoves as the paper describes it (§3.1)", Options()),
        coolmoves(
            "coolmoves+arm-ik",
            "CoolMoves, then two-bone arm IK to the tracked controllers (beyond the paper)",
            Options(arm_ik=1.0),
        ),
        coolmoves(
            "coolmoves-gmm", "CoolMoves with the Gaussian-mixture matcher", Options(matcher="gmm")
        ),
        coolmoves(
            "coolmoves-centroid-align",
            "CoolMoves aligning about the clouds' centroids (the printed equation)",
            Options(align_about_centroid=True),
        ),
        coolmoves(
            "coolmoves-own-hand-align",
            "CoolMoves turning each hand's matches to fit that hand's window only",
            Options(align_own_hand=True),
        ),
        Method("ik", "VRIK-like full-body IK from headset and controllers (§4.1.1)", ik_baseline),
        avatargo(
            "avatargo",
            "AvatarGo: walk-in calibration, exact tracker offsets, IK, finger IK (§3)",
            "exact",
        ),
        avatargo(
            "avatargo-fixed",
            "AvatarGo with the fixed root/feet tracker offsets it argues against (§3.3)",
            "fixed",
        ),
        Method(
            "movebox",
            "MoveBox: the Kinect skeleton retargeted onto the avatar (§III-A1; [devices] kinect)",
            movebox("movebox", "auto"),
            sensors=("kinect",),
        ),
        Method(
            "movebox+hinge-roll",
            "MoveBox, limb roll turned onto the avatar's hinge axes (beyond the paper)",
            movebox("movebox+hinge-roll", "hinge"),
            sensors=("kinect",),
        ),
        Method(
            "controllerpose",
            "ControllerPose: controller-camera keypoints + VR lifted by a network, IK (§4.3)",
            controllerpose,
            sensors=("fisheye",),
            missing=model_missing,
        ),
    )
}
"""Every registered method by name."""


def method(name: str) -> Method:
    """The registered method ``name``.

    Raises:
        SynthesisError: no method has that name (the message lists them).
    """
    if name not in METHODS:
        raise SynthesisError(f"unknown method {name!r}; available: {', '.join(METHODS)}")
    return METHODS[name]


def build(name: str, inputs: MethodInputs) -> Synthesizer:
    """A fresh synthesiser of the registered method ``name`` for ``inputs``."""
    return method(name).build(inputs)

"""The one path from any motion to the MuJoCo humanoid: :func:`humanoid_for`.

Every command and scenario stage gets its body, qpos and compiled model from here, once, and
passes the :class:`Humanoid` along; nothing downstream rebuilds a body from a skeleton.

- A motion on a rig whose rest pose stands (the avatar rig, CMU, a built-in subject) gets the
  body of its own skeleton and its exact qpos (:meth:`BodyDescription.qpos_from_motion`):
  residual zero.
- Any other rig with a body17 map (Bandai, Kinect...) is retargeted onto the avatar-rig
  humanoid sized to it (:func:`sim.retarget.sizing.humanoid_body`, :func:`sim.retarget.retarget`);
  its per-frame residual is kept.

Physics control needs stance feet flat on the floor (:func:`sim.retarget.feet.level_stance_feet`
and the repairs around it); :meth:`Humanoid.for_control` gives that reference on the same body
and model, retargeting again only for a foreign rig.

Shapes: ``T`` frames, ``nq`` MuJoCo position coordinates.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from avatarsim.avatar_models.body import BodyDescription, RestPoseNotUprightError, build_body
from avatarsim.avatar_models.errors import MotionValueError
from avatarsim.avatar_models.measure import standing_height
from avatarsim.avatar_models.motion import Motion
from avatarsim.avatar_models.rigs import identify_rig

DEFAULT_MASS_KG = 75.0


@dataclass(frozen=True, eq=False)
class Humanoid:
    """A motion on the humanoid.

    Attributes:
        body: the body, built once.
        motion: the motion on ``body.skeleton`` (the source itself for an own rig).
        qpos: ``(T, nq)`` MuJoCo positions of ``motion``.
        residual_cm: ``(T,)`` mean body17 site-to-target distance of the retargeting (zeros
            for an own rig).
        source: the motion as given (after any height scaling).
        model: ``body.spec`` compiled once (:attr:`BodyDescription.model`), shared by every
            stage: read it, do not edit it (physics control compiles its own variant,
            :meth:`control_model`).
        levelled: whether stance feet were levelled for physics control.
    """

    body: BodyDescription
    motion: Motion
    qpos: np.ndarray
    residual_cm: np.ndarray
    source: Motion
    model: mujoco.MjModel
    levelled: bool = False

    @property
    def retargeted(self) -> bool:
        return self.motion is not self.source

    @property
    def mjcf(self) -> str:
        """The body's MJCF text (MuJoCo's export of ``body.spec``, for its viewer), written
        when asked for."""
        return self.body.to_mjcf()

    @property
    def spec(self) -> mujoco.MjSpec:
        """The body's spec (``model``'s source); edit a ``spec.copy()``."""
        return self.body.spec

    def control_model(self) -> mujoco.MjModel:
        """A new compiled physics-control variant of ``model``
        (:func:`sim.control.model.control_model`): motors, only floor contacts."""
        from avatarsim.sim.control.model import control_model  # sim.control builds on this module

        return control_model(self.body.spec)

    def for_control(self) -> Humanoid:
        """This humanoid with stance feet levelled for physics control (module docstring);
        itself for an own rig, whose feet are the source's."""
        if not self.retargeted or self.levelled:
            return self
        return _levelled(self)

    def summary(self) -> dict:
        """Provenance for results files: rig, retargeting and its residual."""
        out = {
            "source_rig": identify_rig(self.source.skeleton).name,
            "body_rig": self.body.rig.name,
            "retargeted": self.retargeted,
            "mass_kg": self.body.mass_kg,
            "nq": int(self.qpos.shape[1]),
        }
        if self.retargeted:
            out["retarget_residual_cm_mean"] = float(np.mean(self.residual_cm))
            out["retarget_residual_cm_p95"] = float(np.percentile(self.residual_cm, 95))
        return out


def humanoid_for(
    motion: Motion,
    height_m: float | None = None,
    mass_kg: float | None = None,
    level_feet: bool = False,
) -> Humanoid:
    """The humanoid for ``motion`` (module docstring).

    Args:
        motion: any rig with a body17 map.
        height_m: scale the motion uniformly (skeleton and root path) to this standing
            height first; ``None`` keeps its own size.
        mass_kg: body mass (default: the built-in subject's, else 75 kg).
        level_feet: level stance feet for control right away (see :meth:`for_control`).

    Raises:
        MotionValueError: a rig with no body17 map, a height outside (0, 3] m.
        BodyError: a skeleton no body can be built from.
    """
    subject = motion.meta.get("subject")
    subject = subject if isinstance(subject, dict) else {}  # a library clip's is a label
    if mass_kg is None:
        mass_kg = subject.get("mass_kg", DEFAULT_MASS_KG)
    if height_m is not None:
        if not (np.isfinite(height_m) and 0.0 < height_m <= 3.0):
            raise MotionValueError(f"body height must be in (0, 3] m, got {height_m!r}")
        factor = height_m / standing_height(motion)
        meta = dict(motion.meta)
        if subject:  # the built-in subject's recorded height follows (synthesis reads it)
            meta["subject"] = subject | {"height_m": float(height_m)}
        motion = motion.replace(
            skeleton=motion.skeleton.scaled(factor), root_pos=motion.root_pos * factor, meta=meta
        )
    try:
        body = build_body(motion.skeleton, mass_kg=mass_kg)
    except RestPoseNotUprightError:
        pass  # a rig whose rest pose lies down (Bandai's): retargeted onto one that stands
    else:
        qpos = body.qpos_from_motion(motion)
        zero = np.zeros(motion.n_frames)
        return Humanoid(body, motion, qpos, zero, motion, body.model)
    from avatarsim.sim.retarget.sizing import humanoid_body  # IK (mink) is only loaded when needed

    body = humanoid_body(motion, mass_kg=mass_kg)
    return _retargeted(body, motion, body.model, level_feet)


def _retargeted(
    body: BodyDescription, motion: Motion, model: mujoco.MjModel, level_feet: bool
) -> Humanoid:
    from avatarsim.sim.retarget import retarget

    result = retarget(motion, body, level_feet=level_feet, scale_targets=False, model=model)
    meta = {**result.motion.meta, "retarget_residual_cm": float(np.mean(result.residual_cm))}
    out = result.motion.replace(meta=meta)
    return Humanoid(body, out, result.qpos, result.residual_cm, motion, model, level_feet)


def _levelled(h: Humanoid) -> Humanoid:
    return _retargeted(h.body, h.source, h.model, level_feet=True)

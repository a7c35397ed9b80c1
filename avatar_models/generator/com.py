"""Whole-body centre of mass of a motion, and moving the root so that it follows a wanted path.

Segment masses and centres of mass are those of the physics body
(:func:`avatar_models.body.build_body`: de Leva 1996 fractions on the subject's skeleton), so
the centre of mass the generator plans is the one the physics checks measure. Gravity acts on
the centre of mass, not on the pelvis: a ballistic flight or a spring-mass stance is a
statement about this point, and a swinging leg moves it relative to the pelvis by centimetres.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cache

import numpy as np
from scipy.linalg import solve_banded

from avatarsim.avatar_models.body import build_body
from avatarsim.avatar_models.generator.bounce import GRAVITY_M_S2
from avatarsim.avatar_models.generator.plan import Plan, Scene, realise_local
from avatarsim.avatar_models.motion import Motion, forward_kinematics
from avatarsim.avatar_models.skeleton import Skeleton


@dataclass(frozen=True)
class MassModel:
    """Point masses of a body: ``mass (S,)`` kg on joint ``joint (S,)`` at ``local (S, 3)`` in
    that joint's frame."""

    mass: np.ndarray
    joint: np.ndarray
    local: np.ndarray

    @staticmethod
    def of(skeleton: Skeleton) -> MassModel:
        return _mass_model(skeleton)

    def centre_of_mass(self, motion: Motion) -> np.ndarray:
        """``(T, 3)`` world centre of mass of ``motion`` (on the skeleton this was built for)."""
        return self.centre_of_mass_fk(*motion.fk())

    def centre_of_mass_fk(self, pos: np.ndarray, rot: np.ndarray) -> np.ndarray:
        """``(T, 3)`` world centre of mass of a pose given by its forward kinematics: joint
        positions ``(T, J, 3)`` and rotations ``(T, J, 3, 3)`` (only ``joint``'s are read)."""
        points = pos[:, self.joint] + np.einsum("tsab,sb->tsa", rot[:, self.joint], self.local)
        return np.einsum("tsa,s->ta", points, self.mass / self.mass.sum())


@cache
def _mass_model(skeleton: Skeleton) -> MassModel:
    segments = build_body(skeleton).segments
    return MassModel(
        mass=np.array([s.mass for s in segments]),
        joint=np.array([s.body for s in segments]),
        local=np.array([s.com for s in segments]),
    )


def plan_centre_of_mass(scene: Scene, plan: Plan) -> np.ndarray:
    """``(T, 3)`` centre of mass of the realised ``plan``, from its rotation matrices and
    only the segments' joints (the planning loops call this a dozen times a clip)."""
    masses = MassModel.of(scene.skeleton)
    local = realise_local(scene, plan)
    fk = forward_kinematics(scene.skeleton, plan.root_pos, local, masses.joint.tolist())
    return masses.centre_of_mass_fk(*fk)


def lipm_centre_of_mass(zmp: np.ndarray, height: float, fps: float) -> np.ndarray:
    """``(T, 2)`` horizontal centre-of-mass path whose zero-moment point is ``zmp (T, 2)``
    under the linear inverted pendulum (Kajita et al. 2003, "Biped walking pattern generation
    by using preview control of zero-moment point"): ``zmp = c - c'' / omega^2`` with
    ``omega = sqrt(g / height)``, second differences in time, and zero slope at both ends.

    This is the one bounded solution (the ZMP smoothed by the kernel ``omega/2 exp(-omega|t|)``):
    a centre of mass that keeps the pressure inside the feet needs no ankle torque the foot
    cannot give, unlike a constant-speed one whose pressure point runs ahead of the toes.
    Solved as a tridiagonal system (``scipy.linalg.solve_banded``).
    """
    n = zmp.shape[0]
    k = fps * fps * height / GRAVITY_M_S2  # 1 / (omega dt)^2
    bands = np.zeros((3, n))
    bands[0, 1:] = -k
    bands[2, :-1] = -k
    bands[1] = 1.0 + 2.0 * k
    bands[1, [0, -1]] = 1.0 + k
    return solve_banded((1, 1), bands, zmp)


def follow_centre_of_mass(
    scene: Scene, plan: Plan, wanted: np.ndarray, iterations: int = 4
) -> np.ndarray:
    """``(T, 3)`` root positions that put the realised ``plan``'s centre of mass on ``wanted
    (T, 3)`` (NaN entries: that coordinate keeps the plan's root).

    Moving the root moves the whole body except where IK holds the feet, so the centre of
    mass moves by somewhat less; a few fixed-point iterations close the gap (the legs are
    about a third of the mass, so the error shrinks about threefold per iteration).
    """
    root = plan.root_pos.copy()
    free = np.isfinite(wanted)
    for _ in range(iterations):
        com = plan_centre_of_mass(scene, replace(plan, root_pos=root))
        root = np.where(free, root + np.nan_to_num(wanted - com), root)
    return root

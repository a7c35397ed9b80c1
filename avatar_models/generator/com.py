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

from avatar_models.body import build_body
from avatar_models.generator.plan import Plan, Scene, realise
from avatar_models.motion import Motion
from avatar_models.skeleton import Skeleton


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
        pos, rot = motion.fk()
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
    """``(T, 3)`` centre of mass of the realised ``plan``."""
    return MassModel.of(scene.skeleton).centre_of_mass(realise(scene, plan))


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

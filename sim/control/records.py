"""What a control run keeps of the simulation: one :class:`FrameRecord` per reference frame,
collected in a :class:`Recording`.

Shapes: ``nq``/``nu`` MuJoCo sizes, 17 body17 sites.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np


@dataclass(frozen=True)
class FrameRecord:
    """The simulated state at one reference frame.

    Attributes:
        reference_frame: the (fractional) reference frame played then.
        qpos: ``(nq,)`` simulated configuration.
        sites: ``(17, 3)`` body17 site positions.
        torque: ``(nu,)`` actuator torques (N m).
        power: mechanical power sum |tau * qd| over the hinges (W).
        unstable: whether MuJoCo had met a diverging simulation by then
            (:meth:`sim.control.controller.Controller.unstable`).
    """

    reference_frame: float
    qpos: np.ndarray
    sites: np.ndarray
    torque: np.ndarray
    power: float
    unstable: bool


@dataclass(frozen=True)
class Recording:
    """The records of a run so far, as a chain of the pieces each call of
    :meth:`sim.control.controller.Controller.advance` recorded: extending it copies nothing,
    and the paths of a search (:mod:`sim.control.search`) share their common beginning.

    Attributes:
        piece: the records of the latest piece, in order.
        before: the recording up to that piece (``None`` at the start).
    """

    piece: tuple[FrameRecord, ...] = ()
    before: Recording | None = None

    def then(self, records: list[FrameRecord]) -> Recording:
        """This recording followed by ``records``."""
        return Recording(tuple(records), self) if records else self

    def records(self) -> list[FrameRecord]:
        """Every record, in order."""
        pieces, node = [], self
        while node is not None:
            pieces.append(node.piece)
            node = node.before
        return [record for piece in reversed(pieces) for record in piece]

    def columns(self) -> dict[str, np.ndarray]:
        """The records' fields stacked over frames: ``reference_frame (T,)``, ``qpos
        (T, nq)``, ``sites (T, 17, 3)``, ``torque (T, nu)``, ``power (T,)``, ``unstable
        (T,)``."""
        records = self.records()
        names = [field.name for field in fields(FrameRecord)]
        return {name: np.array([getattr(r, name) for r in records]) for name in names}

"""Settings of the physics controller: gains, QP weights, foot placement, clock adaptation and
fall criteria (:class:`ControlSettings`), and the constants they rest on."""

from __future__ import annotations

from dataclasses import dataclass

ROOT_DOF = 6  # the free joint's velocity dofs, first in MuJoCo's order; never actuated
GRAVITY = 9.81  # m/s², the humanoid model's gravity (capture point's omega = sqrt(g / z))


@dataclass(frozen=True)
class ControlSettings:
    """Controller gains, QP weights and fall criteria (accelerations in rad/s² or m/s²).

    Attributes:
        kp, kd: hinge stiffness (1/s²) and damping (1/s) of ``qacc_des``.
        kp_root, kd_root: the same for the root's 6 dofs.
        kp_root_xy: root stiffness along world X and Y (drift is corrected by stepping).
        root_weight: QP weight of the root rows relative to a hinge's 1.
        foot_weight, kp_foot, kd_foot: world-orientation task of each foot.
        contact_weight, contact_damping: ``|J_c qacc + k_c J_c qvel|²`` keeps a contact still.
        force_weight: regularisation of the friction-pyramid weights (1/N²).
        friction: cone coefficient of the QP, below the geoms' 1.0 for a margin.
        contact_margin: a foot within this of the floor (m) offers contacts to the QP.
        level_stance_feet: aim a foot the reference stands on flat
            (:meth:`sim.control.qp.WholeBodyQP.foot_tasks`).
        com_weight, kp_com, kd_com: centre-of-mass task, per axis (world x, y, z); weight next
            to a hinge's 1.
        capture_gain: foot-placement shift per metre of capture-point error (simulated minus
            reference), along the reference's heading and sideways.
        max_step_shift: bound on the foot-placement shift (m).
        clock_gain: reference clock rate change per metre of forward capture-point error
            (simulated minus reference): a body ahead of its reference plays the reference
            faster, one behind plays it slower (1/m).
        max_clock_change: bound on the clock rate's departure from 1.
        swing_ramp_s: the shift fades in over this time after lift-off.
        stance_height: a reference foot stands while its ankle is within this of its lowest
            height in the clip (m).
        smoothing_frames: Gaussian sigma (frames) on the reference velocities and
            accelerations (finite differences of mocap are noisy).
        control_period: simulation steps per controller update (torques held in between).
        fall_head_ratio: fall when head height < this x the reference head height.
        fall_tilt_deg: fall when the root's up axis is this far from the reference's.
        lost_error_m: fall (lost) when the mean body17 distance from the reference is larger.
    """

    kp: float = 400.0
    kd: float = 40.0
    kp_root: float = 50.0
    kp_root_xy: float = 0.0
    kd_root: float = 20.0
    root_weight: float = 3.0
    foot_weight: float = 30.0
    kp_foot: float = 400.0
    kd_foot: float = 40.0
    contact_weight: float = 100.0
    contact_damping: float = 20.0
    force_weight: float = 1e-6
    friction: float = 0.8
    contact_margin: float = 0.005
    level_stance_feet: bool = False
    com_weight: tuple[float, float, float] = (3.0, 3.0, 3.0)
    kp_com: float = 20.0
    kd_com: float = 10.0
    capture_gain: tuple[float, float] = (0.2, 0.5)
    max_step_shift: float = 0.25
    clock_gain: float = 2.0
    max_clock_change: float = 0.2
    swing_ramp_s: float = 0.15
    stance_height: float = 0.03
    smoothing_frames: float = 1.0
    control_period: int = 5
    fall_head_ratio: float = 0.6
    fall_tilt_deg: float = 60.0
    lost_error_m: float = 0.5

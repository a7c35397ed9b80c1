"""Vertical pelvis oscillation of gaits that gravity can produce.

Walking vaults over a stiff leg: the pelvis is highest at mid-stance and lowest in double
support, a near-sinusoid twice per stride whose vertical acceleration stays within about
+-0.3 g (Orendurff et al. 2004, J. Rehabil. Res. Dev. 41(6): 4-5 cm peak to peak at
1.2-1.5 m/s). Running bounces on a spring: the body is in ballistic flight between stances
(acceleration exactly -g) and decelerates, then relaunches, during each stance (McMahon &
Cheng 1990, J. Biomech. 23 Suppl 1; vertical ground force a half-sine, peaks 2-3 body
weights). Both profiles are C2 (continuous velocity and acceleration).
"""

from __future__ import annotations

import numpy as np

GRAVITY_M_S2 = 9.81
WALK_MAX_ACCEL_G = 0.3


def vaulting_bob(mid_stance: np.ndarray, amplitude: float, step_frequency: float) -> np.ndarray:
    """``(T,)`` walking pelvis height offset (metres): ``amplitude cos(2 mid_stance)``, highest
    at each mid-stance (``mid_stance (T,)`` radians of the stride phase from one foot's
    mid-stance), with the amplitude reduced so that its acceleration stays under
    :data:`WALK_MAX_ACCEL_G` at ``step_frequency`` (steps per second)."""
    omega = 2.0 * np.pi * step_frequency
    amp = min(amplitude, WALK_MAX_ACCEL_G * GRAVITY_M_S2 / omega**2)
    return amp * np.cos(2.0 * mid_stance)


def spring_mass_bounce(step_phase: np.ndarray, step_period: float, stance: float) -> np.ndarray:
    """``(T,)`` running pelvis height offset (metres, zero mean over a step).

    Args:
        step_phase: phase in ``[0, 1)`` of the current step, 0 at touchdown.
        step_period: seconds per step (half a stride).
        stance: fraction of the step with a foot on the ground; the rest is flight.

    In stance the vertical acceleration is ``A sin(pi tau / Ts) - g`` (the half-sine ground
    force), in flight ``-g``; ``A = pi g T / (2 Ts)`` makes the mean force one body weight,
    so the height is periodic. Touching down at ``-g Tf / 2`` (the end of a symmetric flight)
    makes it C1, and the half-sine starting and ending at zero force makes it C2.
    """
    g = GRAVITY_M_S2
    ts, tf = stance * step_period, (1.0 - stance) * step_period
    peak, w = np.pi * g * step_period / (2.0 * ts), np.pi / ts

    def height(tau: np.ndarray) -> np.ndarray:
        st, fl = np.minimum(tau, ts), np.maximum(tau - ts, 0.0)
        stance_z = -g * tf / 2.0 * st + peak / w * (st - np.sin(w * st) / w) - g * st**2 / 2.0
        return stance_z + g * tf / 2.0 * fl - g * fl**2 / 2.0

    # The mean over a step, from the closed form sampled finely.
    mean = height((np.arange(512) + 0.5) / 512 * step_period).mean()
    return height(np.asarray(step_phase) * step_period) - mean

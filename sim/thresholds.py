"""Every definition and default threshold of the plausibility checks, in one place.

Conventions follow the physics-based character literature: UHC (Luo et al. 2021,
*Dynamics-Regulated Kinematic Policy for Egocentric Pose Estimation*, NeurIPS) and PhysDiff
(Yuan et al. 2023, *PhysDiff: Physics-Guided Human Motion Diffusion Model*, ICCV). Heights and
skating are measured in the floor frame (floor at z = 0, Z up):

- **contact** (labelled by :mod:`avatar_models.foot_contact`, the labeller every module
  shares): a foot point (the heel or the toe of a foot sole) touches the floor when its
  height is below ``contact_height_m`` AND its vertical speed is below ``contact_vz_m_s``
  (height and velocity, as UHC/PhysDiff label contacts; the vertical speed only, so that a
  foot sliding on the floor still counts as in contact and its sliding is measured). The
  5 cm height is the usual foot-contact height of those papers. A contact must last at least
  ``contact_min_s`` (70 ms: below the shortest stance of sprinting, longer than a swing
  toe skimming the floor for a frame or two, which real walks do with 1-2 cm clearance), and
  a point moving faster than ``contact_vxy_m_s`` horizontally (2.5 m/s) is swinging, not
  standing: a low swing (gait initiation, shuffling) is kinematically indistinguishable from
  sliding above that speed, and mocap feet slide far slower than that while planted.
- **penetration**: depth of the deepest MuJoCo floor contact (cm) per frame; the clip's value
  is its 95th percentile.
- **floating**: height of the lowest body point above the floor (cm) when nothing supports
  the body. Running has flight phases, so a frame floats by the lowest height reached within
  ``float_window_s`` around it: a body that touches the floor at least once in that window
  does not float (flights longer than 0.5 s, jumps higher than g t^2 / 8 ~ 30 cm, count).
  PhysDiff's per-frame lowest point height is the special case of a zero window.
- **skating**: horizontal slip speed of a foot's contact (cm/s): the speed of the stillest
  point of its sole between its points in contact, so rolling heel-to-toe and pivoting about a
  point of the sole do not count. The clip's value is the worst foot's median; a frame skates
  above ``skate_speed_cm_s``; a stance (run of contact frames) slides by its slip velocity
  summed over the stance (how far the contact moved on the floor). The
  humanoid's foot is one rigid box without a toe joint, so the sole's points move during
  push-off even in clean mocap; the median threshold (40 cm/s) leaves room for that, the
  slide threshold (10 cm per stance) catches slow drift. Measured on clean motion
  (``python -m tests.measurements.check_values``, and ``... --bandai``): clip medians CMU
  running 14-17 cm/s, other CMU clips 0-8, six Bandai clips 0.1-8.3, built-in activities 0.
  Worst slides: most clips 0-5 cm, but CMU 14_33 (ladder) 10.1, 06_06 (basketball) 13.0,
  125_01 (swimming) 31, Bandai dataset-1 punch 20 and dataset-2 walk 54 cm: those clean
  clips are flagged for skating.
- **joint limits**: a hinge, or the total rotation of a chain of joints sharing one range (the
  spine's, the neck's), beyond its anatomical range (the body's AAOS ranges) by more than
  ``limit_tolerance_deg``; the clip's value is the share of frames with any such hinge. AAOS
  ranges are population averages with standard deviations of 5-10 degrees (Soucie et al.
  2011, Haemophilia 17(3):500-507), so 20 degrees (about 2 SD) is the tolerance; hinges
  narrower than ``limit_min_range_deg`` are replay allowances and are not checked.
- **self-collision**: MuJoCo contacts between geoms of two bodies the body does not exclude
  (non-adjacent segments), deeper than ``self_collision_depth_cm`` (capsules stand in for
  soft tissue, which a swinging arm compresses against the hip by centimetres); share of
  frames.
- **jitter**: mean over bodies of the jerk magnitude (m/s^3, third finite difference of body
  positions); the clip's value is the median over frames (noise raises every frame).
  Measured (``python -m tests.measurements.check_values``): CMU at 120 Hz 2.9-4.3k m/s^3
  for running and basketball, 1.0-1.1k for the ladder, 0.07-0.17k for swimming; six Bandai
  clips at 30 Hz 0.015-0.6k; built-in activities at 90 Hz 0.001-1.9k (run the highest);
  the built-in walk with 1 cm of root noise at 90 Hz: 47.5k.
- **balance**: signed distance of the centre of mass projected on the floor outside the
  support polygon (ConvexHull of the foot sole corners in contact), cm; informative only,
  walking is dynamically, not statically, balanced.
- **residual force**: the root force from ``mj_inverse`` (contacts disabled) that the floor
  cannot supply, in body weights: its distance to the friction cone (``friction`` from the
  model) where a body geom is within ``contact_height_m`` of the floor, its magnitude where
  none is. ~0 for standing and for ballistic flight, ~1 for a body hanging in the air.
  Velocities and accelerations are low-passed at ``residual_cutoff_hz`` (zero-lag 4th-order
  Butterworth, the usual treatment of marker kinematics before inverse dynamics, Winter
  2009, *Biomechanics and Motor Control of Human Movement*, ch. 3), else marker noise
  differentiated twice at 120 Hz alone makes g-sized accelerations.

Load overrides from a dict or a TOML file (flat keys, the field names below)::

    contact_height_m = 0.05
    penetration_cm_p95 = 5.0
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from avatarsim.avatar_models.config import ConfigError, from_data, read_toml, setting


@dataclass(frozen=True)
class CheckConfig:
    """Definitions (first block) and pass/fail thresholds (second block). See the module.

    The definitions have sane bounds: beyond them a check measures nothing meaningful (a 1 m
    "contact" height, a contact lasting 10 s). Thresholds only need to be finite and >= 0.
    """

    # -- definitions --------------------------------------------------------------------
    contact_height_m: float = setting(0.05, gt=0.0, le=0.5)
    contact_vz_m_s: float = setting(0.3, gt=0.0, le=10.0)
    contact_min_s: float = setting(0.07, ge=0.0, le=2.0)
    contact_vxy_m_s: float = setting(2.5, gt=0.0, le=20.0)
    float_window_s: float = setting(0.5, ge=0.0, le=10.0)
    skate_speed_cm_s: float = setting(10.0, ge=0.0, le=1000.0)
    limit_tolerance_deg: float = setting(20.0, ge=0.0, le=180.0)
    limit_min_range_deg: float = setting(20.0, ge=0.0, le=360.0)
    self_collision_depth_cm: float = setting(5.0, ge=0.0, le=50.0)
    residual_cutoff_hz: float = setting(10.0, gt=0.0, le=500.0)
    friction: float = setting(1.0, gt=0.0, le=10.0)
    # -- pass/fail thresholds (clip values must be <= these) ----------------------------
    penetration_cm_p95: float = setting(5.0, ge=0.0)
    float_cm_p95: float = setting(5.0, ge=0.0)
    skate_cm_s_median: float = setting(40.0, ge=0.0)
    skate_slide_cm_max: float = setting(10.0, ge=0.0)
    joint_limit_violation_frac: float = setting(0.05, ge=0.0)
    self_collision_frac: float = setting(0.5, ge=0.0)
    jitter_m_s3_median: float = setting(10000.0, ge=0.0)
    residual_force_bw_p95: float = setting(0.5, ge=0.0)

    def as_dict(self) -> dict[str, float]:
        return asdict(self)

    @classmethod
    def from_dict(cls, values: Mapping[str, Any], where: str = "") -> CheckConfig:
        """Defaults overridden by ``values`` (:func:`avatar_models.config.from_data`)."""
        return from_data(cls, values, where)

    @classmethod
    def from_toml(cls, path: str | Path) -> CheckConfig:
        """The settings of a TOML file: flat keys, or all of them in one ``[checks]`` table."""
        data = read_toml(path)
        table, where = (data["checks"], "checks") if set(data) == {"checks"} else (data, "")
        try:
            return cls.from_dict(table, where)
        except ConfigError as exc:
            raise ConfigError(f"{path}: {exc}") from None


THRESHOLD_KEYS: dict[str, str] = {
    "penetration_cm_p95": "penetration",
    "float_cm_p95": "floating",
    "skate_cm_s_median": "skating",
    "skate_slide_cm_max": "skating",
    "joint_limit_violation_frac": "joint_limits",
    "self_collision_frac": "self_collision",
    "jitter_m_s3_median": "jitter",
    "residual_force_bw_p95": "residual_force",
}
"""Clip value (and threshold) name -> the check that computes it."""

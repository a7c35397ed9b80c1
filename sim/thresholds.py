"""Every definition and default threshold of the plausibility checks, in one place.

Conventions follow the physics-based character literature: UHC (Luo et al. 2021,
*Dynamics-Regulated Kinematic Policy for Egocentric Pose Estimation*, NeurIPS) and PhysDiff
(Yuan et al. 2023, *PhysDiff: Physics-Guided Human Motion Diffusion Model*, ICCV). Heights and
skating are measured in the floor frame (floor at z = 0, Z up):

- **contact**: a foot point (the heel or the toe of a foot sole) touches the floor when its
  height is below ``contact_height_m`` AND its vertical speed is below ``contact_vz_m_s``
  (height and velocity, as UHC/PhysDiff label contacts; the vertical speed only, so that a
  foot sliding on the floor still counts as in contact and its sliding is measured). The
  5 cm height is the usual foot-contact height of those papers.
- **penetration**: depth of the deepest MuJoCo floor contact (cm) per frame; the clip's value
  is its 95th percentile.
- **floating**: height of the lowest body point above the floor (cm) when nothing supports
  the body. Running has flight phases, so a frame floats by the lowest height reached within
  ``float_window_s`` around it: a body that touches the floor at least once in that window
  does not float (flights longer than 0.5 s, jumps higher than g t^2 / 8 ~ 30 cm, count).
  PhysDiff's per-frame lowest point height is the special case of a zero window.
- **skating**: horizontal speed of a foot's contact points while in contact (cm/s). The clip's
  value is the worst foot's median; a frame skates above ``skate_speed_cm_s``.
- **joint limits**: a hinge beyond its anatomical range (the body's ranges, AAOS) by more than
  ``limit_tolerance_deg``; the clip's value is the share of frames with any such hinge.
- **self-collision**: MuJoCo contacts between geoms of two bodies the body does not exclude
  (non-adjacent segments), deeper than ``self_collision_depth_cm``; share of frames.
- **jitter**: mean over bodies of the jerk magnitude (m/s^3, third finite difference of body
  positions); the clip's value is the median over frames (noise raises every frame).
- **balance**: signed distance of the centre of mass projected on the floor outside the
  support polygon (ConvexHull of the foot sole corners in contact), cm; informative only,
  walking is dynamically, not statically, balanced.
- **residual force**: the root force from ``mj_inverse`` (contacts disabled) that the floor
  cannot supply, in body weights: its distance to the friction cone (``friction`` from the
  model) where a body geom is within ``contact_height_m`` of the floor, its magnitude where
  none is. ~0 for standing and for ballistic flight, ~1 for a body hanging in the air.

Load overrides from a dict or a TOML file (flat keys, the field names below)::

    contact_height_m = 0.05
    penetration_cm_p95 = 5.0
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path
from typing import Any

from avatar_models.errors import AvatarsimError


class ConfigError(AvatarsimError):
    """A plausibility configuration with an unknown key or a bad value."""


@dataclass(frozen=True)
class CheckConfig:
    """Definitions (first block) and pass/fail thresholds (second block). See the module."""

    # -- definitions --------------------------------------------------------------------
    contact_height_m: float = 0.05
    contact_vz_m_s: float = 0.3
    float_window_s: float = 0.5
    skate_speed_cm_s: float = 10.0
    limit_tolerance_deg: float = 10.0
    self_collision_depth_cm: float = 1.0
    friction: float = 1.0
    # -- pass/fail thresholds (clip values must be <= these) ----------------------------
    penetration_cm_p95: float = 5.0
    float_cm_p95: float = 5.0
    skate_cm_s_median: float = 10.0
    joint_limit_violation_frac: float = 0.02
    self_collision_frac: float = 0.1
    jitter_m_s3_median: float = 1000.0
    residual_force_bw_p95: float = 0.5

    def as_dict(self) -> dict[str, float]:
        return asdict(self)

    @classmethod
    def from_dict(cls, values: Mapping[str, Any]) -> CheckConfig:
        """Defaults overridden by ``values``; unknown keys and non-positive values raise."""
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(values) - known)
        if unknown:
            raise ConfigError(f"unknown check setting(s) {unknown}; known: {sorted(known)}")
        for key, value in values.items():
            if isinstance(value, bool) or not isinstance(value, int | float) or not value >= 0:
                raise ConfigError(f"check setting {key!r} must be a number >= 0, got {value!r}")
        return replace(cls(), **{k: float(v) for k, v in values.items()})

    @classmethod
    def from_toml(cls, path: str | Path) -> CheckConfig:
        try:
            with open(path, "rb") as fh:
                values = tomllib.load(fh)
        except (OSError, tomllib.TOMLDecodeError) as exc:
            raise ConfigError(f"cannot read check config {path}: {exc}") from exc
        return cls.from_dict(values.get("checks", values))


THRESHOLD_KEYS: dict[str, str] = {
    "penetration_cm_p95": "penetration",
    "float_cm_p95": "floating",
    "skate_cm_s_median": "skating",
    "joint_limit_violation_frac": "joint_limits",
    "self_collision_frac": "self_collision",
    "jitter_m_s3_median": "jitter",
    "residual_force_bw_p95": "residual_force",
}
"""Clip value (and threshold) name -> the check that computes it."""

"""``body17``: the common evaluation joint set. All accuracy metrics are computed on it.

Order (17): head, neck, pelvis, then left/right shoulder, elbow, wrist, hip, knee, ankle, foot.
Every rig maps its joints onto these names in its rig file (``[body17]`` table).
"""

from __future__ import annotations

import numpy as np

BODY17: tuple[str, ...] = (
    "head",
    "neck",
    "pelvis",
    "l_shoulder",
    "l_elbow",
    "l_wrist",
    "r_shoulder",
    "r_elbow",
    "r_wrist",
    "l_hip",
    "l_knee",
    "l_ankle",
    "l_foot",
    "r_hip",
    "r_knee",
    "r_ankle",
    "r_foot",
)
INDEX = {name: i for i, name in enumerate(BODY17)}

# Groups as CoolMoves reports errors (hands, upper body, lower body, full body).
HANDS = ("l_wrist", "r_wrist")
UPPER = ("head", "neck", "l_shoulder", "l_elbow", "l_wrist", "r_shoulder", "r_elbow", "r_wrist")
LOWER = ("pelvis", "l_hip", "l_knee", "l_ankle", "l_foot", "r_hip", "r_knee", "r_ankle", "r_foot")
FEET = ("l_ankle", "l_foot", "r_ankle", "r_foot")

# body17 is its own left/right mirror under this permutation.
MIRROR = np.array(
    [INDEX[n.replace("l_", "#").replace("r_", "l_").replace("#", "r_")] for n in BODY17]
)


def group_indices(names: tuple[str, ...]) -> np.ndarray:
    return np.array([INDEX[n] for n in names], dtype=np.int64)

"""What makes two runs of a scenario comparable: its hash and its seed.

The hash covers what decides the measured values (motion, body, devices, methods, cameras,
physics control and the ``[physics]`` check definitions), not what only judges or shows them
(``name``, thresholds, ``expect_fail``, ``[regression]``, ``[report]``) nor the seed, which a
baseline compares on its own so that a message can say which of the two changed.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
from pathlib import Path

from avatarsim.scripts.scenario import Scenario

JUDGING_ONLY = ("name", "seed", "path", "thresholds", "expect_fail", "regression", "report")


def normalised(scenario: Scenario) -> dict:
    """The scenario as plain data without :data:`JUDGING_ONLY`; a motion file's path is made
    relative to the scenario file, so the hash holds across checkouts; the Kinect's skeleton
    source only where there is a Kinect."""
    data = dataclasses.asdict(scenario)
    source = scenario.motion.source
    if source != "builtin" and scenario.path is not None:
        data["motion"]["source"] = os.path.relpath(source, Path(scenario.path).parent)
    if data.get("devices") is not None and not data["devices"]["kinect"]:
        del data["devices"]["kinect_skeleton"]  # no Kinect: it decides nothing
    return {k: v for k, v in data.items() if k not in JUDGING_ONLY}


def scenario_hash(scenario: Scenario) -> str:
    """SHA-256 (hex, 16 digits) of :func:`normalised` as canonical JSON."""
    text = json.dumps(normalised(scenario), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]

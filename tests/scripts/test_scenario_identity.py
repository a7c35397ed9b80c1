"""The scenario hash: what decides the measured values, nothing that only judges them."""

from __future__ import annotations

import dataclasses
import shutil

from avatarsim.scripts.scenario import Threshold, load_scenario
from avatarsim.scripts.scenario_identity import scenario_hash
from tests.scripts.suite.conftest import write_scenario


def test_judging_and_showing_do_not_change_the_hash(tmp_path):
    sc = load_scenario(write_scenario(tmp_path, "a"))
    judged = dataclasses.replace(
        sc,
        name="b",
        seed=9,
        thresholds={"frames": Threshold(max=3.0)},
        expect_fail=("frames",),
        regression={"frames": 1.0},
        report=dataclasses.replace(sc.report, gif=True),
    )
    assert scenario_hash(judged) == scenario_hash(sc)


def test_what_is_measured_changes_the_hash(tmp_path):
    sc = load_scenario(write_scenario(tmp_path, "a"))
    longer = dataclasses.replace(sc, motion=dataclasses.replace(sc.motion, duration_s=2.0))
    stricter = dataclasses.replace(sc, physics={"skate_cm_s_median": 10.0})
    hashes = {scenario_hash(s) for s in (sc, longer, stricter)}
    assert len(hashes) == 3


def test_the_kinect_skeleton_source_counts_only_with_a_kinect(tmp_path):
    sc = load_scenario(write_scenario(tmp_path, "a", tables="[devices]\nvr = true\n"))
    assert sc.devices.kinect is None

    def with_devices(**changes):
        return dataclasses.replace(sc, devices=dataclasses.replace(sc.devices, **changes))

    oracle = with_devices(kinect_skeleton="oracle-noise")
    assert scenario_hash(oracle) == scenario_hash(sc)
    kinect = with_devices(kinect="kinect-v2")
    assert scenario_hash(with_devices(kinect="kinect-v2", kinect_skeleton="oracle-noise")) != (
        scenario_hash(kinect)
    )


def test_a_scenario_with_its_motion_file_hashes_alike_in_any_checkout(tmp_path):
    here = tmp_path / "one"
    write_scenario(here, "a", motion='source = "clip.bvh"')
    (here / "clip.bvh").write_text("not read")
    shutil.copytree(here, tmp_path / "two")
    one, two = (load_scenario(tmp_path / d / "a.toml") for d in ("one", "two"))
    assert one.motion.source != two.motion.source  # resolved to absolute paths
    assert scenario_hash(one) == scenario_hash(two)

"""The devices stage's sweep knobs: each adds one noise model, after the preset."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from render_cams.vr.dropouts import Dropouts
from render_cams.vr.noise import Latency, PositionJitter
from scripts.scenario import DevicesSpec
from scripts.stages.devices import REALISTIC_NOISE, metrics_for, setup


def vr_for(**spec):
    ctx = SimpleNamespace(scenario=SimpleNamespace(devices=DevicesSpec(**spec)))
    return setup(ctx)


def test_no_knob_leaves_the_preset():
    assert vr_for(noise="none").noise == ()
    assert vr_for(noise="realistic").noise == REALISTIC_NOISE


def test_each_knob_adds_its_model_after_the_preset():
    noise = vr_for(noise="realistic", latency_s=0.1, jitter_m=0.02, dropouts_per_s=1.0).noise
    assert noise[: len(REALISTIC_NOISE)] == REALISTIC_NOISE
    extra = noise[len(REALISTIC_NOISE) :]
    assert extra == (Latency(seconds=0.1), PositionJitter(sigma_m=0.02), Dropouts(bursts_per_s=1.0))


def test_kinect_metric_only_with_a_kinect():
    def metrics(**spec):
        return metrics_for(SimpleNamespace(devices=DevicesSpec(**spec)))

    assert metrics() == {"vr_valid_frac"}
    assert metrics(kinect="azure-kinect") == {"vr_valid_frac", "kinect_tracked_frac"}
    assert metrics(vr=False, kinect="kinect-v2") == {"kinect_tracked_frac"}


@pytest.mark.mocap
def test_avatargo_on_a_rig_without_a_t_pose_rest_exits_2_naming_the_way_out(tmp_path, mocap_dir):
    """Bandai's BVH rest pose has the arms down: AvatarGo's walk-in is refused in the devices
    stage, before any synthesis, with the command that does evaluate it there."""
    from typer.testing import CliRunner

    from scripts.cli import app

    clip = mocap_dir / "bandai/dataset-2/data/dataset-2_wave-right-hand_normal_001.bvh"
    scenario = tmp_path / "s.toml"
    scenario.write_text(
        f'name = "b2"\n[motion]\nsource = "{clip}"\nduration_s = 1.0\n'
        '[devices]\ntrackers = true\n[synthesis]\nmethods = ["avatargo", "ik"]\n'
    )
    result = CliRunner().invoke(app, ["run", str(scenario), "--out", str(tmp_path / "o")])
    assert result.exit_code == 2, result.output
    assert "eval avatargo" in result.output and "T-pose" in result.output

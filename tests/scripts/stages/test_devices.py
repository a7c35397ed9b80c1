"""The devices stage's sweep knobs: each adds one noise model, after the preset."""

from __future__ import annotations

from types import SimpleNamespace

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

"""No result depends on which BLAS kernel runs: the same outputs on two OpenBLAS kernels, and
ControllerPose's inference on two CPU instruction sets of torch (MKL and ATen).

The machines here (AMD EPYC with AVX-512) pick OpenBLAS's Haswell kernels by default;
``OPENBLAS_CORETYPE=Sandybridge`` (AVX) is the other kernel set. The scenario
(``tests/data/blas_outputs.toml``) covers IK baseline, AvatarGo, MoveBox, the physics replay
and checks and 1 s of physics control; every metric but wall-clock speed must agree to
``RTOL`` relative (``ATOL`` absolute, in the metric's own unit, for values near zero). Measured:
the largest relative difference is about 2e-7, on a replay error of 1e-6 mm (an absolute
2e-13 mm); the error metrics in cm agree to about 1e-13.
torch does its matrix products in MKL and ATen, not OpenBLAS: ``MKL_ENABLE_INSTRUCTIONS=AVX2``
and ``ATEN_CPU_CAPABILITY=avx2`` make it use its AVX2 kernels instead of AVX-512 (measured:
the same bits; the tolerance allows a few float32 ulps of reordered sums).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

SCENARIO = Path(__file__).resolve().parent / "data" / "blas_outputs.toml"
KERNELS = {"default": {}, "Sandybridge": {"OPENBLAS_CORETYPE": "Sandybridge"}}
TORCH_KERNELS = {
    "default": {},
    "avx2": {"MKL_ENABLE_INSTRUCTIONS": "AVX2", "ATEN_CPU_CAPABILITY": "avx2"},
}
RTOL, ATOL = 1e-8, 1e-9
SPEED_METRICS = ("control_x_real_time",)  # wall-clock, differs run to run

LIFT = """
import sys, numpy as np, torch
from avatarsim.synthesis.controllerpose.features import PER_SKELETON, SKELETON_SLOTS, VR_FEATURES
from avatarsim.synthesis.controllerpose.network import LiftingNet, NetConfig
torch.manual_seed(0)
net = LiftingNet(NetConfig()).eval()
g = torch.Generator().manual_seed(1)
skeletons = torch.randn(64, SKELETON_SLOTS, PER_SKELETON, generator=g)
found = torch.rand(64, SKELETON_SLOTS, generator=g) > 0.3
vr = torch.randn(64, VR_FEATURES, generator=g)
with torch.no_grad():
    np.save(sys.argv[1], net(skeletons, found, vr).numpy())
"""


def run(args: list[str], env: dict[str, str]) -> None:
    done = subprocess.run(
        args, env=os.environ | env, capture_output=True, text=True, timeout=600, check=False
    )
    assert done.returncode in (0, 1), done.stdout + done.stderr  # 1: a threshold, none here


def test_scenario_metrics_agree_across_openblas_kernels(tmp_path):
    cli = [sys.executable, "-m", "avatarsim.scripts.cli", "run", str(SCENARIO)]
    metrics = {}
    for name, env in KERNELS.items():
        report = tmp_path / f"{name}.json"
        run([*cli, "--out", str(tmp_path / name), "--json", str(report)], env)
        metrics[name] = json.loads(report.read_text())["metrics"]
    reference = metrics.pop("default")
    assert len(reference) > 30 and {"ik_err_cm_full", "movebox_err_cm_full"} <= set(reference)
    for name, other in metrics.items():
        assert other.keys() == reference.keys()
        for key, value in reference.items():
            if key not in SPEED_METRICS:
                np.testing.assert_allclose(
                    other[key], value, rtol=RTOL, atol=ATOL, err_msg=f"{key} on {name}"
                )


def test_controllerpose_inference_agrees_across_torch_kernels(tmp_path):
    outputs = {}
    for name, env in TORCH_KERNELS.items():
        run([sys.executable, "-c", LIFT, str(tmp_path / f"{name}.npy")], env)
        outputs[name] = np.load(tmp_path / f"{name}.npy")
    assert outputs["default"].shape == (64, 43)
    # float32 network: products summed in another order differ by a few ulps of the sums.
    np.testing.assert_allclose(outputs["avx2"], outputs["default"], rtol=0, atol=1e-5)

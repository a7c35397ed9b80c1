"""What one AvatarGo ``step()`` costs, and whether a change kept its output.

The inputs are ``avatarsim bench avatargo``'s (a sampled user waving for 4 s, six devices,
realistic VR noise) and, where the real mocap is present, a Bandai dataset-2 right-hand wave
(3 s, the scenario ``bandai2_wave_avatargo``'s clip) worn by a sampled user, the avatar rig
as the avatar. Both with exact and with fixed offsets, the default (analytic) solver.

    python tests/measurements/avatargo_step_cost.py outputs OUT.npz
        run and step outputs (root, local rotations, palm distances, attached flags)
    python tests/measurements/avatargo_step_cost.py compare BEFORE.npz AFTER.npz
        largest difference of each output, and of step against run (attached flags as 0/1)
    python tests/measurements/avatargo_step_cost.py timing [REPEATS]
        thread CPU time of each step on the bench input (exact offsets): per frame the best
        of REPEATS passes (what the step costs), and every pass (what it costs on this
        machine now), with the load average

The script uses only the synthesiser's public API, so it runs on another checkout too:
``PYTHONPATH=/path/to/main python <this file> outputs main.npz``.

Readings of past changes are in the commit log
(``git log -p -- tests/measurements/avatargo_step_cost.py``).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

import avatarsim.avatar_models  # noqa: F401  (the headless GL backend, before anything imports mujoco)
from avatarsim.avatar_models.formats import load_motion
from avatarsim.avatar_models.generator import generate, sample_subject
from avatarsim.avatar_models.rigs import load_rig
from avatarsim.render_cams.vr.noise import REALISTIC_NOISE
from avatarsim.synthesis.avatargo import AvatarGo
from avatarsim.synthesis.avatargo.study import sample_user, setup_for
from avatarsim.synthesis.avatargo.walk_in import walk_in
from avatarsim.synthesis.base import TrackingFrame
from tests.measurements.coolmoves_step_cost import main, print_step_timing

MOCAP = Path(
    os.environ.get(
        "AVATARSIM_MOCAP", Path(__file__).resolve().parents[2].parent / "shared" / "mocap"
    )
)
"""Real mocap, as the tests find it (``tests/conftest.py``)."""
BANDAI = "bandai/dataset-2/data/dataset-2_wave-right-hand_normal_001.bvh"


def bench_input():
    """The bench's avatar skeleton, walk-in sample and stream."""
    truth = generate("wave", sample_subject(np.random.default_rng(0)), 4.0)
    user = sample_user(0, truth.skeleton)
    setup = setup_for(user, REALISTIC_NOISE)
    stream = setup.sample(truth, seed=user.seed)
    return truth.skeleton, walk_in(setup, truth, user.seed, user.heading_rad), stream


def bandai_input():
    """The avatar rig, the walk-in of a sampled user wearing a Bandai dataset-2 wave (3 s),
    and its stream; None without the real mocap."""
    path = MOCAP / BANDAI
    if not path.is_file():
        return None
    truth = load_motion(path).resample(90.0)
    truth = truth[: int(3 * truth.fps)]
    user = sample_user(1, truth.skeleton)
    setup = setup_for(user, REALISTIC_NOISE)
    stream = setup.sample(truth, seed=user.seed)
    avatar = load_rig("avatar").skeleton
    return avatar, walk_in(setup, truth, user.seed, user.heading_rad), stream


def outputs() -> dict[str, np.ndarray]:
    arrays = {}
    for tag, given in {"bench": bench_input(), "bandai": bandai_input()}.items():
        if given is None:
            print(f"{tag}: no real mocap under {MOCAP}, skipped")
            continue
        avatar, sample, stream = given
        for offsets in ("exact", "fixed"):
            synth = AvatarGo(avatar, sample, offsets=offsets)
            motion = synth.run(stream)
            key = f"{tag}/{offsets}"
            arrays[f"{key}/run_rot"] = motion.local_rot
            arrays[f"{key}/run_root"] = motion.root_pos
            arrays[f"{key}/run_palm"] = np.array(synth.palm_distance)
            arrays[f"{key}/run_attached"] = np.array(synth.attached, float)
            synth.reset()
            steps = [
                synth.step(TrackingFrame.from_stream(stream, i)) for i in range(stream.n_samples)
            ]
            arrays[f"{key}/step_rot"] = np.stack([p.local_rot for p in steps])
            arrays[f"{key}/step_root"] = np.stack([p.root_pos for p in steps])
            arrays[f"{key}/step_palm"] = np.array(synth.palm_distance)
            arrays[f"{key}/step_attached"] = np.array(synth.attached, float)
    return arrays


def timing(repeats: int) -> None:
    avatar, sample, stream = bench_input()
    print_step_timing("avatargo", AvatarGo(avatar, sample), stream, repeats)


if __name__ == "__main__":
    main(outputs, timing)

"""Export a replay so it opens in MuJoCo's own viewer (``python -m mujoco.viewer``).

Writes ``model.xml`` (the body's MJCF), ``replay.xml`` (the same model with one keyframe per
exported frame: the viewer's keyframe slider steps through the motion), ``qpos.npy``
``(T, nq)`` and ``replay.json`` (fps, frames, which frames became keys, hinge names). Every
file is written atomically, so an interrupted export never leaves a half-written one.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from avatarsim.avatar_models.fileio import atomic_file, write_atomic, write_json
from avatarsim.sim.humanoid import Humanoid

MAX_KEYS = 2000  # keyframes in replay.xml; longer clips are subsampled evenly


def export_replay(humanoid: Humanoid, qpos: np.ndarray, fps: float, out_dir: Path) -> list[Path]:
    """Write the files above into ``out_dir`` for ``qpos (T, nq)`` of ``humanoid`` (its
    motion's, or a simulation's of it); returns their paths."""
    out_dir = Path(out_dir)
    qpos = np.asarray(qpos, dtype=float)
    model = humanoid.model
    frames = np.unique(np.linspace(0, len(qpos) - 1, min(len(qpos), MAX_KEYS)).round().astype(int))
    # The keys go on a copy of the body's spec, so MuJoCo writes the XML (no text editing).
    replay = humanoid.spec.copy()
    for t in frames:
        replay.add_key(name=f"frame{t}", time=float(t / fps), qpos=qpos[t])
    replay.compile()  # to_xml needs a compiled spec
    paths = [out_dir / n for n in ("model.xml", "replay.xml", "qpos.npy", "replay.json")]
    write_atomic(paths[0], humanoid.mjcf)
    write_atomic(paths[1], replay.to_xml())
    with atomic_file(paths[2]) as fh:
        np.save(fh, qpos)
    info = {
        "fps": fps,
        "frames": int(len(qpos)),
        "key_frames": frames.tolist(),
        "qpos_layout": ["root_x", "root_y", "root_z", "root_qw", "root_qx", "root_qy", "root_qz"]
        + [model.joint(j).name for j in range(1, model.njnt)],
        "open_with": "python -m mujoco.viewer --mjcf replay.xml",
    }
    write_json(paths[3], info)
    return paths

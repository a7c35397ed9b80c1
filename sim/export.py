"""Export a replay so it opens in MuJoCo's own viewer (``python -m mujoco.viewer``).

Writes ``model.xml`` (the body's MJCF), ``replay.xml`` (the same model with one ``<key>`` per
exported frame: the viewer's keyframe slider steps through the motion), ``qpos.npy``
``(T, nq)`` and ``replay.json`` (fps, frames, which frames became keys, hinge names).
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from sim.humanoid import Humanoid

MAX_KEYS = 2000  # keyframes in replay.xml; longer clips are subsampled evenly


def export_replay(humanoid: Humanoid, qpos: np.ndarray, fps: float, out_dir: Path) -> list[Path]:
    """Write the files above into ``out_dir`` for ``qpos (T, nq)`` of ``humanoid`` (its
    motion's, or a simulation's of it); returns their paths."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    xml, model = humanoid.mjcf, humanoid.model
    frames = np.unique(np.linspace(0, len(qpos) - 1, min(len(qpos), MAX_KEYS)).round().astype(int))
    root = ET.fromstring(xml)
    keyframe = ET.SubElement(root, "keyframe")
    for t in frames:
        ET.SubElement(
            keyframe,
            "key",
            name=f"frame{t}",
            time=f"{t / fps:.6g}",
            qpos=" ".join(f"{v:.7g}" for v in qpos[t]),
        )
    ET.indent(root)
    paths = [out_dir / n for n in ("model.xml", "replay.xml", "qpos.npy", "replay.json")]
    paths[0].write_text(xml)
    paths[1].write_text(ET.tostring(root, encoding="unicode"))
    np.save(paths[2], np.asarray(qpos, dtype=float))
    info = {
        "fps": fps,
        "frames": int(len(qpos)),
        "key_frames": frames.tolist(),
        "qpos_layout": ["root_x", "root_y", "root_z", "root_qw", "root_qx", "root_qy", "root_qz"]
        + [model.joint(j).name for j in range(1, model.njnt)],
        "open_with": "python -m mujoco.viewer --mjcf replay.xml",
    }
    paths[3].write_text(json.dumps(info, indent=1))
    return paths

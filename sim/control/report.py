"""Outputs of a physics control run: per-frame CSV, summary JSON, a plot.

The plot answers what a person asks of a control run: how far is each part of the body from
the reference over time and on average, when (if ever) did it fall, how much effort did it
take (mechanical power), and how much the reference's clock had to bend.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from avatarsim.avatar_models.body17 import BODY17
from avatarsim.avatar_models.fileio import write_columns_csv, write_json
from avatarsim.sim.control.controller import ControlResult


def per_frame(result: ControlResult) -> dict[str, np.ndarray]:
    """Columns ``(T,)`` each: time, played reference frame, body17 error (cm, mean and per
    site), root height (m), mechanical power (W), mean absolute torque (N m), fallen (0/1)."""
    n = result.qpos.shape[0]
    err = 100.0 * result.body17_error
    fallen = np.zeros(n)
    if result.fall_frame is not None:
        fallen[result.fall_frame :] = 1.0
    columns = {
        "time_s": np.arange(n) / result.fps,
        "reference_frame": result.reference_frame,
        "body17_err_cm": err.mean(axis=1),
    }
    columns |= {f"err_{name}_cm": err[:, k] for k, name in enumerate(BODY17)}
    return columns | {
        "root_height_m": result.qpos[:, 2],
        "power_w": result.power,
        "mean_abs_torque_nm": np.abs(result.torque).mean(axis=1),
        "fallen": fallen,
    }


def write_csv(result: ControlResult, path: Path) -> Path:
    return write_columns_csv(path, per_frame(result))


def write_plot(result: ControlResult, path: Path, title: str) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pf = per_frame(result)
    t = pf["time_s"]
    fig, axes = plt.subplots(4, 1, figsize=(10, 11))
    ax = axes[0]
    ax.plot(t, pf["body17_err_cm"], color="k", lw=1.2, label="mean")
    for name in ("head", "l_wrist", "r_wrist", "l_ankle", "r_ankle"):
        ax.plot(t, pf[f"err_{name}_cm"], lw=0.8, label=name)
    ax.set_ylabel("cm")
    ax.set_title("distance from the reference (world frame, at the played reference frame)")
    ax.legend(loc="upper left", fontsize=7, ncol=3)
    ax = axes[1]
    upright = result.upright_frames
    ax.bar(BODY17, 100.0 * result.body17_error[upright].mean(axis=0), color="C0")
    ax.set_ylabel("cm")
    ax.set_title("mean error per body17 site while upright")
    ax.tick_params(axis="x", labelrotation=60, labelsize=7)
    ax = axes[2]
    ax.plot(t, pf["power_w"], lw=0.8, color="C3")
    ax.set_ylabel("W")
    ax.set_title(f"mechanical power sum |tau qd| (energy {result.summary()['energy_j']:.0f} J)")
    ax = axes[3]
    rate = np.gradient(result.reference_frame) if len(t) > 1 else np.ones(1)
    ax.plot(t, rate, lw=0.8, color="C2")
    ax.set_ylabel("frames / frame")
    ax.set_title("reference clock rate (1 = real time)")
    ax.set_xlabel("time (s)")
    for ax in axes[[0, 2, 3]]:
        if result.fall_time_s is not None:
            ax.axvline(result.fall_time_s, color="r", ls="--", lw=1, label="fall")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return Path(path)


def write_outputs(
    result: ControlResult, summary: dict, out_dir: Path, title: str
) -> dict[str, Path]:
    """``control.csv``, ``control.json`` (``summary``), ``control.png`` in ``out_dir``."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    return {
        "csv": write_csv(result, out_dir / "control.csv"),
        "json": write_json(out_dir / "control.json", summary),
        "plot": write_plot(result, out_dir / "control.png", title),
    }

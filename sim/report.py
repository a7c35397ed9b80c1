"""Outputs of a plausibility report: summary rows, per-frame CSV, contract JSON, a plot.

The plot has one panel per question a person asks: when does each foot touch the floor,
how deep does the body go into it, how fast do planted feet slide, which frames break a
joint limit, how much force the floor cannot explain. Thresholds are drawn as dashed lines.
"""

from __future__ import annotations

from pathlib import Path

from avatarsim.avatar_models.fileio import write_columns_csv, write_json
from avatarsim.sim.plausibility import PlausibilityReport


def summary_rows(report: PlausibilityReport) -> list[tuple[str, float, float, bool]]:
    """``(name, value, threshold, passed)`` per thresholded clip value."""
    return [(r["name"], r["value"], r["threshold"], r["passed"]) for r in report.thresholds]


def write_csv(report: PlausibilityReport, path: Path) -> Path:
    return write_columns_csv(path, report.per_frame())


def write_plot(report: PlausibilityReport, path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pf, cfg = report.per_frame(), report.config
    t = pf["time_s"]
    fig, axes = plt.subplots(5, 1, figsize=(10, 11), sharex=True)
    ax = axes[0]
    for k, (side, y) in enumerate((("left", 1.0), ("right", 0.0))):
        on = pf[f"contact_{side}"] > 0
        ax.fill_between(t, y, y + 0.8, where=on, step="mid", color=f"C{k}", label=f"{side} foot")
    ax.set_yticks([0.4, 1.4], ["right", "left"])
    ax.set_title("foot contact (height and vertical speed of heel/toe)")
    panels = [
        (axes[1], ["penetration_cm", "float_cm"], "cm", cfg.penetration_cm_p95, "floor"),
        (
            axes[2],
            ["skate_left_cm_s", "skate_right_cm_s"],
            "cm/s",
            cfg.skate_cm_s_median,
            "foot skating in contact",
        ),
        (axes[3], ["limit_excess_deg"], "deg", cfg.limit_tolerance_deg, "beyond joint limits"),
        (
            axes[4],
            ["residual_force_bw"],
            "body weights",
            cfg.residual_force_bw_p95,
            "root residual force",
        ),
    ]
    for ax, keys, unit, limit, title in panels:
        for key in keys:
            if key in pf:
                ax.plot(t, pf[key], label=key, lw=1)
        ax.axhline(limit, ls="--", color="k", lw=0.8, label="threshold")
        ax.set_ylabel(unit)
        ax.set_title(title)
        ax.legend(loc="upper right", fontsize=7)
    axes[-1].set_xlabel("time (s)")
    verdict = "PASSED" if report.passed else f"FAILED: {', '.join(report.failed_checks)}"
    fig.suptitle(f"physics plausibility - {verdict}")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def write_outputs(report: PlausibilityReport, out_dir: Path) -> dict[str, Path]:
    """``check.csv``, ``check.json``, ``check.png`` in ``out_dir``."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    return {
        "csv": write_csv(report, out_dir / "check.csv"),
        "json": write_json(out_dir / "check.json", report.contract()),
        "plot": write_plot(report, out_dir / "check.png"),
    }

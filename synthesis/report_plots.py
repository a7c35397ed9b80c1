"""Bar plots of an evaluation like CoolMoves' Fig. 4 (matplotlib, Agg backend: headless).

- ``errors_by_group.png`` (Fig. 4 A): mean error of the method and the IK baseline for hands,
  upper, lower and full body.
- ``errors_by_activity.png`` (Fig. 4 B): full-body error per class, method beside baseline.
- ``ablation.png``: full-body error of the ablation steps, the paper's values beside ours.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402 - the backend must be chosen first
import numpy as np  # noqa: E402

_WIDTH = 0.38


def _bars(ax, labels: list[str], series: dict[str, list[float]], ylabel: str) -> None:
    x = np.arange(len(labels))
    for i, (name, values) in enumerate(series.items()):
        offset = (i - (len(series) - 1) / 2) * _WIDTH
        bars = ax.bar(x + offset, values, _WIDTH, label=name)
        ax.bar_label(bars, fmt="%.1f", fontsize=7)
    ax.set_xticks(x, labels, rotation=20 if len(labels) > 5 else 0, ha="right")
    ax.set_ylabel(ylabel)
    ax.legend(frameon=False)


def write_plots(results: dict, out: Path) -> dict[str, str]:
    """Write the three PNGs for ``results`` (from :func:`synthesis.evaluate.run_protocol`)
    into ``out``; returns ``{plot: path}``."""
    out.mkdir(parents=True, exist_ok=True)
    title = f"{results['method']} {results['protocol']}"
    if results.get("heading_deg"):
        # A second line: the conditions would not fit beside the plot's own title.
        title += f"\ntest turned up to {results['heading_deg']:g} deg"
    if results.get("db_headings", 1) > 1:
        title += f", database at {results['db_headings']} headings"
    overall, per_class = results["overall"], results["per_activity"]
    written = {}

    fig, ax = plt.subplots(figsize=(6, 3.5))
    groups = list(overall["err_cm"])
    _bars(
        ax,
        groups,
        {
            results["method"]: [overall["err_cm"][g] for g in groups],
            "IK baseline": [overall["baseline_err_cm"][g] for g in groups],
        },
        "mean joint error (cm)",
    )
    ax.set_title(f"{title}: error by body part")
    written["errors_by_group"] = _save(fig, out / "errors_by_group.png")

    fig, ax = plt.subplots(figsize=(max(6, 0.9 * len(per_class)), 3.5))
    classes = list(per_class)
    _bars(
        ax,
        classes,
        {
            results["method"]: [per_class[c]["err_cm"]["full"] for c in classes],
            "IK baseline": [per_class[c]["baseline_err_cm"]["full"] for c in classes],
        },
        "full-body error (cm)",
    )
    ax.set_title(f"{title}: full-body error per class")
    written["errors_by_activity"] = _save(fig, out / "errors_by_activity.png")

    if "ablation_full_cm" in overall:
        fig, ax = plt.subplots(figsize=(6, 3.5))
        steps = list(overall["ablation_full_cm"])
        series = {"ours": [overall["ablation_full_cm"][s] for s in steps]}
        if results["protocol"] == "cross-subject":
            series["paper"] = list(results["paper"]["ablation_full_cm"])
        labels = [s.replace("_no_", "\nno ").replace("_", " ") for s in steps]
        _bars(ax, labels, series, "full-body error (cm)")
        ax.set_title(f"{title}: ablation")
        written["ablation"] = _save(fig, out / "ablation.png")
    return written


def _save(fig, path: Path) -> str:
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return str(path)

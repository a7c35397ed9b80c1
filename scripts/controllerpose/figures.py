"""Figures of the training and evaluation runs, written atomically as PNG."""

from __future__ import annotations

import io
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from avatarsim.avatar_models.fileio import write_atomic  # noqa: E402


def save_png(fig: plt.Figure, path: Path) -> None:
    """``fig`` as a PNG at ``path`` (atomically), then closed."""
    fig.tight_layout()
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=100)
    plt.close(fig)
    write_atomic(path, buffer.getvalue())

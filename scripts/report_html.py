"""One self-contained HTML report per run: checks, metrics, and every picture inlined."""

from __future__ import annotations

import base64
import html
import json
from pathlib import Path
from typing import Any

PICTURES = (
    ("strip_png", "The ground truth on the humanoid over one stride"),
    ("compare_png", "Ground truth next to each synthesis method"),
    ("compare_gif", "Ground truth next to each synthesis method (animated)"),
    ("cameras_png", "What the devices see: controller fisheye cameras and a Kinect depth frame"),
    ("physics_plot", "Physics plausibility over time"),
    ("control_plot", "The humanoid following the ground truth under physics, root unactuated"),
)
MIME = {".png": "image/png", ".gif": "image/gif"}


def image_html(path: Path, caption: str) -> str:
    """A figure with the picture at ``path`` inlined (PNG or GIF) and its caption."""
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return (
        f'<figure><img alt="{html.escape(caption)}" '
        f'src="data:{MIME[path.suffix]};base64,{data}"/>'
        f"<figcaption>{html.escape(caption)}</figcaption></figure>"
    )


def table_html(rows: list[list[str]], header: list[str]) -> str:
    """An HTML table: ``rows`` of HTML cells under a plain-text ``header``."""
    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{cell}</td>" for cell in row) + "</tr>" for row in rows)
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def render_report(results: dict[str, Any], out_dir: Path) -> str:
    """The report's HTML for ``results`` (the run's results.json) with files in ``out_dir``."""
    verdict = "passed" if results["passed"] else "FAILED"
    checks = [
        [
            html.escape(c["name"]),
            f"{c['value']:.4g}",
            html.escape(str(c["threshold"])),
            '<b class="ok">yes</b>' if c["passed"] else '<b class="bad">NO</b>',
        ]
        for c in results["checks"]
    ]
    metrics = [[html.escape(k), f"{v:.4g}"] for k, v in results["metrics"].items()]
    figures = [
        image_html(out_dir / results["outputs"][key], caption)
        for key, caption in PICTURES
        if key in results["outputs"] and (out_dir / results["outputs"][key]).is_file()
    ]
    about = {
        k: results.get(k) for k in ("motion", "body", "devices", "synthesis", "seeds", "versions")
    }
    body = f"""<h1>Scenario <code>{html.escape(results["scenario"])}</code>: {verdict}</h1>
<h2>Checks</h2>{table_html(checks, ["check", "value", "threshold", "passed"])}
{"".join(figures)}
<h2>All metrics</h2>{table_html(metrics, ["metric", "value"])}
<h2>Run</h2><pre>{html.escape(json.dumps(about, indent=2, default=str))}</pre>"""
    return page(f"avatarsim: {results['scenario']}", body)


def page(title: str, body: str) -> str:
    """A self-contained HTML page: ``title`` (plain text) and ``body`` (HTML), one style."""
    return f"""<!doctype html>
<html><head><meta charset="utf-8"><title>{html.escape(title)}</title>
<style>
body {{ font-family: system-ui, sans-serif; margin: 2em; color: #222; }}
table {{ border-collapse: collapse; margin: 1em 0; }}
td, th {{ border: 1px solid #ccc; padding: 0.3em 0.7em; text-align: left; }}
.ok {{ color: #197a1d; }} .bad {{ color: #b3261e; }}
figure {{ margin: 1.5em 0; }} img {{ max-width: 100%; }}
pre {{ background: #f5f5f5; padding: 1em; overflow-x: auto; }}
</style></head><body>
{body}
</body></html>
"""

"""The suite's ``index.html``: scenarios x checks in one table, each scenario linking to its
own report (``<name>/report.html``). Self-contained, no scripts."""

from __future__ import annotations

import html
from typing import Any

from avatarsim.scripts.suite.junit import check_message, regression_message

STYLE = """
body { font-family: system-ui, sans-serif; margin: 2em; color: #222; }
table { border-collapse: collapse; } td, th { border: 1px solid #ccc; padding: 0.3em 0.6em; }
th { writing-mode: sideways-lr; vertical-align: bottom; } th.row { writing-mode: initial; }
.passed { background: #e3f4e3; } .failed, .error { background: #f9dcda; }
.skipped { background: #eee; color: #666; } td.expected { background: #e3eef9; }
"""


def _check_cell(check: dict[str, Any] | None) -> str:
    if check is None:
        return "<td></td>"
    state = "passed" if check["passed"] else "failed"
    if check.get("expected_fail") and check["passed"]:
        state = "expected"
    value = "NaN" if check["value"] is None else f"{check['value']:.3g}"
    return f'<td class="{state}" title="{html.escape(check_message(check))}">{value}</td>'


def _regression_cell(rows: list[dict[str, Any]]) -> str:
    worse = [r for r in rows if r["regressed"]]
    better = [r for r in rows if r["improved"]]
    titles = "\n".join(regression_message(r) for r in worse + better)
    state = "failed" if worse else "passed" if rows else ""
    text = f"{len(worse)} worse, {len(better)} better" if rows else ""
    return f'<td class="{state}" title="{html.escape(titles)}">{text}</td>'


def render_index(suite: dict[str, Any]) -> str:
    """The page for ``suite`` (the suite's results.json)."""
    scenarios = suite["scenarios"]
    names: dict[str, None] = {}  # check names in order of first appearance
    for sc in scenarios:
        names.update((c["name"], None) for c in sc.get("checks", []))
    head = "".join(f"<th>{html.escape(n)}</th>" for n in names)
    rows = []
    for sc in scenarios:
        checks = {c["name"]: c for c in sc.get("checks", [])}
        name = html.escape(sc["name"])
        link = f'<a href="{name}/report.html">{name}</a>' if sc.get("report") else name
        status = html.escape(sc["status"])
        note = f' title="{html.escape(sc["message"])}"' if sc.get("message") else ""
        cells = "".join(_check_cell(checks.get(n)) for n in names)
        rows.append(
            f'<tr><th class="row">{link}</th><td class="{status}"{note}>{status}</td>'
            f"{cells}{_regression_cell(sc.get('regression', []))}</tr>"
        )
    counts = ", ".join(f"{n} {k}" for k, n in suite["counts"].items())
    verdict = "passed" if suite["passed"] else "FAILED"
    return f"""<!doctype html>
<html><head><meta charset="utf-8"><title>avatarsim suite: {verdict}</title>
<style>{STYLE}</style></head><body>
<h1>avatarsim suite: {verdict}</h1><p>{html.escape(counts)}</p>
<table><thead><tr><th class="row">scenario</th><th>status</th>{head}<th>regression</th></tr>
</thead><tbody>{"".join(rows)}</tbody></table>
<p>Hover a cell for its value, threshold and unit; a blue cell failed as expected.</p>
</body></html>
"""

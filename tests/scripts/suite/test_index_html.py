"""index.html: one row per scenario linking its report, one column per check."""

from __future__ import annotations

from html.parser import HTMLParser

from avatarsim.scripts.suite.index_html import render_index


class Cells(HTMLParser):
    def __init__(self):
        super().__init__()
        self.links, self.classes = [], []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "a":
            self.links.append(attrs["href"])
        if tag == "td" and attrs.get("class"):
            self.classes.append(attrs["class"])


def test_a_row_per_scenario_and_a_column_per_check():
    check = {"name": "frames", "value": 9.0, "threshold": 10.0, "passed": True}
    expected = {"name": "float_cm_p95", "value": 9.0, "threshold": 5.0, "passed": True}
    suite = {
        "passed": True,
        "counts": {"passed": 2, "skipped": 1},
        "scenarios": [
            {
                "name": "a",
                "status": "passed",
                "checks": [check],
                "regression": [],
                "report": "a/report.html",
            },
            {
                "name": "b",
                "status": "passed",
                "checks": [expected | {"expected_fail": True}],
                "regression": [],
                "report": "b/report.html",
            },
            {
                "name": "c",
                "status": "skipped",
                "message": "absent",
                "checks": [],
                "regression": [],
                "report": None,
            },
        ],
    }
    page = render_index(suite)
    cells = Cells()
    cells.feed(page)
    assert cells.links == ["a/report.html", "b/report.html"]
    assert cells.classes == ["passed", "passed", "passed", "expected", "skipped"]
    assert page.count("<th>frames</th>") == 1 and page.count("<th>float_cm_p95</th>") == 1

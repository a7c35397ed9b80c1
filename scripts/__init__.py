"""The application: the ``avatarsim`` CLI, the scenario pipeline and suites, the studies and
leaderboard, the dataset generator (:mod:`scripts.dataset`) and the benchmarks.

The public names below load their modules on first use (:mod:`avatar_models.lazy_exports`),
so the CLI starts without them."""

from avatarsim.avatar_models.lazy_exports import lazy_exports

_EXPORTS = {
    "Scenario": ".scenario",
    "ScenarioError": ".scenario",
    "load_scenario": ".scenario",
    "parse_scenario": ".scenario",
    "run_scenario": ".pipeline",
    "SuiteEntry": ".suite.discovery",
    "load_suite": ".suite.discovery",
    "Outcome": ".suite.runner",
    "run_suite": ".suite.runner",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)

"""Scenario suites for headless CI: many scenarios in one ``avatarsim run``.

One concept per module: :mod:`~scripts.suite.discovery` (files -> checked scenarios),
:mod:`~scripts.scenario_identity` (the scenario hash), :mod:`~scripts.suite.runner` (a process
pool), :mod:`~scripts.suite.regression` (comparison with a baseline),
:mod:`~scripts.suite.junit` and :mod:`~scripts.suite.index_html` (the suite's reports),
:mod:`~scripts.suite.command` (the ``run`` command's suite mode).
"""

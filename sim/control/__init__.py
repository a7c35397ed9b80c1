"""Physics control: the MuJoCo humanoid follows a reference motion under simulation, root
unactuated, and a search over the controller's targets for long walks.

Modules, one concept each: :mod:`~sim.control.settings` (gains and criteria),
:mod:`~sim.control.model` (the control variant of the humanoid model),
:mod:`~sim.control.reference` (the reference and its clock), :mod:`~sim.control.qp` (the
whole-body QP), :mod:`~sim.control.balance` (foot placement and clock adaptation),
:mod:`~sim.control.falls` (fall criteria), :mod:`~sim.control.records` (what a run keeps),
:mod:`~sim.control.controller` (the controller and its result), :mod:`~sim.control.search`
(SAMCON-style beam search), :mod:`~sim.control.report` (CSV, JSON, plot of a run).
"""

"""Property: random mutations of a valid dataset config and scenario (wrong types, huge,
negative or NaN numbers, missing and extra keys) give a config or a ConfigError, nothing else."""

from __future__ import annotations

import copy
import tomllib

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from avatarsim.avatar_models.config import ConfigError
from avatarsim.scripts.dataset.budget import check_budget
from avatarsim.scripts.dataset.config import from_dict
from avatarsim.scripts.scenario import DEFAULT_SCENARIO, parse_scenario
from tests.scripts.dataset.builders import TINY

SCENARIO = tomllib.loads(DEFAULT_SCENARIO.read_text())
VALUES = st.one_of(
    st.booleans(),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, -1, 1, 1e300, -1e300, float("nan"), float("inf"), 10**9, 1.5]),
    st.text(max_size=8),
    st.lists(st.integers(), max_size=3),
    st.dictionaries(st.text(max_size=4), st.integers(), max_size=2),
)


def paths(data, prefix=()) -> list[tuple]:
    """Every key path into nested tables and arrays of ``data``."""
    items = data.items() if isinstance(data, dict) else enumerate(data)
    out = []
    for key, value in items:
        out.append((*prefix, key))
        if isinstance(value, dict | list):
            out += paths(value, (*prefix, key))
    return out


@st.composite
def mutated(draw, valid: dict) -> dict:
    data = copy.deepcopy(valid)
    for _ in range(draw(st.integers(1, 3))):
        *parent_path, key = draw(st.sampled_from(paths(data) or [("name",)]))
        parent = data
        for k in parent_path:
            parent = parent[k]
        kind = draw(st.sampled_from(["replace", "delete", "extra"]))
        if kind == "replace" or not isinstance(parent, dict):
            parent[key] = draw(VALUES)
        elif kind == "delete":
            parent.pop(key, None)
        else:
            parent[draw(st.text(min_size=1, max_size=6))] = draw(VALUES)
    return data


def dataset_or_config_error(data: dict) -> None:
    try:
        check_budget(from_dict(data))
    except ConfigError:
        pass


def scenario_or_config_error(data: dict) -> None:
    try:
        parse_scenario(data)
    except ConfigError:
        pass


FAST = settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
SLOW = settings(max_examples=3000, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@FAST
@given(mutated(TINY))
def test_mutated_dataset_configs_raise_only_config_errors(data):
    dataset_or_config_error(data)


@FAST
@given(mutated(SCENARIO))
def test_mutated_scenarios_raise_only_config_errors(data):
    scenario_or_config_error(data)


@pytest.mark.slow
@SLOW
@given(mutated(TINY), mutated(SCENARIO))
def test_many_mutated_configs_raise_only_config_errors(dataset, scenario):
    dataset_or_config_error(dataset)
    scenario_or_config_error(scenario)

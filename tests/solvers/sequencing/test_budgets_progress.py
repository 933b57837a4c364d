"""Every sequencing heuristic has a default budget sized to the instance, and reports its progress."""

from __future__ import annotations

import time

import numpy as np
import pytest

from htetro_opt.errors import ParameterError
from htetro_opt.problems import SequencingInstance
from htetro_opt.scenarios import load_tileset, tileset_path
from htetro_opt.solvers.sequencing import default_time_limit, sequence_waypoints


@pytest.fixture(scope="module")
def instance():
    return SequencingInstance.from_tileset(load_tileset(tileset_path("paper_11x11_fig13d")), start=1)


@pytest.mark.parametrize("method,expected", [("ga", 10.56), ("ga-plain", 10.56), ("greedy", 10.28),
                                             ("local", 10.28), ("exact", 60.0)])
def test_the_default_budget_is_used_and_reported(instance, method, expected):
    assert default_time_limit(method, instance.n) == pytest.approx(expected)
    result = sequence_waypoints(instance, method=method, **({} if method == "exact" else {"seed": 0}))
    if method != "exact":
        assert result.info["time_limit_s"] == pytest.approx(expected)


def test_budgets_grow_with_the_instance_and_are_capped():
    assert default_time_limit("ga", 10) < default_time_limit("ga", 1000) < default_time_limit("ga", 10**6) == 60.0
    assert default_time_limit("greedy", 10**6) == 30.0 and default_time_limit("local", 10**6) == 120.0
    assert default_time_limit("zigzag", 10**6) is None


def test_a_tiny_budget_is_honoured(instance):
    # the time limit is the feature: how long the call ran is measured in CPU time (which a busy
    # machine does not stretch), against a wide margin; the default run would take seconds
    began = time.process_time()
    result = sequence_waypoints(instance, method="ga-plain", seed=0, time_limit=0.05, patience=None)
    assert result.info["stopped"] == "time_limit" and time.process_time() - began < 1.0
    assert result.time_limited


@pytest.mark.parametrize("method,unit_total", [("ga", 2000), ("ga-plain", 2000), ("greedy", 10000), ("local", 3)])
def test_methods_report_progress_that_only_grows(instance, method, unit_total):
    calls = []
    options = {"restarts": 3} if method == "local" else {}
    sequence_waypoints(instance, method=method, seed=1, progress=lambda *a: calls.append(a), **options)
    assert calls, "no progress reported"
    done = [c[0] for c in calls]
    assert done == sorted(done) and all(c[1] == unit_total for c in calls)
    assert all(isinstance(c[2], str) and c[2] for c in calls)


def test_ortools_reports_seconds_against_its_budget(instance):
    calls = []
    sequence_waypoints(instance, method="ortools", time_limit=1.0, progress=lambda *a: calls.append(a))
    # seconds spent, as the progress says them (a report comes from a solution before the limit; the
    # margin is wide for a busy machine, where a solution may come late)
    assert calls and all(0 <= c[0] <= 3.0 and c[1] == 1.0 and c[2].startswith("cost") for c in calls)


def test_a_callable_method_gets_progress_only_if_it_takes_it(instance):
    seen = {}

    def with_progress(inst, *, seed, time_limit, progress):
        seen["progress"] = progress
        return np.arange(inst.n), {}

    def without(inst, *, seed, time_limit):
        return np.arange(inst.n), {}

    reporter = lambda *a: None  # noqa: E731
    sequence_waypoints(instance, method=with_progress, progress=reporter)
    sequence_waypoints(instance, method=without, progress=reporter)
    assert seen["progress"] is reporter


def test_progress_must_be_callable(instance):
    with pytest.raises(ParameterError, match="progress"):
        sequence_waypoints(instance, method="greedy", progress=3)

"""The short fuzz pass (the long one: python fuzz/run.py): every parser and boundary, fed structure-aware
mutations of valid inputs drawn by hypothesis, ends in a return or a clean one-line error, never a traceback."""

from __future__ import annotations

import random
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "fuzz"))
from targets import all_targets, mutate  # noqa: E402

TARGETS = {t.name: t for t in all_targets()}


@pytest.fixture(scope="module", autouse=True)
def _close_targets():
    yield
    for target in TARGETS.values():  # the VMC target's listener thread must not outlive these tests
        if hasattr(target, "close"):
            target.close()


@pytest.mark.parametrize("name", sorted(TARGETS))
def test_the_valid_seed_is_accepted(name):
    assert TARGETS[name](TARGETS[name].seed) is False  # the mutations start from an input that works


@pytest.mark.parametrize("name", sorted(TARGETS))
@settings(max_examples=1500, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.randoms(use_true_random=False), st.integers(1, 6))
def test_mutated_inputs_give_a_result_or_a_clean_error(name, rng: random.Random, rounds: int):
    target = TARGETS[name]
    target(mutate(target.seed, rng, rounds))  # a StylesyncError is caught inside: anything else fails here

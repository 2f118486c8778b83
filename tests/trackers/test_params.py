"""Tracker parameter dataclasses: one per family, read by ``make`` and the registry."""

import dataclasses
import inspect

import numpy as np
import pytest

import trackers
from trackers.params import TrackerParams
from trackers.registry import defaults, get_class, parameters

NAMES = trackers.names()


@pytest.mark.parametrize("name", NAMES)
def test_params_dataclass_is_frozen_and_read_by_the_registry(name):
    cls = get_class(name)
    assert issubclass(cls.Params, TrackerParams)
    assert dataclasses.is_dataclass(cls.Params)
    assert parameters(name) == [*cls.Params.names(), "rng"]
    assert defaults(name) == {**cls.Params.defaults(), "rng": None}
    # help() and inspect show the same keywords and defaults.
    sig = inspect.signature(cls)
    assert {p.name: p.default for p in sig.parameters.values()} == defaults(name)
    tracker = trackers.make(name)
    assert tracker.params == cls.Params()
    with pytest.raises(dataclasses.FrozenInstanceError):
        tracker.params.__setattr__(cls.Params.names()[0], None)


@pytest.mark.parametrize("name", NAMES)
def test_every_default_passed_explicitly_gives_the_same_params(name):
    explicit = {k: v for k, v in defaults(name).items() if k != "rng"}
    assert trackers.make(name, **explicit).params == trackers.make(name).params


def test_fields_read_as_attributes_and_integral_values_are_normalised():
    tracker = trackers.make("dps", n_particles=120.0, n_groups=np.int64(3), lam=5)
    assert tracker.n_particles == 120 and type(tracker.n_particles) is int
    assert type(tracker.params.n_groups) is int
    assert tracker.lam == 5.0 and type(tracker.lam) is float
    assert tracker.params.sigma == (2.0, 2.0, 0.001)
    with pytest.raises(AttributeError, match="no attribute 'nonsense'"):
        tracker.nonsense  # noqa: B018


def test_an_integral_float_ordering_is_an_int_like_every_integer_parameter():
    # ordering=1.0 was refused while (1.0, 0) and n_particles=120.0 were taken.
    assert trackers.make("ps", ordering=1.0).params == trackers.make("ps", ordering=1).params
    assert type(trackers.make("ps", ordering=np.float64(2.0)).params.ordering) is int
    for bad in (True, 1.5, float("nan")):
        with pytest.raises(ValueError, match="ordering must be an int"):
            trackers.make("ps", ordering=bad)
    with pytest.raises(ValueError, match="ordering must be a circular shift >= 0"):
        trackers.make("ps", ordering=-1.0)


def test_a_params_object_can_be_passed_and_overridden():
    from trackers.particle import DistributedPartitionedSampling, DPSParams

    base = DPSParams(n_particles=80, n_groups=2)
    tracker = DistributedPartitionedSampling(base, assignment="interleaved", rng=0)
    assert tracker.params == dataclasses.replace(base, assignment="interleaved")
    with pytest.raises(TypeError, match="params must be a DPSParams"):
        DistributedPartitionedSampling(trackers.make("ps").params)


def test_unknown_keyword_is_a_type_error_naming_it():
    from trackers.kams import KAMS

    with pytest.raises(TypeError, match="unknown parameter 'radius'; valid: kernel"):
        KAMS(radius=3)


@pytest.mark.parametrize(
    "name, params, message",
    [
        ("dps", {"n_particles": 0}, r"n_particles must be an integer in \[1, 1000000\], got 0"),
        ("dps", {"n_particles": 10**9}, r"must be an integer in \[1, 1000000\], got 1000000000"),
        ("annealed", {"n_particles": "abc"}, r"n_particles must be an integer in \[1, 1000000\], "
                                             "got 'abc'"),
        ("hybrid", {"n_particles": 1e9}, r"n_particles must be an integer in \[1, 1000000\]"),
        ("kams", {"lam": "x"}, "lam must be finite and > 0, got 'x'"),
        ("hybrid", {"resampler": "best"}, "unknown resampler 'best'; valid: multinomial"),
        ("dps", {"n_groups": 301}, r"n_groups must be an integer in \[1, 300\] or None"),
        ("ps", {"ordering": -1}, "ordering must be a circular shift >= 0"),
        # A string was read digit by digit ("10" -> the permutation (1, 0)), 1.5 as 1.
        ("ps", {"ordering": "10"}, "ordering must be an int .* or a sequence of target"),
        ("ps", {"ordering": [1.5, 0]}, "ordering must be an int .* got \\[1.5, 0\\]"),
        ("annealed", {"sigma": True}, "sigma must be a number or 3 numbers"),  # was 1 px
        ("kams", {"sigma": [True, True, False]}, "sigma must be a number or 3 numbers"),
        ("condensation", {"rng": True}, "rng must be a numpy Generator, a non-negative int or "
                                        "None, not True"),  # was seed 1
        ("meanshift", {"rng": np.random.SeedSequence(1)}, "not SeedSequence$"),  # 3 lines
        ("condensation", {"lam": -1.0}, "lam must be finite and > 0"),
        ("joint-pf", {"bins": 0}, r"bins must be an integer in \[1, 256\]"),
        ("joint-pf", {"kernel": "gauss"}, "unknown kernel 'gauss'"),
        ("joint-pf", {"a1": np.inf}, "a1 must be finite"),
        ("joint-pf", {"observation": 3}, "observation must be None or an observation model"),
        ("annealed", {"alpha": 0.0}, r"alpha must be in \(0, 1\), got 0.0"),
        ("kams", {"eps": -1.0}, "eps must be a finite number >= 0"),
        ("hybrid", {"sigma": -1.0}, "sigma must be finite and >= 0"),
        ("sok", {"threshold": True}, r"threshold must be in \[0, 1\]"),
        ("kalman", {"velocity_std": 0.0}, r"velocity_std must be in \(0, 1e\+06\]"),
        ("shm", {"p_stay": 0.0}, r"p_stay must be in \(0, 1\]"),
        ("shm-fast", {"evidence": "x"}, "unknown evidence 'x'; valid: union, objects"),
        ("shm", {"use_mse": "no"}, "use_mse must be True or False, got 'no'"),
    ],
)
def test_bad_value_is_one_line_naming_the_parameter(name, params, message):
    with pytest.raises(ValueError, match=message) as info:
        trackers.make(name, **params)
    assert "\n" not in str(info.value)

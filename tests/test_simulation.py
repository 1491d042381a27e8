"""The door to the routes (ehm.simulation.SeatedHuman): one default route everywhere.

Every drive here is SYNTHETIC (ehm.random_vibration)."""

from __future__ import annotations

import inspect

import ehm
from ehm.interfaces.cli.parser import build_parser


def test_the_same_route_by_default_everywhere(human):
    """Issue 32: SeatedHuman.simulate defaulted to the nonlinear route, ehm simulate and ehm.assess to the hybrid
    route: the same call gave different routes from Python and from the command line."""
    defaults = {f.__qualname__: inspect.signature(f).parameters["method"].default
                for f in (ehm.SeatedHuman.simulate, ehm.SeatedHuman.stream, ehm.SeatedHuman.simulate_to, ehm.assess)}
    assert set(defaults.values()) == {"auto"}, defaults
    parser = build_parser()
    for command in (["simulate", "--out", "x"], ["assess", "--motion", "city", "--out", "x"]):
        assert parser.parse_args(command).method == "auto"
    run = human.simulate(ehm.random_vibration("z", 1.0, 0.3, seed=0))
    assert run.extra["route"]["method"] == "auto"

"""Cases: grid expansion, case ids and seeds, relative and random starts."""

import json

import numpy as np
import pytest
from sweep_support import with_

from spine_mj import sweep
from spine_mj.jsonio import to_jsonable


def test_grid_expansion_counts_ids_and_seeds():
    doc = with_(
        grid__mu=[0.5, 1.0, 1.5],
        grid__trajectory=["streamline", "ideal"],
        grid__tip_radius={"logspace": [0.01, 1.0], "num": 3},
    )
    doc["surfaces"] = [
        {"preset": "paper-single-peak"},
        {"preset": "paper-random-convex", "seeds": [3, 4]},
        {"preset": "paper-random-concave", "n_seeds": 2},
    ]
    config = sweep.parse_config(doc)
    cases = sweep.expand_cases(config)
    assert len(cases) == 5 * 3 * 2 * 3
    assert set(config.swept) == {"mu", "trajectory", "tip_radius"}
    assert dict(config.grid)["tip_radius"] == pytest.approx((0.01, 0.1, 1.0))
    assert len({c.case_id for c in cases}) == len(cases)
    assert len({c.seed for c in cases}) == len(cases)
    assert [c.index for c in cases] == list(range(len(cases)))
    labels = sorted({c.surface.label for c in cases})
    assert "paper-random-convex#3" in labels and "paper-single-peak" in labels
    # ids are a function of the parameters only: same after re-parsing, a changed master
    # seed changes the case seeds (and the derived surface seeds) but not explicit ids
    again = sweep.expand_cases(sweep.parse_config(json.loads(json.dumps(doc))))
    assert [c.case_id for c in again] == [c.case_id for c in cases]
    assert [c.seed for c in again] == [c.seed for c in cases]
    doc["sweep"]["seed"] = 7
    other = sweep.expand_cases(sweep.parse_config(doc))
    explicit = [c for c in cases if c.surface.source != "paper-random-concave"]
    assert {c.case_id for c in explicit} <= {c.case_id for c in other}
    assert not {c.seed for c in cases} & {c.seed for c in other}
    assert sweep.parse_config(doc).hash != config.hash


def test_relative_and_random_starts():
    doc = with_(starts={"random": 4})
    case = sweep.expand_cases(sweep.parse_config(doc))[0]
    bounds = case.surface.make().bounds
    pts = case.starts.resolve(bounds, case.seed)
    assert pts.shape == (4, 2)
    assert np.all((pts[:, 0] >= bounds[0]) & (pts[:, 0] <= bounds[1]))
    np.testing.assert_array_equal(pts, case.starts.resolve(bounds, case.seed))
    rel = sweep.StartsSpec(frame="relative", points=((0.0, 1.0), (0.5, 0.5)))
    np.testing.assert_allclose(rel.resolve((-5, 5, -2, 2), 0), [[-5, 2], [0, 0]])


def test_config_hash_case_ids_and_seeds_are_pinned_so_existing_stores_resume():
    """Values a store resumes by: its config hash and case ids. The pydantic schema kept
    those of the hand-written parser; they changed twice since, on purpose: when the
    quasistatic analysis took the shared force cap ``kappa_cap`` (its streamlines differ,
    so a store computed without the cap must not resume), and when an absent ``tip_radius``
    became the rig's default tip for the quasistatic analysis too (it had been a point: the
    second config's streamlines differ)."""
    doc = with_(grid__mu=[0.5, 1.0, 1.5], grid__tip_radius={"logspace": [0.01, 1.0], "num": 3})
    doc["grid"]["trajectory"] = ["streamline", "ideal"]
    doc["surfaces"] = [
        {"preset": "paper-single-peak"},
        {"preset": "paper-random-convex", "seeds": [3, 4]},
        {"preset": "paper-random-concave", "n_seeds": 2},
    ]
    config = sweep.parse_config(doc)
    cases = sweep.expand_cases(config)
    assert config.hash == "ca77f3f5e520b6ddffa0233fa3422998ba1c0eec0f33af07962c18531b19de24"
    assert [c.case_id for c in cases[:2]] == ["176375e7bb37d952", "5a8484c85d375a2c"]
    assert (len(cases), cases[-1].case_id, cases[-1].surface.label) == (
        90,
        "aa3f63a06ae864f4",
        "paper-random-concave#2001798622",
    )
    assert cases[0].seed == 3671383166542398349
    # starts per surface, the absolute frame, a bare analysis name, generator overrides
    config = sweep.parse_config(
        {
            "sweep": {"analyses": "quasistatic"},
            "surfaces": [
                {"preset": "paper-single-peak", "starts": {"frame": "absolute", "x": -3, "y": [-1, -2]}},
                {"preset": "paper-fractal", "seed": 5, "set": {"hurst": 0.6}, "starts": {"random": 3}},
            ],
            "grid": {"mu": {"linspace": [0.5, 1], "num": 3}, "max_steps": [10, 20]},
        }
    )
    cases = sweep.expand_cases(config)
    assert config.hash == "bc9917536ebcf6bac70af8d230b30807d8ee0b1e8a0c2402c9d3211bec5caafb"
    assert [c.case_id for c in cases[:2]] + [cases[-1].case_id] == [
        "194a75e742494a6a",
        "6628d07ed6d38034",
        "5a53974cad264687",
    ]


def test_listing_reports_progress_and_keeps_each_value_apart(monkeypatch):
    """A million cases take minutes to list: expand_cases reports (listed, total) every
    PROGRESS_EVERY_S (here every case); its ids, joined from each value's text written
    once, are those of the canonical JSON of each case, and that memo keeps 0.0 and -0.0
    (and 1 and 1.0) apart, as converting each value afresh did."""
    from spine_mj.sweep import cases as cases_module

    monkeypatch.setattr(cases_module, "PROGRESS_EVERY_S", -1.0)
    seen = []
    config = sweep.parse_config(with_(grid__mu=[0.5, 1.0], grid__dl=[0.01, 0.02, 0.03]))
    cases = sweep.expand_cases(config, lambda i, n: seen.append((i, n)))
    assert seen == [(i, 6) for i in range(6)]
    reference = [
        sweep.digests.digest(
            {
                "surface": c.surface.as_dict(),
                "starts": c.starts.as_dict(),
                "params": {k: to_jsonable(v) for k, v in c.params.items()},
            }
        )[:16]
        for c in cases
    ]
    assert [c.case_id for c in cases] == reference
    fragment = cases_module._memo_fragments()
    texts = [fragment("x", v) for v in (0.0, -0.0, 1, 1.0, 1)]
    assert texts == ['"x":0.0', '"x":-0.0', '"x":1', '"x":1.0', '"x":1']


def test_ids_and_seeds_of_a_mixed_engine_grid_are_those_of_their_definitions():
    """The fast listing (each value's text joined, seeds drawn when read) against the
    definitions, case by case: the digest of each case's canonical JSON and
    :func:`~spine_mj.sweep.cases.case_seed`, on a grid over both engines (Bullet's unread
    MuJoCo options None), the preset's mu, two surfaces with their own starts."""
    pytest.importorskip("pybullet")
    from spine_mj.sweep.cases import case_seed

    doc = with_(sweep__analyses=["engine"], grid__mu=None, sweep__seed=11)
    doc["surfaces"] = [
        {"preset": "paper-single-peak"},
        {"preset": "paper-single-valley", "starts": {"frame": "absolute", "points": [[-3.0, -1.0]]}},
    ]
    doc["grid"] = {"engine": ["mujoco", "bullet"], "settle_time": [0.0, 0.01]}
    doc["drive"] = {"ie": [1e-3, 1e-2], "K": [10, 30.0]}
    cases = sweep.expand_cases(sweep.parse_config(doc))
    assert len(cases) == 2 * 2 * 2 * 2 * 2
    for c in cases:
        canonical = {
            "surface": c.surface.as_dict(),
            "starts": c.starts.as_dict(),
            "params": {k: to_jsonable(v) for k, v in c.params.items()},
        }
        assert c.case_id == sweep.digests.digest(canonical)[:16]
        assert c.seed == case_seed(11, c.case_id)
        if c.params["engine"] == "bullet":
            assert c.params["integrator"] is None and c.params["timestep"] is None
        else:
            assert c.params["integrator"] == "implicitfast"
    assert len({c.case_id for c in cases}) == len(cases)

"""RigInputs, the one record of a rig's inputs (spine_mj.sim.rig_inputs): checked once when
made, hashable, and the same rig whether it or build_rig's keywords are given."""

import pytest

from spine_mj import sim
from spine_mj.errors import SpineInputError
from spine_mj.sim.rig_inputs import RigInputs
from spine_mj.surfaces import single_gaussian


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"ie": 1e-3, "speed_m_s": 0.01}, "give at most one of ie, speed_m_s, rate_n_s"),
        ({"stiffness_number": 10.0, "stiffness_n_m": 5.0}, "give at most one of stiffness_number"),
        ({"engine_options": {"no_such_option": 1}}, "no_such_option: not read by engine mujoco"),
        ({"engine": "no-such-engine"}, "no-such-engine"),
        ({"mass_kg": -1.0}, "mass_kg"),
        ({"mu": -0.5}, "mu_s"),
    ],
)
def test_bad_inputs_are_refused_when_the_record_is_made(kwargs, match):
    with pytest.raises(SpineInputError, match=match):
        RigInputs(**{"mu": 0.5, **kwargs})


@pytest.mark.parametrize("value", ["x", 0, -1, 2.5, float("nan"), float("inf"), True, None, "2"])
def test_a_nonsense_hfield_refinement_is_refused_naming_it_before_any_sizing(value):
    """build_rig(hfield_refinement='x') raised int()'s bare ValueError, True ran as 1."""
    with pytest.raises(
        SpineInputError, match=rf"hfield_refinement .* must be a whole number in \[1, 8192\], got {value!r}"
    ):
        sim.build_rig(single_gaussian(), mu=0.5, hfield_refinement=value)


@pytest.mark.parametrize("value", ["x", 3, 40.5, float("nan"), False, 10**6])
def test_a_nonsense_hfield_resolution_is_refused_naming_it(value):
    with pytest.raises(
        SpineInputError, match=rf"hfield_resolution .* must be a whole number in \[4, 8192\], got {value!r}"
    ):
        RigInputs(mu=0.5, hfield_resolution=value)


def test_whole_floats_count_as_their_integers():
    inputs = RigInputs(mu=0.5, hfield_resolution=41.0, hfield_refinement=2.0)
    assert (inputs.hfield_resolution, inputs.hfield_refinement) == (41, 2)
    assert type(inputs.hfield_resolution) is int and type(inputs.hfield_refinement) is int


def test_options_are_one_sorted_tuple_and_equal_inputs_hash_alike():
    a = RigInputs(mu=0.5, engine_options={"timestep_s": None, "impratio": 2.0, "noslip_iterations": 1})
    b = RigInputs.from_keywords(mu=0.5, noslip_iterations=1, impratio=2.0)
    assert a.engine_options == (("impratio", 2.0), ("noslip_iterations", 1))
    assert a == b and hash(a) == hash(b) and len({a, b}) == 1
    assert a.tip == sim.TipParams(mu_s=0.5)
    assert RigInputs(mu=0.5, ie=1e-2).pace == {"ie": 1e-2, "speed_m_s": None, "rate_n_s": None}


def test_build_rig_takes_the_record_or_its_keywords_alike():
    surface = single_gaussian()
    keywords = {"mu": 0.8, "ie": 1e-2, "stiffness_number": 10.0, "hfield_resolution": 41, "impratio": 2.0}
    by_record = sim.build_rig(surface, RigInputs.from_keywords(**keywords))
    by_keywords = sim.build_rig(surface, **keywords)
    assert by_record.scales == by_keywords.scales
    assert by_record.engine == by_keywords.engine and by_record.engine.impratio == 2.0
    assert by_record.tip == by_keywords.tip
    with pytest.raises(SpineInputError, match="give RigInputs or keywords, not both"):
        sim.build_rig(surface, RigInputs(mu=0.8), ie=1e-2)

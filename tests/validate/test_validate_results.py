"""The studies' typed results: ``as_dict`` gives the keys ``validation.json`` has always had."""

from spine_mj import validate

SPRING_KEYS = [
    "ie",
    "agreement",
    "frechet",
    "median_frechet",
    "lateral",
    "engine_trouble",
    "runs_per_ie",
    "frechet_kind",
]


def _curve(**ramp):
    return validate.BoundaryCurve(
        ie=[1e-2, 1.0],
        agreement=[1.0, 0.5],
        frechet=[0.01, 0.2],
        median_frechet=[0.01, 0.1],
        lateral=[0.0, 0.1],
        engine_trouble=[0.0, 0.0],
        runs_per_ie=2,
        frechet_kind="Frechet",
        **ramp,
    )


def test_a_spring_curve_has_no_ramp_keys_and_a_ramp_curve_has_them_last():
    assert list(_curve().as_dict()) == SPRING_KEYS
    ramp = _curve(
        coverage=[1.0, 0.4], ie_achieved=[1e-2, 1.0], ie_kind="eq", ramp_max_steps=10, ramp_plans={}
    )
    assert list(ramp.as_dict()) == [
        *SPRING_KEYS,
        "coverage",
        "ie_achieved",
        "ie_kind",
        "ramp_max_steps",
        "ramp_plans",
    ]


def test_boundary_result_nests_its_curves_as_dicts():
    res = validate.BoundaryResult(
        curves={"spring": _curve()}, ie_star={}, skip_rate={"spring": [0.0, 0.0]}, families=["f"]
    )
    d = res.as_dict()
    assert list(d) == ["curves", "ie_star", "skip_rate", "families"]
    assert d["curves"]["spring"]["agreement"] == [1.0, 0.5]

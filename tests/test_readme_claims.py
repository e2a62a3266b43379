"""Numbers README quotes from the committed validation reports equal the reports' data.

Each row of ``CLAIMS`` names a claim, gives a regular expression that finds it in
README.md with one group per quoted number, the report it comes from
(``analysis/reports/<report>/validation.json``) and, per group, the path of that number in
the report (keys and list indices joined by ``/``, a negative index counting from the end,
a trailing ``%`` for a share quoted in percent). A quoted number must equal the report's
rounded to the decimals it is quoted with. A claim README no longer makes fails too, so
the table cannot go stale silently: when README is rewritten, rewrite its rows (or
generate README's numbers from the reports).
"""

import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NUM = r"([0-9]+(?:\.[0-9]+)?)"


def _family(name: str) -> list[str]:
    """Agreement on well-conditioned starts [CI], count of runs, median Frechet [CI]."""
    f = f"limit_families/{name}/"
    return [f + "agreement_well_conditioned", f + "agreement_ci/0", f + "agreement_ci/1"]


def _frechet(name: str) -> list[str]:
    f = f"limit_families/{name}/"
    return [f + "median_frechet", f + "median_frechet_ci/0", f + "median_frechet_ci/1"]


def _runs(name: str) -> list[str]:
    return [f"limit_families/{name}/well_conditioned_runs", f"limit_families/{name}/runs"]


def _ill(name: str) -> list[str]:
    return [
        f"limit_families/{name}/ill_conditioned_share/mujoco%",
        f"limit_families/{name}/ill_conditioned_share/reference%",
    ]


_RATE_CI = rf"{NUM} \[{NUM}, {NUM}\]"
_LOCK = "fractal_lock_rate/rows/"

CLAIMS = [
    (
        "the quick plan's ramp coverage at I_e 1e-4",
        rf"ramp covers {NUM} of its path at I_e 1e-4",
        "validation-quick",
        ["ie_curves/ramp/coverage/0"],
    ),
    (
        "the quick plan's limit-study time",
        rf"the quasistatic-limit study is {NUM} s of it",
        "validation-quick",
        ["timings_s/limit"],
    ),
    (
        "full plan, single peak/valley at the corner",
        rf"single peak/valley \*\*{_RATE_CI}\*\* \({NUM} of {NUM}\), {_RATE_CI} L_c",
        "validation-full",
        _family("single_peak_valley") + _runs("single_peak_valley") + _frechet("single_peak_valley"),
    ),
    (
        "full plan, random Gaussian at the corner",
        rf"random Gaussian \*\*{_RATE_CI}\*\* \({NUM} of {NUM}\), {_RATE_CI} L_c",
        "validation-full",
        _family("random_gaussian") + _runs("random_gaussian") + _frechet("random_gaussian"),
    ),
    (
        "full plan, fractal at the corner",
        rf"\*\*{_RATE_CI}\*\* \({NUM} of {NUM}; ill-conditioned: MuJoCo {NUM} %, reference {NUM} %\), "
        rf"{_RATE_CI} L_c",
        "validation-full",
        _family("fractal") + _runs("fractal") + _ill("fractal") + _frechet("fractal"),
    ),
    (
        "full plan, sandpaper at the corner",
        rf"sandpaper \*\*{_RATE_CI}\*\* \({NUM} of {NUM},",
        "validation-full",
        _family("sandpaper") + _runs("sandpaper"),
    ),
    (
        "quick plan, peak/valley and random Gaussian at the corner",
        rf"peak/valley {_RATE_CI} and random Gaussian {_RATE_CI} \({NUM} of {NUM} each\)",
        "validation-quick",
        _family("single_peak_valley") + _family("random_gaussian") + _runs("random_gaussian"),
    ),
    (
        "quick plan, fractal at the corner",
        rf"fractal {_RATE_CI} on {NUM} well-conditioned starts \(ill-conditioned: MuJoCo {NUM} %, "
        rf"reference {NUM} %\)",
        "validation-quick",
        [*_family("fractal"), "limit_families/fractal/well_conditioned_runs", *_ill("fractal")],
    ),
    (
        "static breakaway error, full plan",
        rf"mean error {NUM} %, max {NUM} %",
        "validation-full",
        [
            "static_by_engine/recommended (elliptic, noslip 3)/mean_rel_error%",
            "static_kappa_max_rel_error%",
        ],
    ),
    (
        "static breakaway error, quick plan",
        rf"quick plan max {NUM} %",
        "validation-quick",
        ["static_kappa_max_rel_error%"],
    ),
    (
        "MuJoCo's fractal self-lock rate against the streamline's",
        rf"follows the streamline's: {NUM} -> {NUM} against {NUM} -> {NUM} for H = {NUM} -> {NUM}",
        "validation-full",
        [
            _LOCK + "0/rate_mujoco_corner",
            _LOCK + "-1/rate_mujoco_corner",
            _LOCK + "0/rate_streamline",
            _LOCK + "-1/rate_streamline",
            _LOCK + "0/hurst",
            _LOCK + "-1/hurst",
        ],
    ),
    (
        "the fractal self-lock rate of a moving tip",
        rf"at I_e = {NUM} it drops to {NUM} -> {NUM}",
        "validation-full",
        ["fractal_lock_rate/dynamic_ie", _LOCK + "0/rate_mujoco_dynamic", _LOCK + "-1/rate_mujoco_dynamic"],
    ),
]


def _lookup(data, path: str) -> float:
    percent = path.endswith("%")
    node = data
    for key in path.rstrip("%").split("/"):
        node = node[int(key)] if isinstance(node, list) else node[key]
    return float(node) * (100 if percent else 1)


def _agrees(quoted: str, value: float) -> bool:
    """``quoted`` is ``value`` rounded to the decimals it is written with."""
    decimals = len(quoted.partition(".")[2])
    return abs(value - float(quoted)) <= 0.5 * 10.0**-decimals * (1 + 1e-9)


@pytest.fixture(scope="module")
def readme() -> str:
    return " ".join((ROOT / "README.md").read_text().split())  # line breaks as spaces


@pytest.mark.parametrize(("what", "pattern", "report", "paths"), CLAIMS, ids=[c[0] for c in CLAIMS])
def test_readme_quotes_the_committed_report(readme, what, pattern, report, paths):
    data = json.loads((ROOT / "analysis" / "reports" / report / "validation.json").read_text())
    found = re.findall(pattern, readme)
    assert found, f"README no longer says {what!r} ({pattern}): update README or this table"
    for groups in found:
        groups = (groups,) if isinstance(groups, str) else groups
        assert len(groups) == len(paths)
        for quoted, path in zip(groups, paths, strict=True):
            value = _lookup(data, path)
            assert _agrees(quoted, value), f"README quotes {what} as {quoted}; {report}: {path} = {value:.6g}"


def test_the_rounding_rule():
    assert _agrees("0.945", 0.9454189) and not _agrees("1.0", 0.9454189)
    assert _agrees("1", 0.9659) and _agrees("16.7", 16.6667) and not _agrees("0.0100", 0.01006)

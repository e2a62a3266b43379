"""Numbers README quotes from the committed validation reports equal the reports' data.

Each row of ``CLAIMS`` names a claim, gives a regular expression that finds it in
README.md with one group per quoted number, the report it comes from
(``analysis/reports/<report>/validation.json``) and, per group, the path of that number in
the report (keys and list indices joined by ``/``, a negative index counting from the end,
a trailing ``%`` for a share quoted in percent). A quoted number must equal the report's
rounded to the decimals it is quoted with. A claim README no longer makes fails too, so
the table cannot go stale silently: when README is rewritten, rewrite its rows. README's
numbers are now its headline table, written from the full plan's report by
docs/tools/readme_table.py; this test reads them back independently of that script.
"""

import json
import re
from pathlib import Path

import pytest

from spine_mj.validate.report.common import preset_label

ROOT = Path(__file__).resolve().parents[1]
NUM = r"([0-9]+(?:\.[0-9]+)?(?:e[-+]?[0-9]+)?)"


def _family(name: str) -> list[str]:
    """Agreement on well-conditioned starts [CI], count of runs, median Frechet [CI]."""
    f = f"limit_families/{name}/"
    return [f + "agreement_well_conditioned", f + "agreement_ci/0", f + "agreement_ci/1"]


def _frechet(name: str) -> list[str]:
    f = f"limit_families/{name}/"
    return [f + "median_frechet", f + "median_frechet_ci/0", f + "median_frechet_ci/1"]


_RATE_CI = rf"{NUM} \[{NUM}, {NUM}\]"


_FULL = json.loads((ROOT / "analysis" / "reports" / "validation-full" / "validation.json").read_text())


def _moved(name: str, headline: str) -> bool:
    """A refinement moved ``headline`` of the family outside its interval: README does not
    quote that number."""
    conv = (_FULL.get("convergence") or {}).get(name) or {}
    return any(isinstance(r, dict) and r.get(f"{headline}_converged") is False for r in conv.values())


def _unconverged(name: str) -> bool:
    """A refinement moved one of the family's judged headlines: its target gets no verdict."""
    conv = (_FULL.get("convergence") or {}).get(name) or {}
    return any(
        isinstance(r, dict) and r.get("refined") and r.get("converged") is False for r in conv.values()
    )


def _drive(corner: dict, path: str) -> tuple[str, list[str]]:
    """One corner's ``I_e, K`` (and ``, dt x f`` where the family runs at its own step)."""
    keys = ["ie", "K", *(["timestep_factor"] if "timestep_factor" in corner else [])]
    return ", ".join([rf"{NUM}", rf"{NUM}", *([rf"dt x {NUM}"] if len(keys) == 3 else [])]), [
        f"{path}/{k}" for k in keys
    ]


def _corner(name: str) -> tuple[str, list[str]]:
    """The corner cell's pattern and paths: one ``I_e, K`` where the family's presets share
    it, else ``label I_e, K`` per preset; a report before per-surface corners: its one
    corner, or the fixed I_e at K 30 before any."""
    corner = (_FULL.get("corner") or {}).get(name)
    if not corner:
        return rf"{NUM}, 30 \(fixed\)", ["lowest_ie"]
    if "ie" in corner:
        return _drive(corner, f"corner/{name}")
    presets = list(corner)
    if len({tuple(sorted(c.items())) for c in corner.values()}) == 1:
        return _drive(corner[presets[0]], f"corner/{name}/{presets[0]}")
    cells, paths = [], []
    for p in presets:
        pattern, own = _drive(corner[p], f"corner/{name}/{p}")
        cells.append(rf"{re.escape(preset_label(p))} {pattern}")
        paths += own
    return "; ".join(cells), paths


def _row(label: str, name: str) -> tuple:
    """A family's row of README's headline table (docs/tools/readme_table.py writes it): its
    corner, then its agreement and Frechet distance, each "not quoted" where a refinement
    moved it, and the target's verdict ("no verdict" where either moved)."""
    corner, corner_paths = _corner(name)
    counts = [f"limit_families/{name}/well_conditioned_runs", f"limit_families/{name}/starts"]
    hidden = r"not quoted \(unconverged: [^|]+\)"
    agree, agree_paths = (
        (hidden, []) if _moved(name, "agreement_well_conditioned") else (_RATE_CI, _family(name))
    )
    frechet, frechet_paths = (hidden, []) if _moved(name, "median_frechet") else (_RATE_CI, _frechet(name))
    target = "no verdict" if _unconverged(name) else "(?:not )?met"
    return (
        f"full plan, {label} at the corner",
        rf"\| {label} \| {corner} \| {agree} \| {NUM} / {NUM} \| {frechet} \| {target} \|",
        "validation-full",
        [*corner_paths, *agree_paths, *counts, *frechet_paths],
    )


CLAIMS = [
    _row("single peak/valley", "single_peak_valley"),
    _row("random Gaussian", "random_gaussian"),
    _row("fractal", "fractal"),
    _row("sandpaper", "sandpaper"),
    *([_row("measured \\(shipped scans\\)", "measured")] if "measured" in _FULL["limit_families"] else []),
]


def _lookup(data, path: str) -> float:
    percent = path.endswith("%")
    node = data
    for key in path.rstrip("%").split("/"):
        node = node[int(key)] if isinstance(node, list) else node[key]
    return float(node) * (100 if percent else 1)


def _agrees(quoted: str, value: float) -> bool:
    """``quoted`` is ``value`` rounded to the decimals it is written with."""
    mantissa, _, exponent = quoted.partition("e")
    decimals = len(mantissa.partition(".")[2]) - (int(exponent) if exponent else 0)
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

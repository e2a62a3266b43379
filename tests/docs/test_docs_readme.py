"""README fits on two screens, quotes its headline numbers from the committed
validation.json (docs/tools/readme_table.py), and its local links resolve."""

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "docs" / "tools"))

import readme_table  # noqa: E402

README = (ROOT / "README.md").read_text()


def test_readme_is_at_most_150_lines():
    assert len(README.splitlines()) <= 150


def test_headline_table_is_the_committed_validation():
    assert readme_table.rewritten(README) == README, "run python docs/tools/readme_table.py"


def test_headline_table_has_a_row_per_family():
    validation = readme_table.generate.load_validation("validation-full")
    table = readme_table.table()
    for family, summary in validation["limit_families"].items():
        name = readme_table.generate.FAMILY_NAMES.get(family, family)
        row = next(line for line in table.splitlines() if line.startswith(f"| {name} |"))
        if "| unconverged (" in row:  # a headline not quoted, no verdict (docs/tools/generate.py)
            assert "not quoted (unconverged: " in row and "no verdict" in row
        else:
            assert ("not met" in row) != bool(summary["meets_target"])
        assert f"{summary['well_conditioned_runs']} / {summary['starts']}" in row


def test_a_changed_number_is_noticed():
    table = readme_table.table()
    stale = README.replace(table, table.replace(" / ", " / 1", 1))
    assert stale != README and readme_table.rewritten(stale) == README


def test_local_links_resolve():
    links = re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", README)
    local = [link for link in links if "://" not in link]
    assert local and all((ROOT / link).exists() for link in local), [
        link for link in local if not (ROOT / link).exists()
    ]

"""Every ``spine-mj`` command quoted in README, the site's pages and the gallery names a
real command with real options (docs/tools/doccommands.py)."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "docs" / "tools"))

import doccommands


def _quoted():
    out = []
    for page in doccommands.pages():
        for cmd in doccommands.quoted_commands(page.read_text()):
            out.append((page.relative_to(doccommands.ROOT).as_posix(), cmd))
    return out


QUOTED = _quoted()


def test_the_docs_quote_commands():
    pages = {p for p, _ in QUOTED}
    assert "README.md" in pages and len(QUOTED) > 50


@pytest.mark.parametrize("page,command", QUOTED, ids=[f"{p}:{c[:60]}" for p, c in QUOTED])
def test_quoted_command_resolves(page, command):
    assert doccommands.unknown_words(command) == [], f"{page}: {command}"


def test_a_misspelt_command_or_option_is_caught():
    assert doccommands.unknown_words("spine-mj surface make paper-fractal --hurts 0.7")
    assert doccommands.unknown_words("spine-mj sweep status runs/x --frobnicate")
    assert doccommands.unknown_words("spine-mj surface mkae x.npz")
    assert doccommands.unknown_words("spine-mj sweep example:mujoco-ie.toml --out runs/ie --workers 2") == []


def test_commands_in_comments_and_continuations():
    text = (
        "```sh\nspine-mj surface make --from-file example:plu-1.plu \\\n"
        "    --spacing 2e-6 -o s.npz  # a scan\n```\n"
    )
    assert doccommands.quoted_commands(text) == [
        "spine-mj surface make --from-file example:plu-1.plu --spacing 2e-6 -o s.npz"
    ]

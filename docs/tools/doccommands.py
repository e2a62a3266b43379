"""The ``spine-mj`` commands and code blocks that the documentation quotes.

Used by the docs' tests: every quoted command must name a real command and real options
(:func:`unknown_words`), and every command of a tutorial runs (:func:`blocks`).
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import click

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
#: pages written by the build (the CLI reference quotes the commands' own help)
GENERATED = ("_build", "api/generated", "results/generated", "gallery", "user_guide/cli_reference.md")

_FENCE = re.compile(r"^```(\S*)[^\n]*\n(.*?)^```", re.M | re.S)
_INLINE = re.compile(r"`(spine-mj [^`]+)`")


def pages() -> list[Path]:
    """README, the hand-written pages of ``docs/`` and the gallery's scripts."""
    out = [ROOT / "README.md"]
    for path in sorted(DOCS.rglob("*.md")):
        rel = path.relative_to(DOCS).as_posix()
        if not any(rel == g or rel.startswith(g + "/") for g in GENERATED):
            out.append(path)
    return out


def blocks(text: str) -> list[tuple[str, str]]:
    """The fenced code blocks of a Markdown text as ``(language, body)``, in order."""
    return [(m.group(1).lower(), m.group(2)) for m in _FENCE.finditer(text)]


def shell_commands(body: str) -> list[tuple[str, str]]:
    """The commands of a shell block as ``(command, comment)``: continuations joined,
    the comment after ``#`` (stripped, "" without one) kept apart."""
    out, cur = [], ""
    for raw in body.splitlines():
        line = raw.rstrip()
        if line.endswith("\\"):
            cur += line[:-1] + " "
            continue
        cur += line
        code = _strip_comment(cur).strip()
        if code:
            comment = cur.split(" #", 1)[1].strip() if " #" in cur else ""
            out.append((code, comment))
        cur = ""
    return out


def shell_lines(body: str) -> list[str]:
    """The command lines of a shell block: continuations joined, comments dropped."""
    return [code for code, _ in shell_commands(body)]


def _strip_comment(line: str) -> str:
    try:
        lex = shlex.shlex(line, posix=True, punctuation_chars=False)
        lex.whitespace_split = True
        lex.commenters = "#"
        return " ".join(shlex.quote(t) for t in lex)
    except ValueError:
        return line.split(" #", 1)[0]


def quoted_commands(text: str) -> list[str]:
    """Every ``spine-mj ...`` command of a text: in shell blocks and inline code."""
    found = []
    for lang, body in blocks(text):
        if lang in ("sh", "bash", "console", "shell"):
            found += [ln for ln in shell_lines(body) if ln.startswith("spine-mj ")]
    prose = _FENCE.sub("", text)
    found += [m.group(1) for m in _INLINE.finditer(prose)]
    return found


def _options(cmd: click.Command, ctx: click.Context) -> set[str]:
    names = set(ctx.help_option_names) | {"--help"}
    for p in cmd.params:
        if isinstance(p, click.Option):
            names |= set(p.opts) | set(p.secondary_opts)
    return names


def resolve(words: list[str]) -> tuple[click.Command, click.Context, list[str]]:
    """The command that ``spine-mj WORDS...`` runs, its context, and the words left."""
    from spine_mj.cli import main

    cmd, ctx = main, click.Context(main, info_name="spine-mj")
    rest = list(words)
    while isinstance(cmd, click.Group) and rest:
        name = rest[0]
        sub = cmd.get_command(ctx, name)
        if sub is None and not name.startswith("-") and cmd.get_command(ctx, "run") is not None:
            sub, name = cmd.get_command(ctx, "run"), None  # `sweep CONFIG` runs `sweep run`
        if sub is None:
            break
        if name is not None:
            rest.pop(0)
        ctx = click.Context(sub, info_name=name or "run", parent=ctx)
        cmd = sub
    return cmd, ctx, rest


def unknown_words(command: str) -> list[str]:
    """What in a quoted ``spine-mj ...`` command names no command or option ([] when it
    resolves). Placeholders (``...``, ``SURFACE``, ``[--mu MU]``) are allowed."""
    words = [w.strip("[]") for w in command.split()[1:]]
    words = [w for w in words if w and w != "..."]
    cmd, ctx, rest = resolve(words)
    if isinstance(cmd, click.Group) and rest and not rest[0].startswith("-") and rest[0].islower():
        if rest[0] not in ("DIR", "CONFIG", "SURFACE") and not re.search(r"[./:]", rest[0]):
            return [f"no command {rest[0]!r} under {ctx.command_path!r}"]
    known = _options(cmd, ctx)
    bad = []
    for w in rest:
        if w.startswith("-") and len(w) > 1 and not re.fullmatch(r"-\d.*", w):
            opt = w.split("=", 1)[0]
            if opt not in known:
                bad.append(f"{ctx.command_path}: no option {opt}")
    return bad

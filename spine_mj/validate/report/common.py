"""What every study's report module shares: table cells, Markdown tables and figure links,
and the :class:`ReportContext` a module gets (the output folder and every study's result).

A study's report module (:mod:`spine_mj.validate.report`) defines, from the study's result,
what :func:`~spine_mj.validate.report.document.write_report` puts into ``report.md`` in the
order of the registry (:data:`spine_mj.validate.studies.STUDIES`):

* ``section(result, ctx) -> str | None``: its Markdown section with the figures it drew
  under ``ctx.figures`` (:func:`assemble`), or None for no section at all;
* where the study has any, ``headline(result) -> list[str]``: its lines of the report's
  headline list (the boundary study's I_e*; :meth:`spine_mj.validate.studies.Study.headline`
  gives none for a module without it).

and, where the study has any, three that read its keys of a loaded ``validation.json``
(:meth:`spine_mj.validate.studies.Study.summary_lines`, ``headline_numbers`` and
``results_lines`` call them; a study whose keys are absent gives nothing):

* ``summary_lines(validation) -> list[str]``: its lines of what ``spine-mj validate`` prints
  (:func:`spine_mj.validate.summary.summary_lines`);
* ``headline_numbers(validation) -> dict[str, Headline]``: its numbers that carry an interval
  (:func:`spine_mj.validate.headlines.headline_numbers`), read by :func:`read_number`,
  :func:`read_interval` and :func:`read_table`, which name a malformed field;
* ``results_lines(validation) -> list[str]``: its Markdown block of the site's results page
  of a committed run (``docs/tools/generate.py``), after the page's headline verdicts.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from spine_mj.errors import SpineInputError
from spine_mj.plotting import sig
from spine_mj.validate.convergence import REFINEMENT_LABELS

__all__ = [
    "Headline",
    "ReportContext",
    "assemble",
    "cell",
    "corner_text",
    "image",
    "preset_label",
    "read_interval",
    "read_number",
    "read_table",
    "refinement_rows",
    "refinement_verdict",
    "table",
]


@dataclass(frozen=True)
class ReportContext:
    """What a study's report module may read besides its own result.

    Attributes
    ----------
    out : Path
        The validation's output folder (``out/sweeps`` holds the studies' stores).
    figures : Path
        ``out/figures``, where the modules write their PNGs.
    results : mapping
        Study name (:data:`spine_mj.validate.studies.STUDIES`) -> the result of every
        study given to the report, for a section that cites another study's numbers.
    """

    out: Path
    figures: Path
    results: Mapping[str, Any]

    def draw(self, drawer: Callable[[Any, Path], Path | None], result, name: str) -> str | None:
        """``drawer(result, figures/name)``; the link to the PNG relative to ``out``, or
        None when nothing was drawn."""
        return self.link(drawer(result, self.figures / name))

    def link(self, path: Path | None) -> str | None:
        """``path`` relative to ``out`` if it is a file, else None."""
        return path.relative_to(self.out).as_posix() if path is not None and path.is_file() else None


def cell(v, digits=3) -> str:
    """A table cell: numbers to ``digits`` significant digits, NaN and None as ``-``."""
    try:
        text = sig(v, digits)
    except (TypeError, ValueError):
        return str(v)
    return "-" if text in ("nan", "-") else text


def table(rows: list[dict], cols: list[str], names: list[str] | None = None) -> str:
    """A Markdown table of ``rows`` (dicts), columns ``cols`` headed ``names``."""
    names = names or cols
    out = ["| " + " | ".join(names) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        out.append("| " + " | ".join(cell(r.get(c)) for c in cols) + " |")
    return "\n".join(out)


def image(alt: str, link: str | None, before: str = "") -> str | None:
    """A figure's Markdown (``before`` it, a paragraph), or None without a ``link``."""
    return None if link is None else f"{before}![{alt}]({link})\n"


def assemble(text: str, *figures: str | None) -> str:
    """A section: its text, then each figure that was drawn, a blank line between them."""
    return "\n".join([text, *(f for f in figures if f is not None)])


def corner_text(corner: dict | None) -> str:
    """A family's corner as one cell: ``"I_e, K"`` where its presets share one, else
    ``"label I_e, K; ..."`` per preset (``corner``: preset -> ``{"ie", "K"}``, as
    ``validation.json``'s ``corner``; a report made before each preset had its own gives
    ``{"ie", "K"}``), with ``", dt x f"`` where a family runs at ``f`` times the step rule's
    step (its ``timestep_factor``); ``"-"`` for none."""
    if not corner:
        return "-"
    if "ie" in corner:
        corner = {"": corner}
    pairs = {
        p: f"{sig(c['ie'], 2)}, {sig(c['K'], 2)}"
        + (f", dt x {sig(c['timestep_factor'], 2)}" if "timestep_factor" in c else "")
        for p, c in corner.items()
    }
    if len(set(pairs.values())) == 1:
        return next(iter(pairs.values()))
    return "; ".join(f"{preset_label(p)} {v}" for p, v in pairs.items())


def preset_label(preset: str) -> str:
    """``sandpaper-P36`` -> ``P36``, ``example:di-1.di`` -> ``di-1``, ``paper-fractal`` -> ``fractal``."""
    name = preset.split(":")[-1]
    name = name.rsplit(".", 1)[0] if ":" in preset else name
    return name.removeprefix("sandpaper-").removeprefix("paper-")


def refinement_verdict(entry: dict) -> str:
    """A refinement's verdict in words (an entry of a ``convergence`` dict)."""
    if not entry.get("refined"):
        return entry.get("note", "not refined")
    return {True: "converged", False: "not converged", None: "-"}[entry.get("converged")]


def refinement_rows(convergence: dict, **fields) -> list[dict]:
    """One table row per refinement of a headline's ``convergence`` entry
    (:func:`~spine_mj.validate.convergence.headline_convergence`): ``fields``, then
    ``refinement``, ``runs``, ``base``, ``refined``, ``change`` and ``verdict``."""
    return [
        {
            **fields,
            "refinement": REFINEMENT_LABELS[key],
            "runs": e.get("runs", 0),
            "base": e.get("base"),
            "refined": e.get("refined_value"),
            "change": e.get("change"),
            "verdict": refinement_verdict(e),
        }
        for key, e in convergence.items()
        if key in REFINEMENT_LABELS
    ]


@dataclass(frozen=True)
class Headline:
    """One headline number of a ``validation.json`` with its 95 % interval.

    ``interval`` is ``(low, high)``; ``verdict`` the family's target verdict where the
    number decides one (None otherwise)."""

    key: str
    value: float | None
    interval: tuple[float, float] | None
    verdict: bool | None = None


def _missing(v) -> bool:
    return v is None or (isinstance(v, float) and math.isnan(v))


def read_number(where: str, v, *, missing: bool = False) -> float | None:
    """``v`` as a finite number; None (for None or NaN) only where ``missing`` values are
    allowed; else a :class:`~spine_mj.errors.SpineInputError` naming the field ``where``."""
    if missing and _missing(v):
        return None
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise SpineInputError(f"{where} must be a finite number, got {v!r}")
    return float(v)


def read_table(where: str, v) -> dict:
    """``v`` if it is a JSON object, else an error naming the field ``where``."""
    if not isinstance(v, dict):
        raise SpineInputError(f"{where} must be a JSON object, got {type(v).__name__} {v!r:.60}")
    return v


def read_interval(where: str, v, *, missing: bool = False) -> tuple[float, float] | None:
    """``v`` as a pair ``(low, high)`` of :func:`read_number`; None where a bound is missing."""
    if not (isinstance(v, (list, tuple)) and len(v) == 2):
        raise SpineInputError(f"{where} must be a pair [low, high], got {v!r:.60}")
    lo, hi = (read_number(f"{where}[{i}]", x, missing=missing) for i, x in enumerate(v))
    return None if lo is None or hi is None else (lo, hi)

"""Pages of the site written from the code and the data at every build (``docs/conf.py``).

* ``api/generated/PACKAGE.rst``: one autosummary table per public package, listing every
  name of its ``__all__`` (a name added to ``__all__`` gets its page without a doc edit);
* ``results/generated/``: the validation's headline tables, rendered from the committed
  ``analysis/reports/validation-*/validation.json``, and the committed reports with their
  figures, so that no number on the site is copied by hand;
* ``user_guide/cli_reference.md``: every ``spine-mj`` command's ``--help``.
"""

from __future__ import annotations

import importlib
import inspect
import json
import math
import shutil
from pathlib import Path

import click

ROOT = Path(__file__).resolve().parents[2]
REPORTS = ROOT / "analysis" / "reports"
#: the two committed validation runs: (plan, folder under analysis/reports, how it was made)
PLANS = (
    ("full", "validation-full", "spine-mj validate --out DIR"),
    ("quick", "validation-quick", "spine-mj validate --quick --out DIR  (make demo)"),
)
#: the public packages of the API reference, with one line on what each holds
PACKAGES = {
    "spine_mj": "Surfaces, the engagement ratio, streamlines and comparison metrics (no MuJoCo).",
    "spine_mj.surfaces": "Rough surfaces in physical units, generators and MuJoCo's height field.",
    "spine_mj.sim": "The MuJoCo rig: tip, engine settings, drives, batched runs, spine arrays.",
    "spine_mj.sweep": "Batch runs from a TOML config into a resumable store, on processes or Dask.",
    "spine_mj.validate": "``spine-mj validate``: the studies of MuJoCo against the streamline.",
}
#: the families of the quasistatic corner, as the headline table names them
FAMILY_NAMES = {
    "single_peak_valley": "single peak/valley",
    "random_gaussian": "random Gaussian",
    "fractal": "fractal",
    "sandpaper": "sandpaper",
    "measured": "measured (shipped scans)",
}


# --------------------------------------------------------------------------- API reference
def public_names(mod) -> list[str]:
    """The names of a package's ``__all__`` that an API page lists: not private, and not its
    subpackages and modules (``spine_mj.sim`` is in ``spine_mj.__all__`` so that it loads on
    first use, and has its own page)."""
    return [n for n in mod.__all__ if not n.startswith("_") and not inspect.ismodule(getattr(mod, n))]


def _owners() -> dict[int, str]:
    """For each public object, the package whose page documents it: the most specific one
    that exports it (``spine_mj.Rig`` is documented as ``spine_mj.sim.Rig``)."""
    owners: dict[int, str] = {}
    for name in reversed(list(PACKAGES)):  # the subpackages first, spine_mj last
        mod = importlib.import_module(name)
        for n in public_names(mod):
            obj = getattr(mod, n)
            if callable(obj) or isinstance(obj, type):
                owners.setdefault(id(obj), name)
    return owners


def api_pages(out: Path) -> list[Path]:
    """One reStructuredText page per package of :data:`PACKAGES`: an autosummary table of
    the names of its ``__all__`` it documents, and links to those another package's page
    documents (every object has one page)."""
    out.mkdir(parents=True, exist_ok=True)
    owners = _owners()
    written = []
    for name, blurb in PACKAGES.items():
        mod = importlib.import_module(name)
        own, elsewhere = [], []
        for n in public_names(mod):
            owner = owners.get(id(getattr(mod, n)), name)
            if owner == name:
                own.append(n)
            else:
                elsewhere.append(f"{owner}.{n}")
        title = f"``{name}``"
        lines = [
            title,
            "=" * len(title),
            "",
            f".. automodule:: {name}",
            "   :no-members:",
            "",
            blurb,
            "",
            f".. currentmodule:: {name}",
            "",
            ".. autosummary::",
            "   :toctree: .",
            "",
            *(f"   {n}" for n in own),
            "",
        ]
        if elsewhere:
            lines += [
                f"Also importable from ``{name}``, documented with their package: "
                + ", ".join(f":obj:`~{n}`" for n in elsewhere)
                + ".",
                "",
            ]
        path = out / f"{name}.rst"
        _write(path, "\n".join(lines))
        written.append(path)
    return written


# --------------------------------------------------------------------------- results
def _num(v, digits: int = 3) -> str:
    if v is None or isinstance(v, bool) or not isinstance(v, (int, float)):
        return "-" if v is None else str(v)
    if isinstance(v, float) and not math.isfinite(v):
        return "-"
    return f"{v:.{digits}g}"


def _ci(pair, digits: int = 3) -> str:
    if not pair or len(pair) != 2 or any(not isinstance(v, (int, float)) for v in pair):
        return ""
    return f" [{_num(pair[0], digits)}, {_num(pair[1], digits)}]"


def load_validation(folder: str) -> dict | None:
    """The committed ``analysis/reports/FOLDER/validation.json``, or None when missing."""
    path = REPORTS / folder / "validation.json"
    return json.loads(path.read_text()) if path.is_file() else None


def headline_table(validation: dict) -> list[str]:
    """The headline verdicts as Markdown lines: per family of the quasistatic corner the
    agreement on well-conditioned starts and the median Frechet distance with their 95 %
    intervals, and whether the target is met, at the family's own corner (I_e, K). A number
    that refinement moved outside its interval is not quoted (each headline on its own
    refinements, :func:`spine_mj.validate.convergence.quoted`): the cell says so, and the
    target, which judges both, gets no verdict."""
    from spine_mj.validate.convergence import quoted
    from spine_mj.validate.report.common import corner_text

    cols = [
        "family",
        "corner (I_e, K)",
        "agreement [95 % CI]",
        "well-conditioned / starts",
        "median Frechet / L_c [95 % CI]",
        "target",
        "under refinement",
    ]
    rows = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for key, fam in validation.get("limit_families", {}).items():
        verdict = refinement_verdict(validation, key)
        unconverged = verdict.startswith("unconverged")
        conv = (validation.get("convergence") or {}).get(key)
        corner = fam.get("corner") or (validation.get("corner") or {}).get(key)
        at = corner_text(corner) if corner else f"{_num(validation.get('lowest_ie'))}, 30 (fixed)"
        rows.append(
            "| "
            + " | ".join(
                [
                    FAMILY_NAMES.get(key, key),
                    at,
                    quoted(
                        _num(fam.get("agreement_well_conditioned")) + _ci(fam.get("agreement_ci")),
                        conv,
                        "agreement_well_conditioned",
                    ),
                    f"{fam.get('well_conditioned_runs', '-')} / {fam.get('starts', fam.get('runs', '-'))}",
                    quoted(
                        _num(fam.get("median_frechet")) + _ci(fam.get("median_frechet_ci")),
                        conv,
                        "median_frechet",
                    ),
                    "no verdict" if unconverged else ("met" if fam.get("meets_target") else "not met"),
                    verdict,
                ]
            )
            + " |"
        )
    return rows


def refinement_verdict(validation: dict, family: str) -> str:
    """A family's solution-verification verdict (``convergence``): "converged", the
    refinements under which it moved, or "not checked" for a report without the check."""
    conv = (validation.get("convergence") or {}).get(family)
    if not isinstance(conv, dict):
        return "not checked"
    moved = [
        name.replace("_", " ")
        for name, r in conv.items()
        if isinstance(r, dict) and r.get("refined") and r.get("converged") is False
    ]
    return "unconverged (" + ", ".join(moved) + ")" if moved else "converged"


def _flat(d: dict, prefix: str = "") -> dict:
    out = {}
    for k, v in d.items():
        key = f"{prefix}{k}"
        if isinstance(v, dict):
            out.update(_flat(v, key + "."))
        elif not isinstance(v, list):
            out[key] = v
    return out


def convergence_section(validation: dict) -> list[str]:
    """The convergence checks of the quasistatic corner (time step halved, hfield doubled),
    when the run recorded them: ``validation.json``'s ``convergence`` (per family, per
    variation), or a ``convergence`` entry inside each of ``limit_families``. Empty when
    neither is there (runs made before the check existed)."""
    conv = validation.get("convergence")
    if not isinstance(conv, dict):
        conv = {
            fam: s["convergence"]
            for fam, s in validation.get("limit_families", {}).items()
            if isinstance(s, dict) and isinstance(s.get("convergence"), dict)
        }
    if not conv:
        return []
    rows = []
    for fam, checks in conv.items():
        if not isinstance(checks, dict):
            continue
        nested = {k: v for k, v in checks.items() if isinstance(v, dict)}
        flat = {k: v for k, v in checks.items() if not isinstance(v, (dict, list))}
        for variation, values in nested.items():
            rows.append({"family": FAMILY_NAMES.get(fam, fam), "variation": variation, **_flat(values)})
        if flat:
            rows.append({"family": FAMILY_NAMES.get(fam, fam), "variation": "", **flat})
    if not rows:
        return []
    cols = ["family", "variation"]
    for r in rows:
        cols += [c for c in r if c not in cols]
    lines = [
        "## Convergence of the corner",
        "",
        "Each family's corner run again with the time step halved and with the height "
        "field's resolution doubled; the change in agreement and in the median Frechet "
        "distance, and whether the numbers count as converged (`convergence` in "
        "`validation.json`).",
        "",
        "| " + " | ".join(cols) + " |",
        "|" + "---|" * len(cols),
    ]
    for r in rows:
        lines.append(
            "| "
            + " | ".join(
                _num(r.get(c, None)) if c not in ("family", "variation") else str(r[c]) for c in cols
            )
            + " |"
        )
    return [*lines, ""]


def results_page(plan: str, folder: str, command: str, validation: dict) -> str:
    """The Markdown of one plan's results page."""
    from spine_mj.validate import studies
    from spine_mj.validate.report.verdicts import platform_line, verdicts_section

    timings = validation.get("timings_s") or {}
    total = timings.get("total") if isinstance(timings, dict) else None
    lines = [
        f"# Validation, {plan} plan",
        "",
        f"Rendered at build time from the committed `analysis/reports/{folder}/validation.json`, "
        f"made by `{command}`. The full report that run wrote is "
        f"[its report](reports/{folder}/report.md).",
        "",
        *platform_line(validation.get("platform")),
        "## Headline verdicts",
        "",
        *headline_table(validation),
        "",
        *verdicts_section(validation.get("limit_families", {})),
        *(line for study in studies.STUDIES for line in study.results_lines(validation)),
        *convergence_section(validation),
    ]
    if total is not None:
        lines += [f"Wall time of the run: {_num(total, 4)} s.", ""]
    figures = sorted((REPORTS / folder / "figures").glob("*.png"))
    if figures:
        lines += ["## Figures", ""]
        for fig in figures:
            lines += [f"![{fig.stem}](reports/{folder}/figures/{fig.name})", ""]
    return "\n".join(lines)


def results_pages(out: Path) -> list[Path]:
    """The results pages and a copy of ``analysis/reports`` they link to."""
    out.mkdir(parents=True, exist_ok=True)
    copy = out / "reports"
    if copy.exists():
        shutil.rmtree(copy)
    shutil.copytree(REPORTS, copy, ignore=shutil.ignore_patterns("*.json"))
    written = []
    for plan, folder, command in PLANS:
        validation = load_validation(folder)
        if validation is None:
            continue
        path = out / f"validation_{plan}.md"
        _write(path, results_page(plan, folder, command, validation))
        written.append(path)
    return written


# --------------------------------------------------------------------------- CLI reference
def _commands(group: click.Group, ctx: click.Context, prefix: list[str]):
    for name in group.list_commands(ctx):
        cmd = group.get_command(ctx, name)
        if cmd is None or getattr(cmd, "hidden", False):
            continue
        path = [*prefix, name]
        yield path, cmd
        if isinstance(cmd, click.Group):
            yield from _commands(cmd, click.Context(cmd, info_name=name, parent=ctx), path)


def command_paths() -> list[list[str]]:
    """Every ``spine-mj`` command and subcommand as its words after ``spine-mj``."""
    from spine_mj.cli import main

    ctx = click.Context(main, info_name="spine-mj")
    return [path for path, _ in _commands(main, ctx, [])]


def cli_reference() -> str:
    """Every command's help text, as ``spine-mj COMMAND --help`` prints it."""
    from spine_mj.cli import main

    root = click.Context(main, info_name="spine-mj", terminal_width=100, max_content_width=100)
    lines = [
        "# Command reference",
        "",
        "Every `spine-mj` command's `--help`, written from the commands themselves when the site is built.",
        "",
        "```text",
        main.get_help(root),
        "```",
        "",
    ]
    for path, cmd in _commands(main, root, []):
        ctx = root
        for word in path:
            ctx = click.Context(
                ctx.command.get_command(ctx, word),
                info_name=word,
                parent=ctx,
                terminal_width=100,
                max_content_width=100,
            )
        lines += [f"## spine-mj {' '.join(path)}", "", "```text", cmd.get_help(ctx), "```", ""]
    return "\n".join(lines)


# --------------------------------------------------------------------------- all
def _write(path: Path, text: str) -> None:
    """Write only when the text changed, so Sphinx does not reread unchanged pages."""
    text = text.rstrip() + "\n"
    if not path.is_file() or path.read_text() != text:
        path.write_text(text)


def write_all(docs: Path) -> None:
    """Every generated page under ``docs`` (the site's source folder)."""
    api = docs / "api" / "generated"
    if api.exists():
        shutil.rmtree(api)  # stubs of names no longer public go with them
    api_pages(api)
    results_pages(docs / "results" / "generated")
    _write(docs / "user_guide" / "cli_reference.md", cli_reference())

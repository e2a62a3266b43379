"""``spine-mj validate``: the validation suite, MuJoCo against the quasistatic streamline; and
``spine-mj compare-engines``: MuJoCo beside Bullet, the comparisons too long for a plan."""

from __future__ import annotations

from pathlib import Path

import click

from spine_mj.choices import PLAN_NAMES
from spine_mj.cli.app import Progress, main
from spine_mj.errors import SpineInputError

#: ``--workers`` of both commands: the sweeps' worker processes.
_workers_option = click.option(
    "--workers",
    type=click.IntRange(min=1),
    default=None,
    help="Worker processes for the sweeps (default: all cores).",
)


@main.command("validate")
@click.option(
    "--out",
    "out_dir",
    required=True,
    type=click.Path(),
    help="Output folder: report.md, validation.json, figures/, sweeps/ and stored/ (resumable).",
)
@click.option(
    "--quick",
    is_flag=True,
    help="The quick plan (about 7 min on 2 idle cores): fewer starts and I_e values, coarser hfields.",
)
@click.option(
    "--plan",
    "plan_name",
    type=click.Choice(PLAN_NAMES),
    default=None,
    hidden=True,
    help="Plan by name (smoke: a seconds-long test size).",
)
@_workers_option
@click.option("--quiet", is_flag=True, help="No progress lines.")
def validate_cmd(out_dir, quick, plan_name, workers, quiet):
    """Run the validation suite (MuJoCo against the quasistatic streamline across inertia
    numbers) and write --out/report.md and --out/validation.json.

    \b
    Example:
      spine-mj validate --quick --out demo-out
    """

    from spine_mj import validate
    from spine_mj.validate.summary import summary_lines

    if plan_name is not None and quick and plan_name != "quick":
        raise SpineInputError(f"--quick and --plan {plan_name}: give one of them")
    plan = plan_name or ("quick" if quick else "full")
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise SpineInputError(f"--out {out} exists and is not a folder")
    with Progress("validate", unit="case", quiet=quiet) as bar:
        result = validate.run_validation(
            out,
            plan=plan,
            workers=workers,
            progress=lambda p: bar.update(
                p.finished_cases, max(p.total_cases, 1), desc=f"{p.study}: {p.step}"
            ),
        )
    for line in summary_lines(result):
        click.echo(line)
    click.echo(
        f"wrote {out / 'report.md'} and {out / 'validation.json'} ({result['timings_s']['total']:.0f} s)"
    )


@main.command("compare-engines")
@click.option(
    "--out",
    "out_dir",
    required=True,
    type=click.Path(),
    help="Output folder: engines.json, engines.md (with --headlines headlines.json), sweeps/ (resumable).",
)
@click.option("--quick", is_flag=True, help="Prandtl-Tomlinson over fewer corrugation wavelengths.")
@click.option(
    "--fractal",
    type=click.IntRange(min=0),
    default=0,
    metavar="N",
    help="Also the fractal self-lock rate against H in both engines, N surfaces per H.",
)
@click.option(
    "--headlines",
    type=click.IntRange(min=0),
    default=0,
    metavar="N",
    help="Also the quasistatic-limit corner per family in both engines, N y starts per surface "
    "(and the full report's soft-contact misses rerun).",
)
@click.option(
    "--headlines-plan",
    type=click.Choice(PLAN_NAMES),
    default="quick",
    show_default=True,
    help="The plan whose corner --headlines runs.",
)
@_workers_option
def compare_engines_cmd(out_dir, quick, fractal, headlines, headlines_plan, workers):
    """MuJoCo beside Bullet: the closed forms in both engines (the validation's engines study),
    and with --fractal and --headlines the comparisons too long for a validation plan; writes
    --out/engines.json and --out/engines.md. Needs the [bullet] extra.

    \b
    Example:
      spine-mj compare-engines --out engines-out --fractal 6
    """
    from spine_mj.validate.engines import compare_engines

    text = compare_engines(
        Path(out_dir),
        quick=quick,
        fractal_surfaces=fractal,
        headlines_starts=headlines,
        headlines_plan=headlines_plan,
        workers=workers,
        progress=lambda line: click.echo(line, err=True),
    )
    click.echo(text)

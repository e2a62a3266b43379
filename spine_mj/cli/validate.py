"""``spine-mj validate``: the validation suite, MuJoCo against the quasistatic streamline."""

from __future__ import annotations

from pathlib import Path

import click

from spine_mj.choices import PLAN_NAMES
from spine_mj.cli.app import Progress, main
from spine_mj.errors import SpineInputError


@main.command("validate")
@click.option(
    "--out",
    "out_dir",
    required=True,
    type=click.Path(),
    help="Output folder: report.md, validation.json, figures/, sweeps/ (resumable).",
)
@click.option(
    "--quick",
    is_flag=True,
    help="The quick plan (<= 5 min on 2 cores): fewer starts and I_e values, coarser hfields.",
)
@click.option(
    "--plan",
    "plan_name",
    type=click.Choice(PLAN_NAMES),
    default=None,
    hidden=True,
    help="Plan by name (smoke: a seconds-long test size).",
)
@click.option(
    "--workers",
    type=click.IntRange(min=1),
    default=None,
    help="Worker processes for the sweeps (default: all cores).",
)
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

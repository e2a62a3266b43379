"""``spine-mj sweep ...`` (run, status) and ``spine-mj report``: batch sweeps and their HTML report."""

from __future__ import annotations

from pathlib import Path

import click

from spine_mj.cli.app import (
    Progress,
    _Group,
    check_suffix,
    main,
    refuse_options_not_for,
)


class _SweepGroup(_Group):
    """`sweep CONFIG.toml ...` runs a sweep; `sweep status DIR` is a subcommand."""

    def parse_args(self, ctx, args):
        if args and args[0] not in self.commands and args[0] not in ctx.help_option_names:
            args = ["run", *args]
        return super().parse_args(ctx, args)

    def format_options(self, ctx, formatter):
        """The group's help lists the options of `sweep run`, the command it runs by default."""
        super().format_options(ctx, formatter)
        run = self.commands["run"]
        opts = [p for p in run.params if isinstance(p, click.Option)]
        records = [r for r in (p.get_help_record(ctx) for p in opts) if r]
        with formatter.section("Options of `sweep CONFIG.toml` (sweep run)"):
            formatter.write_dl(records)


@main.group(cls=_SweepGroup)
def sweep():
    """Batch sweeps: `spine-mj sweep CONFIG.toml --out DIR` runs (or resumes) a sweep,
    `spine-mj sweep status DIR` tells how far it got.

    \b
    Examples:
      spine-mj sweep example:paper-quasistatic.toml --out runs/qs
      spine-mj sweep config.toml --out runs/x --scheduler tcp://head:8786
      spine-mj sweep status runs/qs
    """


@sweep.command("run")
@click.argument("config", type=click.Path(dir_okay=False))
@click.option(
    "--out",
    "out_dir",
    required=True,
    type=click.Path(file_okay=False),
    help="Result store folder (resumed if it holds this config's sweep).",
)
@click.option(
    "--workers",
    type=click.IntRange(min=1),
    default=None,
    help="Local worker processes [default: all cores; at most 4 per core].",
)
@click.option(
    "--scheduler", metavar="ADDRESS", help="Run on a Dask distributed cluster (e.g. tcp://head:8786)."
)
@click.option(
    "--overwrite",
    is_flag=True,
    help="Replace a store in --out that holds another config's sweep or one computed on changed "
    "inputs (removes only the files the store wrote).",
)
@click.option("--retry-failed", is_flag=True, help="Run again the cases with failed runs.")
@click.option(
    "--worker-wait",
    type=float,
    default=None,
    metavar="SECONDS",
    help="With --scheduler: how long to wait for its first worker before giving up [default: 300].",
)
@click.option("--quiet", is_flag=True, help="No progress bar.")
def sweep_run(config, out_dir, workers, scheduler, overwrite, retry_failed, worker_wait, quiet):
    """Run the sweep CONFIG (TOML) into --out; re-running resumes and skips finished runs.

    \b
    Example:
      spine-mj sweep example:paper-quasistatic.toml --out runs/qs --workers 4
    """

    from spine_mj import examples
    from spine_mj import sweep as sw

    if scheduler is None:
        refuse_options_not_for("a sweep without --scheduler", ["worker_wait"])
    else:  # the cluster's workers are the scheduler's
        refuse_options_not_for(f"a sweep on --scheduler {scheduler}", ["workers"])
    if worker_wait is None:
        worker_wait = sw.DEFAULT_WORKER_WAIT_S
    cfg = sw.load_config(examples.resolve(config))
    with Progress(cfg.name, unit="case", quiet=quiet) as bar:
        try:
            summary = sw.run_sweep(
                cfg,
                out_dir,
                workers=workers,
                scheduler=scheduler,
                overwrite=overwrite,
                retry_failed=retry_failed,
                progress=lambda p: bar.update(
                    p.finished_cases + p.skipped_cases, p.total_cases, ok=p.ok_runs, failed=p.failed_runs
                ),
                worker_wait_s=worker_wait,
                notice=lambda text: click.echo(text, err=True),
            )
        except sw.SchedulerUnavailable as exc:  # the environment: exit code 1
            raise click.ClickException(str(exc)) from None
        except sw.WorkersCannotStart as exc:  # the environment, not the input: exit code 1
            raise click.ClickException(f"{exc}; the finished cases are kept, a re-run resumes") from None
    if summary.rerun_corrupt:
        click.echo(
            f"ran again {len(summary.rerun_corrupt)} case(s) whose stored rows could not be read: "
            + ", ".join(summary.rerun_corrupt[:10])
            + (" ..." if len(summary.rerun_corrupt) > 10 else "")
        )
    where = (
        f"scheduler {scheduler}"
        if scheduler
        else f"{summary.workers} worker{'s' if summary.workers != 1 else ''}"
    )
    click.echo(
        f"{cfg.name}: {summary.total_runs} runs in {summary.total_cases} cases; "
        f"done {summary.ok_runs}, failed {summary.failed_runs}, skipped "
        f"{summary.skipped_runs} (finished before); {summary.elapsed_s:.1f} s on {where}"
    )
    bad = {k: v for k, v in summary.status_counts.items() if k != "ok"}
    if bad:
        click.echo(
            "not ok in the store: "
            + ", ".join(f"{k} {v}" for k, v in sorted(bad.items()))
            + f" (see {Path(out_dir) / 'runs.parquet'}, column reason)"
        )
    click.echo(f"wrote {Path(out_dir) / 'runs.parquet'}")


@sweep.command("status")
@click.argument("out_dir", metavar="DIR", type=click.Path(file_okay=False))
def sweep_status(out_dir):
    """How far the sweep in DIR got: finished cases and runs by status.

    \b
    Example:
      spine-mj sweep status runs/qs
    """

    from spine_mj import sweep as sw

    st = sw.store_status(out_dir)
    runs = sum(st.status_counts.values())
    click.echo(
        f"{st.name} (config {st.config_hash[:12]}, created {st.created}, "
        f"{st.sessions} session{'s' if st.sessions != 1 else ''})"
    )
    click.echo(
        f"cases {st.finished_cases}/{st.total_cases}, runs {runs}/{st.total_runs}"
        + (" - complete" if st.complete else " - unfinished: run the same command again")
    )
    for status, n in sorted(st.status_counts.items()):
        click.echo(f"  {status:18s} {n}")
    if st.corrupt_cases:
        click.echo(
            f"corrupt case files ({len(st.corrupt_cases)}, run again by a resume): "
            + ", ".join(f"runs/{c}.parquet" for c in st.corrupt_cases)
        )


@main.command("report")
@click.argument("out_dir", metavar="DIR", type=click.Path(file_okay=False))
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False), help="Output .html file.")
def report(out_dir, output):
    """Write an HTML report of the sweep in DIR: runs by status, metric tables and plots of
    the metrics against the swept parameters.

    \b
    Example:
      spine-mj report runs/qs -o qs-report.html
    """

    from spine_mj import sweep as sw

    check_suffix(output, ".html", "-o/--output")
    sw.write_report(out_dir, output)
    click.echo(f"wrote {output}")

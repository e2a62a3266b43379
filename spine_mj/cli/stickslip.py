"""``spine-mj stickslip``: slip-event statistics of a track against the quasistatic
references (docs/physics.md §12)."""

from __future__ import annotations

import click

from spine_mj.choices import ENGINES, check_engine
from spine_mj.cli.app import InputError, Progress, main
from spine_mj.errors import check_positive


def parse_stiffness_list(text: str) -> list[float]:
    """``"0.25,0.5,1"`` as positive floats, or one Error line naming --K."""
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise InputError(f"--K must be comma-separated numbers, got {text!r}") from None
    if not values:
        raise InputError(f"--K must name at least one stiffness number, got {text!r}")
    return [check_positive("--K", v) for v in values]


@main.command("stickslip")
@click.argument("surface_spec", metavar="SURFACE")
@click.option("--mu", type=float, default=None, help="Friction coefficient (default: the preset's).")
@click.option(
    "--K",
    "stiffness",
    default=None,
    help="Stiffness numbers K = k l_s / F_p, comma-separated (default on an ABBM track: a decade "
    "over its ABBM range, spine_mj.surfaces.abbm_stiffness_numbers; required elsewhere).",
)
@click.option("--ie", type=float, default=1e-4, show_default=True, help="Inertia number of the drive.")
@click.option(
    "--engine",
    default=None,
    help="Also run this engine, one spring drive per K (default: the references only); one of "
    + ", ".join(ENGINES)
    + ".",
)
@click.option("--start", type=float, default=None, help="Start x in surface units (default: 5 % in).")
@click.option(
    "--travel",
    type=float,
    default=None,
    help="Track travelled, surface units (default: to 5 % from the end).",
)
@click.option(
    "--bootstrap", type=click.IntRange(min=10), default=100, show_default=True, help="Bootstrap samples."
)
@click.option(
    "--drop-floor",
    type=float,
    default=None,
    help="Smallest force drop (and reload) that counts in drops.parquet [F_p] "
    "(default: slip_catalog.DROP_FLOOR_FP, 1e-3).",
)
@click.option("--out", "out_dir", required=True, type=click.Path(file_okay=False), help="Output folder.")
def stickslip_cmd(surface_spec, mu, stiffness, ie, engine, start, travel, bootstrap, drop_floor, out_dir):
    """Slip events on SURFACE (a track uniform in y, e.g. the abbm preset) at each K: the
    overdamped and inertial quasistatic references, and an engine with --engine.

    Writes events.parquet (one row per slip: source, K, ie, size_lc, duration_s,
    force_drop_fp, ...), drops.parquet (every source's slips as force drops, one rule for
    all), summary.json (per source and K: n_events, tau {value, low, high},
    cutoff_lc, the power-law tests; per K the two-sample tests; per reference and K the
    mean pulse), distributions.png, collapse.png and pulse.png.

    \b
    Example:
      spine-mj stickslip abbm --K 0.25,0.5 --out slips/
    """
    from spine_mj import presets
    from spine_mj.validate.stickslip_outputs import stickslip_to

    if engine is not None:
        check_engine(engine, "--engine")
    ks = None if stiffness is None else parse_stiffness_list(stiffness)
    check_positive("--ie", ie)
    if drop_floor is not None:
        check_positive("--drop-floor", drop_floor)
    surf = presets.open_surface(surface_spec)
    mu = presets.resolve_mu(surf, mu, name="--mu")
    with Progress("stickslip", unit="step") as bar:
        out = stickslip_to(
            out_dir,
            surf,
            mu=mu,
            stiffness_numbers=ks,
            ie=ie,
            surface_name=surface_spec,
            engine=engine,
            start=start,
            travel=travel,
            n_bootstrap=bootstrap,
            drop_floor_fp=drop_floor,
            progress=lambda done, total, what: bar.update(done, total, step=what),
        )
    for line in summary_lines(out.summary):
        click.echo(line)


def summary_lines(summary: dict) -> list[str]:
    """One line per source and K: events, tau with its interval, S_m; with an engine, one
    line per K and reference: its force drops' sizes against the reference's (KS)."""
    lines = []
    for source, per_k in summary["sources"].items():
        for k, entry in per_k.items():
            line = f"{source:>10}  K {k:>6}  {entry['n_events']:>6} slips"
            if "tau" in entry:
                tau, cut = entry["tau"], entry["cutoff_lc"]
                line += (
                    f"  tau {tau['value']:.3f} [{tau['low']:.3f}, {tau['high']:.3f}]"
                    f"  S_m {cut['value']:.3g} L_c [{cut['low']:.3g}, {cut['high']:.3g}]"
                )
            lines.append(line)
    for k, tests in summary["drops"]["two_sample"].items():
        for pair, test in tests.items():
            size = test["size_lc"]
            lines.append(
                f"drops  K {k:>6}  {pair}: sizes KS D {size['ks']:.3f} p {size['ks_p']:.3g}"
                f"  ({'agree' if size['agree'] else 'differ'})"
            )
    return lines

"""``spine-mj examples``: the scans and sweep configs that ship with spine_mj."""

from __future__ import annotations

import click

from spine_mj.cli.app import main


@main.command("examples")
def examples_cmd():
    """List the shipped examples: name them as example:NAME wherever a surface file,
    --from-file or a sweep CONFIG is expected; they run the same from any folder and from
    a wheel install.

    \b
    Examples:
      spine-mj surface info example:plu-1.plu
      spine-mj sweep example:paper-quasistatic.toml --out runs/qs
    """

    from spine_mj import examples

    for name, (kind, path) in examples.list_examples().items():
        click.echo(f"{examples.PREFIX + name:40s} {kind:6s} {path}")

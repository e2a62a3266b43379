"""The reproductions by name, and running one (``spine-mj reproduce NAME``).

:data:`REPRODUCTIONS` maps a name to its figure family's function ``f(*, quick=False,
progress=None, **over)``, which returns ``(numbers, figure)``; :func:`run` runs one and
:func:`run_to` writes its numbers and figure.
"""

from __future__ import annotations

from pathlib import Path

from spine_mj.errors import SpineInputError
from spine_mj.reproduce._common import Progress
from spine_mj.reproduce.fractal import fractal_hurst
from spine_mj.reproduce.random_gaussian import random_gaussian
from spine_mj.reproduce.single_peak import kappa_map, single_peak

__all__ = ["REPRODUCTIONS", "run", "run_to"]

#: The reproductions, by the name ``spine-mj reproduce`` takes.
REPRODUCTIONS = {
    "single-peak": single_peak,
    "random-gaussian": random_gaussian,
    "fractal-hurst": fractal_hurst,
    "kappa-map": kappa_map,
}


def run(name: str, *, quick: bool = False, progress: Progress = None, **options):
    """Run reproduction ``name`` (one of :data:`REPRODUCTIONS`); returns ``(numbers, fig)``."""
    if name not in REPRODUCTIONS:
        raise SpineInputError(f"NAME must be one of {', '.join(REPRODUCTIONS)}, got {name!r}")
    return REPRODUCTIONS[name](quick=quick, progress=progress, **options)


def run_to(
    out_dir, name: str, *, quick: bool = False, progress: Progress = None, **options
) -> tuple[Path, Path]:
    """:func:`run` reproduction ``name`` and write ``out_dir/NAME.json`` (its numbers) and
    ``out_dir/NAME.png`` (its figure), both or neither (``spine-mj reproduce``).

    Returns
    -------
    (Path, Path)
        The JSON and the PNG written.
    """
    from spine_mj.atomic import all_or_none
    from spine_mj.jsonio import write_json
    from spine_mj.plotting import save_figure

    numbers, fig = run(name, quick=quick, progress=progress, **options)
    out = Path(out_dir)
    json_path, png_path = out / f"{name}.json", out / f"{name}.png"
    with all_or_none(json_path, png_path):
        write_json(json_path, numbers)
        save_figure(fig, png_path)
    return json_path, png_path

"""Reproductions of the paper's figures: numbers (a JSON-ready dict) plus a figure.

``REPRODUCTIONS`` maps a name to a function ``f(*, quick=False, progress=None, **over)``
returning ``(numbers, figure)``. Parameters the paper leaves open (mu_s, random-field
widths and heights, fractal size and normalization) come from the ``[engagement]`` and
``[reproduce]`` tables of the ``paper-*`` presets (calibrated in
``analysis/calibration.py``); keyword overrides replace them. ``progress(done, total)`` is
called as work completes.

One module per figure family: :mod:`~spine_mj.reproduce.single_peak` (Figs. 2B, 3-4),
:mod:`~spine_mj.reproduce.random_gaussian` (Fig. 5), :mod:`~spine_mj.reproduce.fractal`
(Figs. 7E, 9); what they share in ``_common``.
"""

from __future__ import annotations

from pathlib import Path

from spine_mj.errors import SpineInputError
from spine_mj.reproduce._common import Progress
from spine_mj.reproduce.fractal import fig9_rms_height, fig9_seeds, fractal_hurst, raw_rms_height
from spine_mj.reproduce.random_gaussian import random_gaussian
from spine_mj.reproduce.single_peak import calibrate_single_peak_mu, kappa_map, kappa_map_to, single_peak

__all__ = [
    "REPRODUCTIONS",
    "calibrate_single_peak_mu",
    "fig9_rms_height",
    "fig9_seeds",
    "fractal_hurst",
    "kappa_map",
    "kappa_map_to",
    "random_gaussian",
    "raw_rms_height",
    "run",
    "run_to",
    "single_peak",
]

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

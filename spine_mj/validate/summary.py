"""The validation's headline in a few lines of text (what ``spine-mj validate`` prints):
each study's own lines (:meth:`~spine_mj.validate.studies.Study.summary_lines`: I_e* per
protocol, each family's agreement at its corner, the static kappa error, the fractal
self-lock rates, the arrays' pooled differences, the engines side by side), in the order of
the registry, read from the result :func:`~spine_mj.validate.run_validation` returns (the
content of ``validation.json``)."""

from __future__ import annotations

from spine_mj.validate import studies

__all__ = ["summary_lines"]


def summary_lines(result: dict) -> list[str]:
    """The headline lines of a validation ``result`` (a loaded ``validation.json``); the
    studies a plan did not run (fractal lock rate, arrays) give no line."""
    return [line for study in studies.STUDIES for line in study.summary_lines(result)]

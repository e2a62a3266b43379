"""Jinja2 templates of the reports, shipped inside the package (``*.j2`` files here).

``sweep_report.html.j2`` (:mod:`spine_mj.sweep.report`) is rendered with HTML
autoescaping; ``validation_report.md.j2`` (:mod:`spine_mj.validate.report`) without. Both
get the filter ``sig`` (:func:`spine_mj.plotting.sig`: 3 significant digits).
"""

from __future__ import annotations

import functools

import jinja2

from spine_mj.plotting import sig

__all__ = ["render"]


@functools.lru_cache(maxsize=1)
def _environment() -> jinja2.Environment:
    env = jinja2.Environment(
        loader=jinja2.PackageLoader("spine_mj", "templates"),
        autoescape=jinja2.select_autoescape(enabled_extensions=("html.j2",), default=False),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
    )
    env.filters["sig"] = sig
    return env


def render(name: str, **context) -> str:
    """The template ``name`` of this folder rendered with ``context``.

    Raises
    ------
    jinja2.UndefinedError
        The template uses a name that ``context`` does not give.
    """
    return _environment().get_template(name).render(**context)

"""Figures and ``report.md`` of the validation suite, one module per study.

Each study module of :mod:`spine_mj.validate` has a report module of the same name here
(:mod:`~spine_mj.validate.report.static_map`, ...), which draws the study's figures and
writes its section from the study's typed result; :mod:`~spine_mj.validate.report.common`
holds what they share (table cells, Markdown tables, figure links) and
:mod:`~spine_mj.validate.report.document` puts the sections together in the order of the
registry (:data:`spine_mj.validate.studies.STUDIES`): :func:`spine_mj.validate.write_report`.

A new study is one study module, one report module here (``headline`` and ``section``,
see :mod:`~spine_mj.validate.report.common`) and one line of the registry.

This package imports nothing itself: the registry imports the report modules, and the
document imports the registry.
"""

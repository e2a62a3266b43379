"""The ``spine-mj`` command line (click).

Modules: :mod:`~spine_mj.cli.app` (the root group :func:`main`, the program :func:`run`,
one-line errors, progress and shared argument parsing), :mod:`~spine_mj.cli.options` (the
options several commands share, such as ``--fill``), and one module per family of
commands: :mod:`~spine_mj.cli.surface` (``surface make/show/info/export``),
:mod:`~spine_mj.cli.theory` (``kappa``, ``streamline``, ``reproduce``),
:mod:`~spine_mj.cli.sim` (``simulate``, ``replay``, ``view``, ``sim export``),
:mod:`~spine_mj.cli.sweep` (``sweep run/status``, ``report``), :mod:`~spine_mj.cli.array`
(``array``), :mod:`~spine_mj.cli.validate` (``validate``, ``compare-engines``), :mod:`~spine_mj.cli.hold`
(``hold``) and :mod:`~spine_mj.cli.examples`
(``examples``).

The CLI starts at once: a command's module is imported when the command is named (or its
help listed), and each module imports the library inside its commands, so ``spine-mj
--help`` loads neither numpy nor MuJoCo (``tests/cli/test_cli_startup.py``). Its public
names are listed in ``__init__.pyi`` and load from :mod:`~spine_mj.cli.app` on first use,
as every public package's do.
"""

import lazy_loader as _lazy

__getattr__, __dir__, __all__ = _lazy.attach_stub(__name__, __file__)

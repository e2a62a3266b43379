"""The command line's shared plumbing: the root group ``main``, the program ``run``, one-line
errors (:class:`InputError`, exit code 2), the progress display and the argument parsers the
command modules share.

Bad input ends in one line ``Error: ...`` on stderr and exit code 2, never a traceback;
outputs are written atomically, so a failed command leaves nothing half-written.
Printing and progress bars live in the CLI; the library reports through return values and
callbacks.
"""

from __future__ import annotations

import importlib
import os
import signal
import sys
import time
import warnings
from pathlib import Path
from typing import ClassVar

import click

from spine_mj.errors import SpineInputError

INPUT_ERROR_EXIT = 2
#: A preparation shows its stages once it has taken this long [s] (quick ones print nothing).
PREPARATION_DELAY_S = 2.0


class Progress:
    """The CLI's one progress display: a tqdm bar on stderr, or nothing with ``quiet``.

    ``update(done, total, desc=None, **postfix)`` moves the bar to ``done`` of ``total``
    (a new ``desc`` starts a fresh bar); used as a context manager it closes the bar. Once
    a SIGTERM came (:func:`run`), an update exits as the kill: a library that caught the
    handler's exit (measured: a run at I_e 1e-6 went on 120 s past its SIGTERM on a loaded
    machine) stops at its next progress report. With ``delay_s`` nothing shows until that
    long after the display was made: a preparation that is quick stays silent.
    """

    def __init__(self, desc: str, *, unit: str = "it", quiet: bool = False, delay_s: float = 0.0):
        self.desc, self.unit, self.quiet, self.bar = desc, unit, quiet, None
        self.shown_from = time.monotonic() + delay_s

    def update(self, done: float, total: float, desc: str | None = None, **postfix) -> None:
        if _TERMINATED:  # a SIGTERM whose exit a library swallowed (numba compiling, a native call)
            raise SystemExit(128 + _TERMINATED[0])
        if self.quiet or time.monotonic() < self.shown_from:
            return
        if self.bar is not None and desc is not None and desc != self.bar.desc:
            self.close()
        if self.bar is None:
            from tqdm import tqdm

            tqdm.monitor_interval = 0  # no monitor thread: a single-threaded CLI forks its workers
            self.bar = tqdm(
                total=total, desc=desc or self.desc, unit=self.unit, dynamic_ncols=True, file=sys.stderr
            )
        self.bar.total = total
        self.bar.n = done
        if postfix:
            self.bar.set_postfix(postfix, refresh=False)
        self.bar.refresh()

    def complete(self) -> None:
        """Move an open bar to its total: a job that ended early (a breakaway) is done too."""
        if self.bar is not None:
            self.update(self.bar.total, self.bar.total)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class InputError(click.ClickException):
    """A :class:`SpineInputError` (or unreadable file) shown as one line, exit code 2."""

    exit_code = INPUT_ERROR_EXIT


#: The usage error by which a group given no arguments shows its help (click >= 8.2).
_SHOWS_HELP = tuple(e for e in [getattr(click.exceptions, "NoArgsIsHelpError", None)] if e)


def _one_line(exc: click.UsageError) -> str:
    """A usage error's message (a choice list spans lines) and its help hint, on one line."""
    hint = f" (see '{exc.ctx.command_path} --help')" if exc.ctx is not None else ""
    return " ".join(exc.format_message().split()) + hint


class _Command(click.Command):
    """A command run with numpy's overflow and invalid-value warnings off (results are
    checked for finiteness where it matters), and other libraries' warnings held back: a
    command that fails shows only its one error line, one that succeeds shows each warning
    as one line after its work (never a warning's source line). numpy is imported here,
    when a command runs, not for ``--help``."""

    def invoke(self, ctx):
        import numpy as np

        with warnings.catch_warnings(record=True) as caught, np.errstate(all="ignore"):
            result = super().invoke(ctx)
        for text in dict.fromkeys(f"{w.category.__name__}: {w.message}" for w in caught):
            click.echo(f"Warning: {' '.join(text.split())}", err=True)
        return result


class _Group(click.Group):
    """Turns the library's input errors and click's usage errors into :class:`InputError`
    (one line) for every subcommand, and so too a request too large for memory or out of
    floating-point range that no check at the boundary caught (not a traceback)."""

    command_class = _Command
    group_class = type

    def parse_args(self, ctx, args):
        """The root's own options (``spine-mj --bogus``) fail here, before :meth:`invoke`."""
        try:
            return super().parse_args(ctx, args)
        except _SHOWS_HELP:
            raise
        except click.UsageError as exc:
            raise InputError(_one_line(exc)) from None

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except _SHOWS_HELP:
            raise
        except click.UsageError as exc:  # click's own: usage, hint and error in one line
            raise InputError(_one_line(exc)) from None
        except SpineInputError as exc:
            root = ctx.find_root()
            if exc.details and root.params.get("verbose"):
                click.echo(exc.details, err=True)
            raise InputError(str(exc)) from None
        except BrokenPipeError:  # the reader left (`spine-mj examples | head`): no error to report
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # the exit's flush too
            raise SystemExit(128 + signal.SIGPIPE) from None
        except OSError as exc:
            where = f": {exc.filename}" if exc.filename is not None else " (the system named no file)"
            raise InputError(f"{exc.strerror or exc}{where}") from None
        except MemoryError as exc:  # the checks at the boundary missed a size: still one line
            raise InputError(
                f"not enough memory for this request ({exc or 'MemoryError'}): a size, resolution or "
                "duration is too large, or a length too small for the surface"
            ) from None
        except (OverflowError, RecursionError) as exc:
            raise InputError(
                f"a value is out of range ({type(exc).__name__}: {exc}); check the parameters given"
            ) from None


class _Root(_Group):
    """The root group: each command's module (and so its dependencies) is imported only when
    that command is named, or listed by ``--help``; the command modules import the library
    inside their functions, so listing them stays light too."""

    #: command name -> the module of :mod:`spine_mj.cli` that registers it on :func:`main`
    lazy_commands: ClassVar[dict[str, str]] = {
        "array": "array",
        "compare-engines": "validate",
        "examples": "examples",
        "hold": "hold",
        "kappa": "theory",
        "replay": "sim",
        "report": "sweep",
        "reproduce": "theory",
        "sim": "sim",
        "simulate": "sim",
        "stickslip": "stickslip",
        "streamline": "theory",
        "surface": "surface",
        "sweep": "sweep",
        "validate": "validate",
        "view": "sim",
    }

    def list_commands(self, ctx):
        return sorted({*self.commands, *self.lazy_commands})

    def get_command(self, ctx, name):
        if name not in self.commands and name in self.lazy_commands:
            importlib.import_module(f"spine_mj.cli.{self.lazy_commands[name]}")
        return self.commands.get(name)


@click.group(cls=_Root, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="spine_mj")
@click.option("-v", "--verbose", is_flag=True, help="Show the full text behind an error (e.g. a reader's).")
def main(verbose):
    """spine_mj: streamline theory and MuJoCo dynamics of bio-inspired spines on rough
    surfaces."""


def run() -> None:
    """The ``spine-mj`` program: :func:`main`, with a SIGTERM (kill, timeout, a scheduler)
    unwinding like Ctrl-C so that temporary outputs are removed. Callers of :func:`main`
    in their own process (tests, notebooks) keep their signal handling.

    A SIGTERM that arrives while a command imports its dependencies can surface as another
    exception (an extension module's ``ImportError: initialization failed`` wraps the
    handler's exit): once the signal came, any exception ends the program as the kill."""
    signal.signal(signal.SIGTERM, _exit_on_sigterm)
    try:
        main()
    except Exception:
        if _TERMINATED:
            raise SystemExit(128 + signal.SIGTERM) from None
        raise


#: Set by :func:`_exit_on_sigterm`: the process was told to stop.
_TERMINATED = []


def _exit_on_sigterm(signum, frame):
    """SIGTERM's handler: exit as a kill would (128 + signal), through every ``finally``."""
    _TERMINATED.append(signum)
    raise SystemExit(128 + signum)


def check_suffix(path: str, suffix: str, option: str) -> None:
    if Path(path).suffix.lower() != suffix:
        raise SpineInputError(f"{option} must name a {suffix} file, got {path!r}")


def parse_start(text: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in text.split(","))
    except ValueError:
        raise SpineInputError(f"--start must look like X,Y (e.g. -3,-1), got {text!r}") from None
    return x, y


def refuse_options_not_for(what: str, params: list[str]) -> None:
    """A :class:`SpineInputError` if any of the current command's ``params`` was given on
    the command line: options that ``what`` would ignore."""
    ctx = click.get_current_context()
    given = [
        opt.opts[0]
        for opt in ctx.command.params
        if opt.name in params and ctx.get_parameter_source(opt.name) is click.core.ParameterSource.COMMANDLINE
    ]
    if given:
        raise SpineInputError(
            f"{what} does not use {', '.join(given)}; leave {'it' if len(given) == 1 else 'them'} out"
        )

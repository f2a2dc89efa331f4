"""The ``ecofmaps`` command: its parser, and the run of one subcommand.

Each subcommand is a module of :mod:`ecofmaps.cli`: ``add(subparsers)`` declares its options,
``run(args)`` works through the public API, importing JAX and the rest only then (``--help`` is
quick). An error in the input is one line and exit status 2, never a traceback.
"""

from __future__ import annotations

import argparse
import difflib
import functools
import gc
import importlib
import os
import re
import signal
import sys
import warnings

from ecofmaps._interrupts import STOP_SIGNALS, interrupts_stop_writes
from ecofmaps._version import __version__


class CommandError(Exception):
    """A user error found after parsing (bad file, bad value): reported in one line."""


#: The subcommands, each a module of :mod:`ecofmaps.cli`, in the order ``--help`` lists them.
_COMMANDS = ("model", "figures", "map", "cache", "loops", "convert", "correct", "explore", "wear")


class _Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one line, like every other error."""

    def error(self, message):
        if message.endswith("expected one argument"):  # or its value is taken for an option
            option = message.removeprefix("argument ").split(":")[0].split("/")[0]
            message += f" (a value that begins with '-' is written {option}=VALUE)"
        self.exit(2, f"ecofmaps: error: {message} (see '{self.prog} --help')\n")


def build_parser() -> argparse.ArgumentParser:
    """The ``ecofmaps`` argument parser with every subcommand."""
    parser = _Parser(
        prog="ecofmaps",
        description="Fretting friction maps: how far the energy CoF drifts from the contact CoF "
        "with rig stiffness and wear-scar shape; the paper's figures; reported ECoFs corrected; "
        "measured loops analysed cycle by cycle. Quantities take units: 50um, 450N, 35MN/m.",
    )
    parser.add_argument("--version", action="version", version=f"ecofmaps {__version__}")
    subparsers = parser.add_subparsers(title="commands", metavar="COMMAND", required=True)
    for name in _COMMANDS:
        module = importlib.import_module(f"ecofmaps.cli.{name}")
        module.add(subparsers)
        command = subparsers.choices[name]
        options = [o for action in command._actions for o in action.option_strings]  # did you mean
        command.set_defaults(handler=module.run, command_prog=command.prog, command_options=options)
    return parser


def _unknown_arguments(unknown, args) -> str:
    """The error line of arguments unknown to the subcommand, with did-you-means."""
    words = [word.split("=")[0] for word in unknown if word.startswith("--")]
    guesses = [difflib.get_close_matches(word, args.command_options, n=1) for word in words]
    hint = "".join(f"; did you mean {guess[0]}?" for guess in guesses if guess)
    hint += f" (see '{args.command_prog} --help')\n"
    return f"ecofmaps: error: unrecognized arguments: {' '.join(unknown)}{hint}"


#: Exit statuses (128 + the signal, as shells report them) of a run stopped by Ctrl-C, by
#: SIGTERM, and once the reader of the output has gone (``| head``).
EXIT_INTERRUPTED, EXIT_TERMINATED, EXIT_BROKEN_PIPE = 130, 143, 141


def main(argv=None) -> int:
    """Run the ``ecofmaps`` command; its exit status: 0, 2 for a user error, 130 or 143 after
    Ctrl-C or SIGTERM (one line on what was left, :func:`ecofmaps._interrupts.add_stop_note`),
    1 for a bug (``ECOFMAPS_DEBUG=1`` shows the traceback). Warnings print one line each."""
    interrupted = status = None
    try:  # the subcommands import JAX and xarray: an interrupt may come during the imports
        with interrupts_stop_writes() as interrupted, warnings.catch_warnings(record=True) as told:
            try:
                parser = build_parser()
                args, unknown = parser.parse_known_args(argv)
                if unknown:
                    parser.exit(2, _unknown_arguments(unknown, args))
            except SystemExit as stop:  # a usage error (printed), --help or --version
                status = int(stop.code or 0)
                return status
            command = getattr(args, "command_prog", "ecofmaps")  # set by every subcommand
            warnings.showwarning = functools.partial(_show_warning, command)
            for warning in told:
                warnings.showwarning(warning.message, warning.category, "", 0)
            status = args.handler(args)
            return status
    except KeyboardInterrupt as stop:  # after the work was done (when leaving), it stops nothing
        return status if status is not None else _stopped(interrupted, getattr(stop, "note", None))
    except BrokenPipeError:  # the reader of standard output has gone: console ends quietly
        raise
    except Exception as error:
        if interrupted is not None and interrupted.is_set():  # an interrupt turned into an error
            return _stopped(interrupted, None)
        if isinstance(error, (CommandError, ValueError, OSError)):  # and what the run left
            left = interrupted.note() if interrupted is not None and interrupted.notes else None
            return _report(2, f"error: {option_names(str(error))}" + (f"; {left}" * bool(left)))
        if isinstance(error, MemoryError):
            return _report(1, "error: not enough memory for this run")
        if os.environ.get("ECOFMAPS_DEBUG"):
            raise
        bug = f"error: unexpected {type(error).__name__}: {error} (a bug: please report it"
        return _report(1, f"{bug}; ECOFMAPS_DEBUG=1 shows the traceback)")


def _stopped(interrupted, note) -> int:
    """Report a stopped run in one line (what was left asked of the notes now); 130 or 143."""
    terminated = interrupted is not None and interrupted.signal == signal.SIGTERM
    words = "terminated (SIGTERM)" if terminated else "interrupted"
    if interrupted is not None and interrupted.notes:
        note = interrupted.note()
    note = note or "no output was left half written"
    return _report(EXIT_TERMINATED if terminated else EXIT_INTERRUPTED, f"{words}; {note}")


def _nothing_to_stop(signum, frame) -> None:
    """A stop signal outside :func:`main`'s block, where there is no work to stop."""


#: The keywords of the Python API that errors of the reading name, and the options giving them.
KEYWORD_OPTIONS = {
    "displacement_column": "--displacement-col",
    "force_column": "--force-col",
    "cycle_column": "--cycle-col",
    "load_column": "--load",
    "displacement_unit": "--displacement-unit",
    "force_unit": "--force-unit",
    "skip_rows": "--skip-rows",
}
_KEYWORD = re.compile(
    rf"(?<![\w./-])({'|'.join(KEYWORD_OPTIONS)})(?:=(\S+))?(?![\w./-])(?: \((--[^()]*)\))?"
)


def option_names(message: str) -> str:
    """An error of the Python API with options for keywords: ``force_column`` (and ``force_column
    (--force-col)``) is ``--force-col``, ``force_unit='foo'`` is ``--force-unit 'foo'``."""

    def option(match) -> str:  # match[3]: the message names the option already
        return match[3] or KEYWORD_OPTIONS[match[1]] + (f" {match[2]}" if match[2] else "")

    return _KEYWORD.sub(option, message)


def _show_warning(command, message, category, filename, lineno, file=None, line=None) -> None:
    """``warnings.showwarning`` as ``<command>: warning: <message>`` on one line."""
    print(f"{command}: warning: {' '.join(str(message).strip().splitlines())}", file=sys.stderr)


def _report(status: int, message: str) -> int:
    """Print ``ecofmaps: <message>`` on standard error; return ``status``."""
    print(f"ecofmaps: {message}", file=sys.stderr)
    return status


def console() -> None:
    """The ``ecofmaps`` console script: exit with :func:`main`'s status; after a stop at once
    (``os._exit``: tearing down around JAX's busy threads can crash); a stop signal once main
    has returned is ignored; a reader that goes (``| head``) ends it quietly."""
    after = [n for n in STOP_SIGNALS if signal.getsignal(n) not in (signal.SIG_IGN, None)]
    for number in after:  # ignored once main has returned; until then main's to handle
        signal.signal(number, _nothing_to_stop)
    try:
        status = main()
        sys.stdout.flush()
    except BrokenPipeError:  # what is still buffered goes nowhere, not into a second error
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        status = EXIT_BROKEN_PIPE
    for number in after:  # the work is done: a signal now stops nothing, not even the exit
        signal.signal(number, signal.SIG_IGN)
    if status in (EXIT_INTERRUPTED, EXIT_TERMINATED):
        gc.collect()  # finalizers first: a process pool's semaphores, else reported as leaked
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
    sys.exit(status)

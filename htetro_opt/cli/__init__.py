"""The ``htetro-opt`` command line: one module per command, each built from the task specs.

Every command takes a SCENARIO, a bundled name (``htetro-opt scenarios`` lists them) or a path to a
scenario TOML file; ``sequence`` also takes a labelled tileset (a bundled name, ``htetro-opt
scenarios`` lists them too, or a file) or a TSPLIB file. A command's ``--method`` choices, its options'
flags, defaults and help, and the "this flag does not apply to that method" errors come from its task's
spec (:mod:`htetro_opt._spec`); nothing here restates them. Errors print one ``error: …`` line and exit
with status 2; Ctrl-C exits with 130 and SIGTERM with 143, one line each (:mod:`htetro_opt._interrupt`).

The console script is :func:`htetro_opt.cli._entry.main`, which installs the signal handling before it
imports this module; this module imports only the standard library, and the commands import their
solvers when they run.
"""

from __future__ import annotations

import json
import os
import signal
import sys
from typing import Sequence

from htetro_opt._interrupt import EXITS, Terminated, exit_now, install, installed, received, say

__all__ = ["main", "main_entry", "build_parser"]

EXIT_ERROR = 2
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as shells report it
EXIT_TERMINATED = 143  # 128 + SIGTERM

COMMANDS = ("scenarios", "plan", "simulate", "tile", "sequence", "study", "cover")
"""The commands, each a module of this package with ``add_parser(sub)`` and ``run(args) -> dict``."""


def build_parser(commands: Sequence[str] = COMMANDS):
    """The parser of these commands (default every one; their options from the task specs)."""
    from importlib import import_module

    from htetro_opt import __version__
    from htetro_opt._argparse import Parser

    parser = Parser(prog="htetro-opt", description="Path planning for the hTetro reconfigurable robot.",
                    epilog="The robot model, the scenario and tileset formats and the JSON output are described in "
                    "docs/model.md and docs/formats.md of the htetro-opt repository. Times are in seconds under the "
                    "default timing. Long work shows progress on stderr when it is a terminal (--quiet: none).")
    parser.add_argument("--version", action="version", version=f"htetro-opt {__version__}")
    sub = parser.add_subparsers(dest="command", parser_class=Parser, metavar="COMMAND")
    for command in commands:
        import_module(f"htetro_opt.cli.{command}").add_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit status (0 success, 2 error, 130 interrupted, 143 terminated)."""
    args = None
    try:
        from importlib import import_module

        from htetro_opt._argparse import UsageError
        from htetro_opt.cli._common import LateOutputError
        from htetro_opt.errors import HtetroError

        given = sys.argv[1:] if argv is None else list(argv)
        # A command named first needs only its own parser (the others import their tasks' specs: 0.03 s)
        parser = build_parser((given[0],) if given and given[0] in COMMANDS else COMMANDS)
        try:
            args = parser.parse_args(given)
            if args.command is None:
                parser.print_help(sys.stderr)
                return EXIT_ERROR
            out = import_module(f"htetro_opt.cli.{args.command}").run(args)
        except (UsageError, HtetroError) as err:
            if received() is not None:  # a signal turned into an error on its way (a solver's wrapper)
                raise
            print("error: " + " ".join(str(err).split()), file=sys.stderr)
            return EXIT_ERROR
        except LateOutputError as late:  # the work is done: its result is not thrown away with the file
            if getattr(args, "json", False):
                print(json.dumps(late.out))
            print("error: " + " ".join(str(late.error).split()), file=sys.stderr)
            return EXIT_ERROR
    except KeyboardInterrupt:
        say("interrupted")
        return EXIT_INTERRUPTED
    except Terminated:
        say("terminated")
        return EXIT_TERMINATED
    except SystemExit as done:  # --help and --version
        return int(done.code or 0)
    except Exception:
        # After a signal, whatever reaches here is its doing: a native module whose import it broke
        # (pybind11 turns the KeyboardInterrupt into "ImportError: initialization failed"), a library that
        # wrapped it. The signal's line and status, not a traceback.
        signum = received()
        if signum is None:
            raise
        code, word = EXITS[signum]
        say(word)
        return code
    if getattr(args, "json", False):
        print(json.dumps(out))
    return 0


def main_entry() -> None:
    """Run the command line as a program: SIGINT and SIGTERM end it with one line and 130 or 143, without a
    traceback and without the interpreter's teardown (:mod:`htetro_opt._interrupt`; installed here too when
    the console script, :mod:`htetro_opt.cli._entry`, has not already)."""
    try:
        install()
        code = main()
        sys.stdout.flush()
    except BrokenPipeError:  # output piped into e.g. `head`, which closed it: not an error of ours
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        code = 1
    except (KeyboardInterrupt, Terminated) as signalled:  # raised after main's own handlers (printing its output)
        code, word = EXITS[signal.SIGINT if isinstance(signalled, KeyboardInterrupt) else signal.SIGTERM]
        say(word)
    if installed():
        if code in (EXIT_INTERRUPTED, EXIT_TERMINATED):
            exit_now(code)  # the finally blocks have run: skip the teardown, seconds on a busy machine
        for signum in (signal.SIGINT, signal.SIGTERM):  # the work and its output are done: a signal in the
            if signal.getsignal(signum) != signal.SIG_IGN:  # teardown ends it plainly, no exception raised
                signal.signal(signum, signal.SIG_DFL)  # in the middle of the interpreter's finalisation
    sys.exit(code)

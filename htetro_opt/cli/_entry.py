"""The ``htetro-opt`` console script: SIGINT and SIGTERM handled first, then the command line imported.

Importing the command's solvers (numpy, scipy, numba, pymoo, OR-Tools) takes seconds on a busy machine;
a signal in that time must end the command like one during its work, with one line and 130 or 143, not a
traceback from inside an import (SIGINT) or nothing at all (SIGTERM). So this module imports nothing but
:mod:`htetro_opt._interrupt` (the standard library) before it installs the handling.
"""

from __future__ import annotations

__all__ = ["main"]


def main() -> None:
    """Install the process-wide signal handling (:func:`htetro_opt._interrupt.install`), then run the
    command line (:func:`htetro_opt.cli.main_entry`)."""
    import signal

    from htetro_opt._interrupt import EXITS, Terminated, exit_now, install, say

    try:
        install()
        from htetro_opt.cli import main_entry
    except (KeyboardInterrupt, Terminated) as signalled:  # while the handling or the command line loads
        code, word = EXITS[signal.SIGINT if isinstance(signalled, KeyboardInterrupt) else signal.SIGTERM]
        say(word)
        exit_now(code)
    main_entry()

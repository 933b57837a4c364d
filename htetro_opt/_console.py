"""Progress on stderr for the command line: one tqdm bar per step of a command.

A step either reports its own progress through the callable it is given (GA generations, greedy
iterations, OR-Tools' seconds; see :mod:`htetro_opt._progress`) or just shows that it is still
running: a helper thread refreshes every bar twice a second, so the elapsed time moves even while a
solver is inside C++. Nothing is drawn when stderr is not a terminal or with ``--quiet``; the bars
disappear when their step ends, so the terminal keeps only the command's own output.
"""

from __future__ import annotations

import sys
import threading
from contextlib import contextmanager
from typing import Iterator

__all__ = ["Console"]

_UNKNOWN_TOTAL = "{desc}: {elapsed}{postfix}"
_KNOWN_TOTAL = "{desc}: {percentage:3.0f}%|{bar:20}| {n_fmt}/{total_fmt} {unit} [{elapsed}<{remaining}]{postfix}"


class Console:
    """Progress bars on ``stream`` (stderr) when ``enabled``.

    Examples
    --------
    >>> console = Console(enabled=False)
    >>> with console.step("tiling") as progress:
    ...     progress(1, 2, "half way")  # does nothing when disabled
    """

    def __init__(self, *, enabled: bool, stream=None) -> None:
        self.enabled = enabled
        self.stream = stream if stream is not None else sys.stderr

    @contextmanager
    def step(self, label: str, total: float | None = None, unit: str = "") -> Iterator:
        """A bar for one step; yields the ``progress(done, total, note)`` callable to give the solver."""
        if not self.enabled:
            yield _silent
            return
        from tqdm import tqdm

        bar = tqdm(total=total, desc=label, unit=unit, file=self.stream, leave=False, dynamic_ncols=True,
                   bar_format=_KNOWN_TOTAL if total else _UNKNOWN_TOTAL, mininterval=0.2)
        lock = threading.Lock()

        def progress(done: float, step_total: float | None = None, note: str = "") -> None:
            with lock:
                if step_total is not None and step_total != bar.total:
                    bar.total = step_total
                    bar.bar_format = _KNOWN_TOTAL if step_total else _UNKNOWN_TOTAL
                bar.n = done
                if note:
                    bar.set_postfix_str(note, refresh=False)
                bar.refresh()

        stop = threading.Event()

        def tick() -> None:  # keeps the elapsed time moving while the solver does not report
            while not stop.wait(0.5):
                with lock:
                    bar.refresh()

        ticker = threading.Thread(target=tick, name="htetro-progress", daemon=True)
        ticker.start()
        try:
            yield progress
        finally:
            stop.set()
            ticker.join(timeout=1.0)
            bar.close()


def _silent(done: float, total: float | None = None, note: str = "") -> None:
    """The progress callable of a disabled console."""

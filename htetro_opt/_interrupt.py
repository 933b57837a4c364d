"""Ctrl-C and SIGTERM: the command line's process-wide handling, and native solvers stopped at once.

**The command line** (:func:`install`, called by its entry point :mod:`htetro_opt.cli._entry` before
anything heavy is imported): SIGINT raises ``KeyboardInterrupt`` and SIGTERM :class:`Terminated` in
the main thread, so that ``finally`` blocks (temporary files, a study's workers) run, and the command
prints one line and exits 130 or 143 without the interpreter's slow teardown (:func:`exit_now`;
measured 0.3-2.4 s with numba, scipy and matplotlib loaded on a busy machine). Python runs a signal
handler only between bytecodes of the main thread, which a compiled loop or a long numpy call does
not reach for seconds: a helper thread, woken through ``signal.set_wakeup_fd`` (written by Python's
C-level handler whatever the main thread is doing), sets the flag the compiled loops poll
(:func:`kernel_flag`), and if the process is still there :data:`GRACE` seconds later (a C call that
polls nothing), or at a second signal, prints the line, removes the temporary files registered with
:func:`removed_on_exit` and ends the process itself (``os._exit``).

**Native solvers** (:func:`on_signal`): OR-Tools' routing search and CP-SAT run in C++ without
returning to the interpreter, so a signal that arrives during a solve is handled by Python only when
the solve has used up its whole budget (measured: 9.5 s of waiting for a 10 s OR-Tools run). Within
:func:`on_signal`, SIGINT and SIGTERM are only recorded, and a helper thread woken through the wakeup fd
calls ``stop`` (e.g. CP-SAT's ``stop_search``) and sets an event that a search callback can poll
(OR-Tools routing's ``FinishCurrentSearch`` may only be called from inside the search). When the block
ends, the recorded signal goes to the handler that was there before (``KeyboardInterrupt``, or the
command line's :class:`Terminated`), raised in ordinary Python code rather than inside a solver's
callback, where it would be lost.

Written here: neither OR-Tools, CP-SAT nor numba offers this from Python, and ``signal`` gives the
pieces. This module imports only the standard library (numpy when :func:`kernel_flag` is first called).
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from contextlib import contextmanager
from typing import Callable, Iterator

__all__ = ["EXITS", "GRACE", "Terminated", "exit_now", "install", "installed", "kernel_flag", "on_signal",
           "received", "release", "removed_on_exit", "say"]

_SIGNALS = (signal.SIGINT, signal.SIGTERM)

EXITS = {signal.SIGINT: (130, "interrupted"), signal.SIGTERM: (143, "terminated")}
"""Exit status (128 + the signal's number, as shells report it) and the one line of each signal."""

GRACE = 1.0
"""Seconds between the first signal and the helper thread ending the process itself, when the main thread
has not ended it by then (stuck in a C call that polls nothing)."""


class Terminated(BaseException):
    """SIGTERM, turned into an exception (like ``KeyboardInterrupt`` for SIGINT) so that ``finally`` blocks
    run; a ``BaseException``, so that no ``except Exception`` of a trial or a library swallows it."""


# --- the command line's process-wide handling --------------------------------------------------------
_lock = threading.Lock()
_installed = False
_first: int | None = None  # the first signal received
_seen = 0  # signals the helper threads have read
_raised = False  # the Python-level handler has raised the first signal's exception
_said = False  # the one line has been printed
_flag = None  # the compiled loops' stop flag (numpy, created on first use)
_temporaries: set[str] = set()


def installed() -> bool:
    """Whether :func:`install` has been called in this process (the command line's entry point)."""
    return _installed


def received() -> int | None:
    """The first signal received under :func:`install` (SIGINT or SIGTERM), None if none (or not installed)."""
    return _first if _installed else None


def install() -> None:
    """Handle SIGINT and SIGTERM for the whole process, as the command line does (module docstring).

    Called by the console script first thing, before the command line and its solvers are imported. A
    signal the process was started with ignored (``nohup``, a background job) stays ignored. Main thread only.
    """
    global _installed
    if _installed or threading.current_thread() is not threading.main_thread():
        return
    watched = [s for s in _SIGNALS if signal.getsignal(s) != signal.SIG_IGN]
    for signum in watched:  # first: the rest of this function and every import after it are covered
        signal.signal(signum, _raise)
    _installed = True
    reader, writer = _wakeup_pair()
    signal.set_wakeup_fd(writer, warn_on_full_buffer=False)
    threading.Thread(target=_watch, args=(reader, watched), name="htetro-signal-exit", daemon=True).start()


def release() -> None:
    """Forget :func:`install` in this process: a study's worker forked from the command line, whose own
    signals are its parent's business (:func:`htetro_opt.studies._execution._die_with`)."""
    global _installed
    _installed = False
    if threading.current_thread() is threading.main_thread():
        signal.set_wakeup_fd(-1)


def _wakeup_pair() -> tuple[Callable[[], bytes], int]:
    """(read some bytes, blocking; the write end's fd, non-blocking) for ``signal.set_wakeup_fd``."""
    if os.name == "posix":
        reader, writer = os.pipe()
        os.set_blocking(writer, False)
        return (lambda: os.read(reader, 64)), writer
    import socket  # Windows: the wakeup fd must be a socket

    a, b = socket.socketpair()
    b.setblocking(False)
    _wakeup_pair.keep = (a, b)  # type: ignore[attr-defined] -- alive for the process
    return (lambda: a.recv(64)), b.fileno()


def _watch(read: Callable[[], bytes], watched) -> None:
    numbers = {int(s) for s in watched}
    while True:
        try:
            data = read()
        except OSError:
            return
        for byte in data:
            if byte in numbers:
                _notify(byte)


def _raise(signum, frame) -> None:
    """The Python-level handler (main thread): the first signal becomes an exception; later ones are left
    to the helper thread, which ends the process at once."""
    global _first, _raised
    with _lock:
        if _first is None:
            _first = signum
        again, _raised = _raised, True
    if _flag is not None:
        _flag[0] = 1
    if not again:
        if _in_native_callback(frame):
            # An exception raised here would be swallowed by ctypes ("Exception ignored on calling ctypes
            # callback function", a traceback on stderr) and the signal lost until GRACE ends the process:
            # end it now, as at a second signal.
            _end()
        raise KeyboardInterrupt if signum == signal.SIGINT else Terminated()


def _in_native_callback(frame) -> bool:
    """Whether ``frame`` runs inside llvmlite, whose Python callbacks (numba's object cache, called by LLVM
    through ctypes while a kernel is compiled or loaded) cannot pass an exception on to their caller."""
    while frame is not None:
        if frame.f_globals.get("__name__", "").startswith("llvmlite"):
            return True
        frame = frame.f_back
    return False


def _notify(signum: int) -> None:
    """A helper thread read ``signum``: set the compiled loops' flag; at the first signal, end the process in
    :data:`GRACE` seconds unless the main thread has by then; at a second, end it now. Nothing outside the
    command line (:func:`install` not called)."""
    global _first, _seen
    if not _installed:
        return
    with _lock:
        _seen += 1
        seen = _seen
        if _first is None:
            _first = signum
    if _flag is not None:
        _flag[0] = 1
    if seen == 1:
        timer = threading.Timer(GRACE, _end)
        timer.daemon = True
        timer.start()
    else:
        _end()


def _end() -> None:
    """End the process from a helper thread: the line, the temporary files removed, the signal's status."""
    code, word = EXITS.get(_first, EXITS[signal.SIGINT])
    say(word)
    for path in list(_temporaries):
        try:
            os.unlink(path)
        except OSError:  # already renamed into place or removed: nothing half-written is left either way
            pass
    os._exit(code)


def say(word: str) -> None:
    """Print the signal's one line on stderr; once a process under :func:`install` (the main thread and a
    helper thread may both get there)."""
    global _said
    if _installed:
        with _lock:
            if _said:
                return
            _said = True
    try:
        print(word, file=sys.stderr, flush=True)
    except (OSError, ValueError):  # stderr closed or its pipe gone: the status still says it
        pass


def exit_now(code: int) -> None:
    """End the process with ``code`` after an interrupt, once its ``finally`` blocks have run: stdout and
    stderr flushed, but without the interpreter's teardown (seconds on a busy machine)."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed stream or a gone pipe: the exit status still says why
            pass
    os._exit(code)


def kernel_flag():
    """The stop flag the compiled loops poll: a one-element ``uint8`` numpy array, set to 1 when SIGINT or
    SIGTERM reaches a process under :func:`install` (the command line) and never otherwise, so that a loop
    that polls it stops within moments and its caller, back in Python, raises the signal's exception.

    Pass it to the kernel as an argument (numba freezes a global array into the compiled code).

    Examples
    --------
    >>> kernel_flag().tolist()
    [0]
    """
    global _flag
    if _flag is None:
        import numpy as np

        flag = np.zeros(1, dtype=np.uint8)
        with _lock:
            if _flag is None:
                _flag = flag
                if _first is not None and _installed:
                    _flag[0] = 1
    return _flag


@contextmanager
def removed_on_exit(path: str | os.PathLike) -> Iterator[None]:
    """Within the block, a process ended by the helper thread (:func:`_end`) removes ``path`` first (a
    temporary file being written); the block's own cleanup handles every other way out."""
    path = os.fspath(path)
    _temporaries.add(path)
    try:
        yield
    finally:
        _temporaries.discard(path)


# --- native solvers ----------------------------------------------------------------------------------


@contextmanager
def on_signal(stop: Callable[[], None] | None = None) -> Iterator[threading.Event]:
    """Within the block, a SIGINT or SIGTERM calls ``stop()`` (from a helper thread) and sets the
    event; the signal is delivered to its usual handler when the block ends.

    Outside the main thread (where Python handles no signals) it only yields an event that stays
    clear.

    Examples
    --------
    >>> with on_signal() as interrupted:
    ...     pass
    >>> interrupted.is_set()
    False
    """
    interrupted = threading.Event()
    if threading.current_thread() is not threading.main_thread():
        yield interrupted
        return
    recorded: list[int] = []

    def record(signum, frame) -> None:
        recorded.append(signum)
        interrupted.set()

    import socket

    reader, writer = socket.socketpair()
    writer.setblocking(False)
    previous_fd = signal.set_wakeup_fd(writer.fileno(), warn_on_full_buffer=False)
    # a signal the process ignores (SIGINT in a background job) stays ignored
    watched = [signum for signum in _SIGNALS if signal.getsignal(signum) != signal.SIG_IGN]
    previous = {signum: signal.signal(signum, record) for signum in watched}
    numbers = {int(signum) for signum in watched}

    def watch() -> None:
        while True:
            try:
                data = reader.recv(64)
            except OSError:
                return
            if not data:  # the writer was closed: the block has ended
                return
            hits = [byte for byte in data if byte in numbers]
            if hits:
                interrupted.set()
                if stop is not None:
                    stop()
            for signum in hits:
                _notify(signum)  # the command line's flag and deadline (nothing outside it)

    watcher = threading.Thread(target=watch, name="htetro-signal-watch", daemon=True)
    watcher.start()
    try:
        yield interrupted
    finally:
        signal.set_wakeup_fd(previous_fd)
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        writer.close()
        watcher.join(timeout=1.0)
        reader.close()
    if recorded:
        _deliver(recorded[0], previous[recorded[0]])


def _deliver(signum: int, handler) -> None:
    """Hand a recorded signal to the handler that was installed before the block."""
    if callable(handler):
        handler(signum, None)
    elif handler == signal.SIG_DFL:
        signal.raise_signal(signum)

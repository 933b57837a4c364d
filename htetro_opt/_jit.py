"""numba, a core dependency: the one place that imports it, and compiling a hot loop on its first call.

numba is a core dependency, but importing it costs about half a second: the model, the problems
and the operators are imported by every command of the CLI and by the tiler, which mostly never run
these loops. A loop wrapped by :func:`lazy_jit` is compiled (``cache=True``: later processes load it
from numba's on-disk cache) the first time it is called. The modules made of compiled kernels
(``ils``'s, the tiler's sweep), imported only when they run, take numba from :func:`require_numba`
when they are imported. There is no pure-Python fallback: without numba these raise a
:class:`~htetro_opt.errors.DependencyError` that says how to install it. (The exact planner runs its first
expansions by a kernel's ``.interpreted``, the same code in the interpreter, because importing numba and
loading a kernel costs more than a small search: a 24 x 24 map's plan then never imports numba; a longer
search is handed over to the compiled kernel, and needs numba.)

A first compile (a fresh install, or after an upgrade) takes seconds; :func:`on_compile` lets the command
line say so, once, rather than seem to hang.
"""

from __future__ import annotations

import functools
import os
import types

from htetro_opt.errors import DependencyError

__all__ = ["announce_compile", "kernels", "lazy_jit", "on_compile", "require_numba"]

_dispatched: list = []  # the numba functions lazy_jit has made in this process (for kernels())
_notice = None  # the command line's: says once that kernels are being compiled (display only, never results)


def require_numba():
    """The ``numba`` module, or a clear error: numba is a core dependency.

    Returns
    -------
    module
        ``numba``.

    Raises
    ------
    DependencyError
        If numba cannot be imported (not installed, or broken): an ``ImportError`` too, naming the
        install command.

    Examples
    --------
    >>> require_numba().__name__
    'numba'
    """
    try:
        import numba
    except ImportError as err:
        raise DependencyError(
            "numba is a core dependency of htetro-opt (it compiles the sequencing local search, the "
            "tiler's sweep and the simulator's and operators' hot loops), and it cannot be imported "
            f"({err}): install it with pip install 'numba>=0.59', or reinstall htetro-opt",
            name="numba") from err
    return numba


def _njit(function):
    return require_numba().njit(cache=True, nogil=True)(function)


def on_compile(notice) -> None:
    """Have ``notice(text)`` called, once, when a kernel is about to be compiled rather than loaded from numba's
    on-disk cache (None: say nothing, the library's default)."""
    global _notice
    _notice = notice


def announce_compile(dispatcher) -> None:
    """Call the :func:`on_compile` notice if ``dispatcher`` (a numba function) has nothing in the on-disk cache
    yet: its first call compiles. Reads numba's cache index (a private attribute: where it is missing, nothing
    is said)."""
    global _notice
    if _notice is None:
        return
    try:
        cached = os.path.exists(dispatcher._cache._cache_file._index_path)
    except AttributeError:
        return
    if not cached:
        notice, _notice = _notice, None  # once a process
        notice("compiling the numerical kernels on their first use (seconds, once: numba keeps them on disk for "
               "the next runs)")


def kernels() -> list:
    """Every numba function of htetro-opt made in this process so far: those :func:`lazy_jit` compiled or loaded,
    the functions they call, and those of the kernel modules imported (each has ``stats.cache_hits`` and
    ``stats.cache_misses``: loads from numba's on-disk cache and compiles, per signature)."""
    import sys

    if "numba" not in sys.modules:
        return []
    dispatcher = require_numba().core.registry.CPUDispatcher
    found = {id(d): d for d in _dispatched}
    for name, module in list(sys.modules.items()):
        if name.startswith("htetro_opt") and module is not None:
            found.update((id(v), v) for v in vars(module).values() if isinstance(v, dispatcher))
    return list(found.values())


def lazy_jit(function=None, *, calls: tuple[str, ...] = ()):
    """``function`` compiled by numba on its first call.

    Parameters
    ----------
    function : callable
        A function defined at module level in a file (numba's cache needs the file) that numba can
        compile in nopython mode.
    calls : tuple of str
        Names of other module-level functions that ``function`` calls: numba resolves them from
        the module's globals when it compiles, so they are compiled first and rebound there.

    Returns
    -------
    callable
        ``function``, compiled at its first call; ``.py_func`` is ``function`` itself,
        ``.interpreted(*args)`` runs it (and the functions of ``calls``) in the interpreter, never
        importing numba, and ``.loaded()`` says whether it has been compiled (or loaded from the cache)
        in this process. Importing numba and loading a kernel from its cache costs about 0.3 s, more than
        a small search takes in the interpreter: a caller may run a short job by ``.interpreted`` and
        hand a long one over to the compiled kernel (the same code, so the same results).

    Examples
    --------
    The shortcut's loop search is wrapped at import and compiled when it first runs:

    >>> import numpy as np
    >>> from htetro_opt.operators.commands.shortcut import _longest_loops, longest_loops
    >>> _longest_loops.py_func.__name__
    '_longest_loops'
    >>> [v.tolist() for v in longest_loops(np.array([[0, 1, 2, 1, 3]]), np.array([4]))]
    [[1], [3]]
    """
    if function is None:
        return functools.partial(lazy_jit, calls=calls)
    compiled = None
    python = None

    @functools.wraps(function)
    def call(*args):
        nonlocal compiled
        if compiled is None:
            dispatcher = require_numba().core.registry.CPUDispatcher
            for name in calls:
                if not isinstance(function.__globals__[name], dispatcher):  # shared by two kernels: compiled once
                    function.__globals__[name] = _njit(function.__globals__[name])
            compiled = _njit(function)
            _dispatched.append(compiled)
            announce_compile(compiled)
        return compiled(*args)

    def interpreted(*args):
        nonlocal python
        if python is None:  # the module is whole by now: its constants are all defined
            scope = dict(function.__globals__)
            for name in calls:  # the Python versions, also once numba has rebound the module's names
                scope[name] = getattr(scope[name], "py_func", scope[name])
            python = types.FunctionType(function.__code__, scope, function.__name__, function.__defaults__,
                                        function.__closure__)
        return python(*args)

    call.py_func = function  # the Python version, for tests that compare the two
    call.interpreted = interpreted
    call.loaded = lambda: compiled is not None
    return call

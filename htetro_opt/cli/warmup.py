"""Compile ahead: ``python -m htetro_opt.cli.warmup [plan] [sequence]`` fills the on-disk caches once, after an
install or an upgrade, so that no later command compiles.

htetro-opt's hot loops are numba kernels compiled on their first call and kept on disk by numba
(``cache=True``: ``__pycache__`` beside the source, or numba's per-user folder when that is not writable;
``NUMBA_CACHE_DIR`` moves it), and the model's swept-cell tables are kept in htetro-opt's own cache
(:mod:`htetro_opt._cache`). Without a warm-up each kernel compiles, once, the first time a command needs
it, and the command line says so on a terminal ("compiling the numerical kernels on their first use");
the warm-up does the same work ahead, by running small jobs of the commands through the command line:

- ``plan``: the exact planner's two compiled searches (the bucket queue and the float heap: a plan with
  and one without diagonal moves, run compiled rather than in the interpreter) and a short hTetro-GA run
  (the simulator's and the operators' kernels);
- ``sequence``: the compiled iterated local search of the sequencing task (``--method ils``; the longest
  compile, some 10 s), with both kinds of neighbour lists, on a tileset and on a TSPLIB file.

It prints how many kernels it compiled and how many it loaded from numba's cache: a second warm-up (or
any later process) compiles none. A small exact plan (a 24 x 24 map) needs none of them: its search runs
in the interpreter while that is cheaper than starting numba
(:data:`~htetro_opt.solvers.grid_paths._lazy._INTERPRETED`).
The tiler's compiled sweep (large maps only) compiles at its first use.
"""

from __future__ import annotations

import contextlib
import io
import sys
import tempfile
from pathlib import Path

__all__ = ["JOBS", "warm_up"]

_TSPLIB = "<a 12-city TSPLIB file>"
_WARMUP_TSP = ("NAME : warmup12\nTYPE : TSP\nDIMENSION : 12\nEDGE_WEIGHT_TYPE : EUC_2D\nNODE_COORD_SECTION\n"
               + "".join(f"{i + 1} {i * 37 % 11 * 10} {i * 53 % 7 * 10}\n" for i in range(12)) + "EOF\n")

JOBS = {
    "plan": (["plan", "three_slit", "--json"], ["plan", "three_slit", "--diagonals", "--json"],
             ["plan", "three_slit", "--method", "htetro-ga", "--pop-size", "8", "--max-gen", "2", "--json"]),
    "sequence": (["sequence", "tiling_11x11", "--method", "ils", "--json"],
                 ["sequence", "tiling_11x11", "--method", "ils", "--candidates", "alpha", "--json"],
                 ["sequence", _TSPLIB, "--method", "ils", "--json"]),
}
"""Each part of the warm-up: the command lines it runs (small, fixed: seconds once kernels are cached;
``_TSPLIB`` stands for a 12-city TSPLIB file the warm-up writes to a temporary folder, so that the kernels
of TSPLIB coordinate instances, costs computed from the coordinates, compile too)."""


def warm_up(parts=tuple(JOBS), *, say=None) -> dict[str, int]:
    """Run the jobs of ``parts`` (keys of :data:`JOBS`) and fill the caches.

    Parameters
    ----------
    parts : sequence of str
    say : callable, optional
        Called with a line of text per job (None: silent).

    Returns
    -------
    dict
        ``{"compiled": n, "loaded": m}``: the kernel signatures compiled in this process and those loaded
        from numba's on-disk cache.

    Raises
    ------
    ParameterError
        If a part is not a key of :data:`JOBS`.
    """
    from htetro_opt._jit import kernels
    from htetro_opt.cli import main
    from htetro_opt.errors import HtetroError, ParameterError
    from htetro_opt.model import sweep_tables
    from htetro_opt.solvers.grid_paths import _lazy

    unknown = [p for p in parts if p not in JOBS]
    if unknown:
        raise ParameterError(f"unknown warm-up part(s) {', '.join(map(repr, unknown))}: expected some of "
                             f"{', '.join(JOBS)}")
    sweep_tables(0.0)
    left, _lazy._interpreted_left = _lazy._interpreted_left, 0  # the compiled searches, not the interpreter's
    try:
        with tempfile.TemporaryDirectory() as folder:  # the TSPLIB job's file, gone with the folder
            tsplib = Path(folder) / "warmup12.tsp"
            tsplib.write_text(_WARMUP_TSP)
            for part in parts:
                for args in JOBS[part]:
                    args = [str(tsplib) if a == _TSPLIB else a for a in args]
                    with contextlib.redirect_stdout(io.StringIO()):
                        code = main(args)
                    if code != 0:
                        raise HtetroError(f"the warm-up job 'htetro-opt {' '.join(args)}' failed (exit status "
                                          f"{code})")
                    if say is not None:
                        say(f"htetro-opt {' '.join(args)}: done")
    finally:
        _lazy._interpreted_left = left
    compiled = loaded = 0
    for kernel in kernels():
        compiled += sum(kernel.stats.cache_misses.values())
        loaded += sum(kernel.stats.cache_hits.values())
    return {"compiled": compiled, "loaded": loaded}


def _main(argv: list[str]) -> int:
    from htetro_opt._jit import on_compile
    from htetro_opt.errors import HtetroError

    on_compile(lambda text: print(text, file=sys.stderr, flush=True))
    try:
        counts = warm_up(argv or tuple(JOBS), say=lambda text: print(text, file=sys.stderr, flush=True))
    except HtetroError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    print(f"kernels: {counts['compiled']} compiled, {counts['loaded']} loaded from numba's on-disk cache")
    return 0


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1:]))

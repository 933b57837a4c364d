"""Lazy package attributes (PEP 562), so that importing one subpackage does not import its siblings'
heavy dependencies: ``import htetro_opt.solvers.tiling`` must not pull in pymoo or DEAP through
``htetro_opt.solvers``'s ``__init__``.

Written here rather than taken from ``lazy_loader``: the whole need is the dozen lines below.
"""

from __future__ import annotations

from importlib import import_module
from typing import Callable, Mapping

__all__ = ["attach"]


def attach(package: str, exports: Mapping[str, str]) -> tuple[Callable, Callable, list[str]]:
    """``(__getattr__, __dir__, __all__)`` for a package whose names live in submodules.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    exports : mapping of str to str
        Public name → submodule (relative to ``package``, e.g. ``"._exact"``, or absolute, for a name
        defined in a lower layer and re-exported) that defines it.

    Examples
    --------
    >>> getattr_, dir_, names = attach("htetro_opt", {"HtetroError": ".errors"})
    >>> getattr_("HtetroError").__name__, names
    ('HtetroError', ['HtetroError'])
    """
    exports = dict(exports)

    def __getattr__(name: str):
        if name not in exports:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        return getattr(import_module(exports[name], package), name)

    def __dir__() -> list[str]:
        return sorted(exports)

    return __getattr__, __dir__, list(exports)

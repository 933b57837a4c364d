"""What a task is, declared once: its methods, each method's options, defaults and capabilities.

Each of htetro-opt's five tasks (grid paths, continuous paths, tiling, sequencing, coverage) has one
:class:`TaskSpec`, in ``htetro_opt/solvers/<task>/_spec.py``. Everything that asks what a task is reads
it, and nothing restates it:

- the task's entry point (``plan_path``, ``plan_continuous``, ``tile_workspace``,
  ``sequence_waypoints``, ``plan_coverage``) resolves ``method=`` and checks the options with it, before
  any work: an unknown option is a :class:`~htetro_opt.errors.ParameterError` naming the method's options;
- the command line builds its flags, choices, defaults and help from it, and refuses a flag that the
  chosen method does not take;
- the study runner checks a study file's keys with it, runs a method once or once per seed by its
  :attr:`Method.seeded` capability, takes the exact reference from :attr:`TaskSpec.exact`, and keys a
  record's code by :meth:`TaskSpec.fingerprint`.

Adding a method is one :class:`Method` in its task's spec (or :meth:`TaskSpec.register` at run time);
adding an option is one :class:`Option` and its name in the methods that take it.

Importing a spec imports nothing heavy (no pymoo, numba, OR-Tools, scikit-fem, matplotlib): a method's
function is named ``"module:function"`` and imported when the method runs.

**Seeds** mean one thing everywhere: ``seed=None`` draws fresh entropy, an int or a
``numpy.random.Generator`` reproduces a run. Every stochastic method's default is :data:`DEFAULT_SEED`
(0): a run is reproducible unless asked otherwise.
"""

from __future__ import annotations

import hashlib
import json
import numbers
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from importlib import import_module
from typing import Any

from htetro_opt._validation import check_int, check_real, check_seed
from htetro_opt.errors import ParameterError

__all__ = ["DEFAULT_SEED", "ORIGINS", "Method", "Option", "Problem", "TaskSpec", "additions", "at_most", "bytes_text",
           "callback", "choice", "duration_text", "integer", "real", "seed_option", "unchecked"]

DEFAULT_SEED = 0
"""The seed of every stochastic method when none is given: the same call gives the same result."""

ORIGINS = {
    "paper": "the paper's algorithm as published",
    "ours": "the paper's algorithm with additions of ours, or a method of ours",
    "baseline": "a baseline the paper compares with",
    "reference": "an exact reference of ours",
    "library": "another library's algorithm on the same problem",
    "external": "an outside solver",
}
"""What a method is, by :attr:`Method.origin`."""

_STAGES = ("method", "problem")


@dataclass(frozen=True)
class Option:
    """One option of a task: its check, default, command-line flag and help, declared once.

    Parameters
    ----------
    name : str
        The keyword in the library and the key in a study file.
    check : callable
        ``check(value, name) -> value``: the value in its canonical type, or a
        :class:`~htetro_opt.errors.ParameterError` naming ``name`` (the keyword, the flag or the study
        key, whichever the user wrote). It also accepts the command line's text where the value is not
        a plain number (``"1,0,0"`` for weights).
    help : str
        One sentence for ``--help`` and the docs, without the default (added from :attr:`default`).
    default : object
        The value when the option is not given; a method may override it (:attr:`Method.defaults`).
        None where the default is not a value (sized to the instance, the algorithm's own): then
        :attr:`default_text` says what it is.
    flag : str, optional
        The command-line flag; by default ``--`` and the name with dashes; ``""``: not on the command
        line (a library-only option such as a callback).
    type : callable
        argparse's conversion of the flag's text (``int``, ``float``, ``str``); ``bool``: a switch.
    choices : tuple of str, optional
        The allowed values, for argparse and the help.
    metavar : str, optional
    default_text : str, optional
        The default in words, where it is not a value.
    study : bool
        Whether a study file may set it (False for callbacks and for ``seed``, which the study's
        ``seeds`` give).
    reference : bool
        The option defines the problem, so the task's exact reference shares it (a plan's clearance,
        a sequence's start).
    stage : {"method", "problem"}
        ``"method"``: a keyword of the task's entry point; ``"problem"``: how a scenario is posed as the
        entry point's data (:meth:`TaskSpec.pose`: a sequence's start tile, a cover's morphology layers).
    off_flag : str, optional
        A switch's flag that sets the option to False (``--no-monotone``, ``--open``); a switch whose
        :attr:`flag` is ``""`` has only this one.
    """

    name: str
    check: Callable[[Any, str], Any]
    help: str
    default: Any = None
    flag: str | None = None
    type: Callable = str
    choices: tuple[str, ...] | None = None
    metavar: str | None = None
    default_text: str | None = None
    study: bool = True
    reference: bool = False
    stage: str = "method"
    off_flag: str | None = None

    def __post_init__(self) -> None:
        if self.stage not in _STAGES:
            raise ValueError(f"option {self.name!r}: stage must be one of {_STAGES}, got {self.stage!r}")
        if self.flag is None:
            object.__setattr__(self, "flag", "--" + self.name.replace("_", "-"))

    @property
    def switch(self) -> bool:
        """A command-line switch (no value)."""
        return self.type is bool

    @property
    def flags(self) -> tuple[str, ...]:
        """Every command-line flag of the option (a switch may have two)."""
        return tuple(f for f in (self.flag, self.off_flag) if f)


@dataclass(frozen=True)
class Method:
    """One method of a task: what it runs, the options it takes and what it is.

    Parameters
    ----------
    name : str
        The ``method=`` name (and ``--method`` choice).
    function : str, callable or None
        What runs: ``"module:attribute"`` (a module relative to the task's package, e.g.
        ``"._exact:plan_exact"``), imported when the method first runs, or the callable itself; None for a
        method the entry point runs itself (a tiling algorithm, sequencing's ``auto``). What it is called
        with is the entry point's business (each entry point documents it).
    summary : str
        One line for ``--method``'s help and the docs.
    options : tuple of str
        The task options it takes (:attr:`TaskSpec.options` names).
    defaults : mapping, optional
        Its own defaults where they differ from the options' (``replan_window`` 0 as published).
    presets : mapping, optional
        Fixed keywords for ``function``, not options of the user's (``algorithm="nsga2"``).
    seeded : bool or callable
        Whether its result can change with the seed: True, False, or ``seeded(options)`` for a method
        that draws only under some option (a tiling only with ``shuffle``). A study runs a seeded
        method once per seed and the others once.
    exact : bool
        It proves an optimum (the task's :attr:`TaskSpec.exact` is one of these).
    origin : str
        One of :data:`ORIGINS`: ``"paper"`` for the paper's algorithm as published, ``"ours"``,
        ``"baseline"``, ``"reference"``, ``"library"``, ``"external"``.
    paper : str, optional
        The paper it comes from, by authors and year ("Cheng et al. 2020").
    family : tuple of str
        Names of the method groups it belongs to (:attr:`TaskSpec.families`), for messages such as
        "pop_size applies to the GA methods (…) only".
    capabilities : frozenset of str
        Task-specific capabilities (sequencing: ``"asymmetric"``, ``"tours"``, ``"geometry"``,
        ``"implicit"``, ``"timed"`` (it ends on its time budget only); tasks that report progress:
        ``"progress"``).
    problem : mapping, optional
        Option values the method's problem always has, for the exact reference (the heat planner
        always plans with the diagonals).
    requires : str, optional
        The optional package it needs (its extra), named when it is missing.
    revision : int
        Bump when the method's results change for the same options: a study's ``resume`` then re-runs
        its records (:meth:`TaskSpec.fingerprint`).
    """

    name: str
    function: str | Callable | None
    summary: str
    options: tuple[str, ...] = ()
    defaults: Mapping[str, Any] = field(default_factory=dict)
    presets: Mapping[str, Any] = field(default_factory=dict)
    seeded: bool | Callable[[Mapping[str, Any]], bool] = False
    exact: bool = False
    origin: str = "ours"
    paper: str | None = None
    family: tuple[str, ...] = ()
    capabilities: frozenset[str] = frozenset()
    problem: Mapping[str, Any] = field(default_factory=dict)
    requires: str | None = None
    revision: int = 1

    def __post_init__(self) -> None:
        if self.origin not in ORIGINS:
            raise ValueError(f"method {self.name!r}: origin must be one of {', '.join(ORIGINS)}, got {self.origin!r}")
        for name in ("options", "family"):
            object.__setattr__(self, name, tuple(getattr(self, name)))
        object.__setattr__(self, "capabilities", frozenset(self.capabilities))
        unknown = sorted(set(self.defaults) - set(self.options))
        if unknown:
            raise ValueError(f"method {self.name!r}: defaults for options it does not take: {unknown}")

    def takes(self, option: str) -> bool:
        return option in self.options

    @property
    def takes_time_limit(self) -> bool:
        """It honours a ``time_limit``."""
        return "time_limit" in self.options

    def draws(self, options: Mapping[str, Any] | None = None) -> bool:
        """Whether, with these options, the result can change with the seed."""
        if callable(self.seeded):
            return bool(self.seeded(dict(options or {})))
        return bool(self.seeded)

    def load(self, package: str) -> Callable:
        """The callable that runs the method (imported on first use)."""
        if callable(self.function):
            return self.function
        if self.function is None:
            raise ParameterError(f"method {self.name!r} is run by its task's entry point, not on its own")
        module, _, attribute = self.function.partition(":")
        return getattr(import_module(module, package), attribute)


# --- the checks the specs' options use (each a check(value, name) of htetro_opt._validation, bound) ---------
def integer(minimum: int | None = None, maximum: int | None = None, *, none: bool = False) -> Callable:
    """A check of an integer in ``[minimum, maximum]`` (None too with ``none``)."""
    return lambda value, name: check_int(value, name, minimum=minimum, maximum=maximum, allow_none=none)


def real(minimum: float | None = None, maximum: float | None = None, *, above: bool = False,
         none: bool = False) -> Callable:
    """A check of a finite number at least ``minimum`` (above it with ``above``), at most ``maximum``."""
    return lambda value, name: check_real(value, name, minimum=minimum, maximum=maximum,
                                          include_minimum=not above, allow_none=none)


def at_most(check: Callable, maximum: int, why: Callable[[int], str]) -> Callable:
    """``check``, and a value above ``maximum`` refused before any work with what it would cost (``why(value)``:
    the memory or time it needs), so that a typo such as ``--pop-size 1000000000`` is an error, not a
    753 GiB allocation."""
    def bounded(value, name):
        value = check(value, name)
        if value is not None and value > maximum:
            raise ParameterError(f"{name} {value:,} {why(value)}: at most {maximum:,}")
        return value
    return bounded


def bytes_text(n: float) -> str:
    """A size in words, e.g. ``"9.3 TiB"``."""
    for unit in ("bytes", "KiB", "MiB", "GiB", "TiB"):
        if n < 1024 or unit == "TiB":
            return f"{n:.0f} {unit}" if unit == "bytes" else f"{n:.1f} {unit}"
        n /= 1024
    raise AssertionError("unreachable")  # the loop returns at TiB


def duration_text(seconds: float) -> str:
    """A duration in words, e.g. ``"31,710 years"``."""
    for unit, length in (("years", 365.25 * 86400), ("days", 86400), ("hours", 3600), ("minutes", 60)):
        if seconds >= length:
            return f"{seconds / length:,.0f} {unit}"
    return f"{seconds:.0f} s"


def choice(choices: Sequence[str]) -> Callable:
    """A check of one of ``choices``."""
    def check(value, name):
        if not isinstance(value, str) or value not in choices:
            raise ParameterError(f"{name} must be one of {', '.join(choices)}, got {value!r}")
        return value
    return check


def additions(names: Mapping[str, str]) -> Callable:
    """A check of a set of additions of ours, by name (``names``: name → what it does): a collection of names,
    or the command line's text ``"all"``, ``"none"`` or ``"a,b"``; the names returned in ``names``' order."""
    def check(value, name):
        if isinstance(value, str):
            value = list(names) if value == "all" else [] if value in ("none", "") else \
                [v.strip() for v in value.split(",") if v.strip()]
        if not isinstance(value, (list, tuple, set, frozenset)):
            raise ParameterError(f"{name} must be names of {', '.join(names)} (or all, none), got {value!r}")
        unknown = [v for v in value if v not in names]
        if unknown:
            raise ParameterError(f"{name}: unknown addition {', '.join(map(repr, unknown))}: the additions are "
                                 f"{', '.join(names)}")
        return tuple(n for n in names if n in set(value))
    return check


def unchecked(value, name):
    """No check here: the value is checked where it is used (a simulator's commands, a tileset's name)."""
    return value


def callback(value, name):
    """A ``progress(done, total, note)`` callable or None (:mod:`htetro_opt._progress`)."""
    from htetro_opt._progress import check_progress

    return check_progress(value, name)


def seed_option(help_text: str = "random seed: the same seed gives the same result") -> Option:
    """The ``seed`` option of every stochastic method: None (fresh entropy), an int or a Generator;
    default :data:`DEFAULT_SEED`; never a study key (the study's ``seeds`` give it)."""
    return Option("seed", lambda value, name: check_seed(value, name), help_text, default=DEFAULT_SEED, type=int,
                  metavar="N", study=False)


@dataclass(frozen=True, eq=False)
class Problem:
    """A scenario posed as a task's data (:meth:`TaskSpec.pose`).

    ``args`` and ``kwargs`` are what the task's entry point takes besides ``method=`` and the options
    (a grid plan's workspace and roadmap; a cover's workspace, layers, start and goal); ``scenario`` is
    the loaded scenario (for plots and the true world), ``name`` its name, ``extras`` what records and
    plots need beyond them (a sequence's instance and tileset).
    """

    name: str
    args: tuple
    kwargs: Mapping[str, Any] = field(default_factory=dict)
    scenario: Any = None
    extras: Mapping[str, Any] = field(default_factory=dict)


class TaskSpec:
    """A task: its entry point, options and methods (see the module docstring).

    Parameters
    ----------
    name : str
        The task's name ("grid paths").
    package : str
        The task's package, from which the methods' ``"module:attribute"`` are imported.
    entry : str
        The entry point, ``"module:function"`` relative to ``package``.
    options : sequence of Option
    methods : sequence of Method
    default : str
        The default method.
    exact : str, optional
        The task's exact method (the reference of its studies' gaps).
    aliases : mapping, optional
        Other names of methods (``exact`` for the grid's dijkstra).
    families : mapping, optional
        Family name → how messages name it ("the GA methods").
    common : sequence of str, optional
        Options every method takes (a sequence's start tile, a plan's clearance): added to each method's
        own at registration, a method registered later included.
    relations : callable, optional
        ``relations(method, given, label)``: a check of the options given together (``given``, checked one
        by one), raising a :class:`~htetro_opt.errors.ParameterError` that names them by ``label(option)``
        (a window given for an addition that is off).
    pose : callable, optional
        ``pose(scenario, *, label, **problem_options) -> Problem``: a scenario (a loaded one, a bundled
        name or a file) as the entry point's data, ``label(option)`` naming an option in its messages; see
        :meth:`pose`.
    solve : callable, optional
        ``solve(spec, problem, method, options) -> result``: how a posed problem is solved (default:
        the entry point called with the problem's data, ``method=`` and the options).
    """

    def __init__(self, name: str, *, package: str, entry: str, options: Sequence[Option], methods: Sequence[Method],
                 default: str, exact: str | None = None, aliases: Mapping[str, str] | None = None,
                 families: Mapping[str, str] | None = None, common: Sequence[str] = (),
                 relations: Callable | None = None, pose: Callable | None = None,
                 solve: Callable | None = None) -> None:
        self.name = name
        self.package = package
        self.entry = entry
        self.options: dict[str, Option] = {}
        for option in options:
            if option.name in self.options:
                raise ValueError(f"task {name!r}: option {option.name!r} declared twice")
            self.options[option.name] = option
        self.common = tuple(common)
        self.methods: dict[str, Method] = {}
        for method in methods:
            self.register(method)
        self.aliases = dict(aliases or {})
        self.families = dict(families or {})
        self.default = default
        self.exact = exact
        self._relations = relations
        self._pose = pose
        self._solve = solve
        for alias, target in self.aliases.items():
            if target not in self.methods or alias in self.methods:
                raise ValueError(f"task {name!r}: alias {alias!r} must name a method and not be one")
        for method in (default, exact):
            if method is not None and method not in self.methods:
                raise ValueError(f"task {name!r}: {method!r} is not one of its methods")

    def __repr__(self) -> str:
        return f"TaskSpec({self.name!r}, methods={list(self.methods)})"

    # --- methods ------------------------------------------------------------------------------------
    def register(self, method: Method) -> Method:
        """Add a method (or replace one of the same name), with the task's :attr:`common` options; every
        reader of the spec then offers it.

        Raises
        ------
        ValueError
            If it takes an option the task does not declare.
        """
        method = replace(method, options=(*self.common, *(o for o in method.options if o not in self.common)))
        unknown = [o for o in method.options if o not in self.options]
        if unknown:
            raise ValueError(f"method {method.name!r} of task {self.name!r} takes undeclared options {unknown}")
        self.methods[method.name] = method
        return method

    def unregister(self, name: str) -> None:
        """Remove a method added by :meth:`register`."""
        self.methods.pop(name, None)

    @property
    def names(self) -> tuple[str, ...]:
        """Every ``method=`` name: the methods, then the aliases."""
        return tuple(self.methods) + tuple(self.aliases)

    def method(self, name) -> Method:
        """The method of ``name`` (an alias resolved).

        Raises
        ------
        ParameterError
            Naming the task's methods.
        """
        if isinstance(name, str):
            name = self.aliases.get(name, name)
            if name in self.methods:
                return self.methods[name]
        raise ParameterError(f"unknown {self.name} method {name!r}: expected one of {', '.join(self.names)}"
                             " or a callable")

    def taking(self, option: str) -> tuple[str, ...]:
        """The methods that take ``option``."""
        return tuple(name for name, m in self.methods.items() if m.takes(option))

    def describe(self, names: Iterable[str], *, members: bool = True) -> str:
        """Methods in words: whole families by their name (with ``members``, listed in brackets), the
        others by name."""
        names = [n for n in self.methods if n in set(names)]
        parts, left = [], list(names)
        families = sorted(self.families.items(), key=lambda item: -len(self._members(item[0])))
        for family, words in families:
            group = self._members(family)
            if group and set(group) <= set(left):
                parts.append(f"{words} ({', '.join(group)})" if members and len(group) > 1 else words)
                left = [n for n in left if n not in group]
        parts += left
        return parts[0] if len(parts) == 1 else ", ".join(parts[:-1]) + " and " + parts[-1]

    def _members(self, family: str) -> list[str]:
        return [n for n, m in self.methods.items() if family in m.family]

    # --- options ------------------------------------------------------------------------------------
    def defaults(self, method: str | Method) -> dict:
        """Every option of ``method`` with its default (the method's own where it has one)."""
        m = method if isinstance(method, Method) else self.method(method)
        return {name: m.defaults.get(name, self.options[name].default) for name in m.options}

    def default_of(self, method: str | Method, option: str):
        m = method if isinstance(method, Method) else self.method(method)
        return m.defaults.get(option, self.options[option].default)

    def label(self, option: str, naming: str) -> str:
        """How the user knows an option: its keyword (``"keyword"``, ``"key"``) or its flag (``"flag"``)."""
        flags = self.options[option].flags
        return flags[0] if naming == "flag" and flags else option

    def check(self, method: str | Method, options: Mapping[str, Any], *, naming: str = "keyword",
              stage: str | None = None, fill: bool = True) -> dict:
        """The options of a call of ``method``, each checked, with the method's defaults for the others.

        Parameters
        ----------
        method : str or Method
        options : mapping
            The options given.
        naming : {"keyword", "flag", "key"}
            How messages name an option: as the library's keyword, the command line's flag, a study key.
        stage : {"method", "problem"}, optional
            Check and fill the options of this stage only (others given are refused as unknown).
        fill : bool
            Add the defaults of the options not given.

        Raises
        ------
        ParameterError
            For an option the task does not have (naming the method's options), one this method does not
            take (naming the methods that do), or a bad value (naming the option as the user wrote it).
        """
        m = method if isinstance(method, Method) else self.method(method)
        if not isinstance(options, Mapping):
            raise ParameterError(f"options must be a mapping of option names to values, got {options!r}")
        own = [o for o in m.options if stage is None or self.options[o].stage == stage]
        out = {}
        for key, value in options.items():
            option = self.options.get(key) if isinstance(key, str) else None
            if option is None or (stage is not None and option.stage != stage):
                listed = ", ".join(self.label(o, naming) for o in own) or "none"
                raise ParameterError(f"method {m.name!r} takes no option {key!r}: its options are {listed}")
            label = self.label(key, naming)
            if key not in own:
                scope = f"{label} applies to {self.describe(self.taking(key))} only"
                if key in m.problem:  # its problem has a fixed value of it (the heat planner's diagonals)
                    scope += f" ({m.name} always plans with {key} {_words(m.problem[key])})"
                if naming == "keyword":  # a library call: the method's options, as for a typo
                    listed = ", ".join(own) or "none"
                    raise ParameterError(f"method {m.name!r} takes no option {key!r} ({scope}): "
                                         f"its options are {listed}")
                raise ParameterError(f"{scope}, not to {m.name}")
            out[key] = option.check(value, label)
        if self._relations is not None:
            self._relations(m, out, lambda option: self.label(option, naming))
        if fill:
            for name in own:
                if name not in out:
                    out[name] = self.default_of(m, name)
        return out

    def applicable(self, method: str | Method, **options) -> dict:
        """Of ``options``, those ``method`` takes: one set of options for a loop over methods that differ.

        Examples
        --------
        >>> from htetro_opt.solvers.sequencing import SPEC
        >>> SPEC.applicable("ga", seed=0, time_limit=2), SPEC.applicable("zigzag", seed=0, time_limit=2)
        ({'seed': 0, 'time_limit': 2}, {})
        """
        m = method if isinstance(method, Method) else self.method(method)
        return {k: v for k, v in options.items() if m.takes(k)}

    def split(self, method: str | Method, options: Mapping[str, Any]) -> tuple[dict, dict]:
        """``options`` as (problem options, method options), by each option's stage (unknown ones in
        the method's, where :meth:`check` refuses them)."""
        problem = {k: v for k, v in options.items() if k in self.options and self.options[k].stage == "problem"}
        return problem, {k: v for k, v in options.items() if k not in problem}

    # --- running ------------------------------------------------------------------------------------
    def entry_point(self) -> Callable:
        module, _, attribute = self.entry.partition(":")
        return getattr(import_module(module, self.package), attribute)

    def pose(self, scenario, *, naming: str = "keyword", **problem_options):
        """A scenario (loaded, a bundled name or a file) as the entry point's data: a
        :class:`Problem` (the entry point's data, the loaded scenario, and what the records and plots
        need). Its errors name the options as ``naming`` says (:meth:`label`)."""
        if self._pose is None:
            raise ParameterError(f"task {self.name!r} takes no scenario")
        filled = {name: option.default for name, option in self.options.items() if option.stage == "problem"}
        filled.update(problem_options)
        return self._pose(scenario, label=lambda option: self.label(option, naming), **filled)

    def solve(self, scenario, *, method: str | None = None, naming: str = "keyword", **options):
        """Pose ``scenario`` with the problem options and solve it with ``method`` and the others.

        What a study trial and a command of the command line do: ``spec.solve(scenario, method=…,
        **options)``, then ``result.as_dict()``. Returns ``(problem, result)``.
        """
        name = self.default if method is None else method
        m = self.method(name) if isinstance(name, str) else None
        problem_options, method_options = self.split(m, options) if m is not None else ({}, dict(options))
        if m is not None:
            problem_options = self.check(m, problem_options, naming=naming, stage="problem", fill=False)
        problem = self.pose(scenario, naming=naming, **problem_options)
        return problem, self.run(problem, method=name, **method_options)

    def run(self, problem: Problem, *, method, **options):
        """Solve a posed problem (:meth:`pose`) with ``method`` and its options: the entry point, called with
        the problem's data (or the task's own ``solve``)."""
        if self._solve is not None:
            return self._solve(self, problem, method, options)
        return self.entry_point()(*problem.args, method=method, **problem.kwargs, **options)

    def fingerprint(self, method: str | Method, options: Mapping[str, Any]) -> str:
        """A hash of the code and settings a run of ``method`` stands for: the package version, the
        method's revision, presets and capabilities, and every option it takes with the value it runs
        with (given, or the default): a result recorded under another fingerprint is stale.

        Examples
        --------
        >>> from htetro_opt.solvers.sequencing._spec import SPEC
        >>> SPEC.fingerprint("exact", {}) == SPEC.fingerprint("exact", {"time_limit": None})
        True
        >>> SPEC.fingerprint("exact", {}) == SPEC.fingerprint("exact", {"time_limit": 5.0})
        False
        """
        from htetro_opt import __version__

        m = method if isinstance(method, Method) else self.method(method)
        values = {**self.defaults(m), **{k: v for k, v in options.items() if k in m.options}}
        described = {
            "version": __version__, "task": self.name, "method": m.name, "revision": m.revision,
            "presets": dict(m.presets), "seeded": m.draws(values), "exact": m.exact, "origin": m.origin,
            "options": {k: values[k] for k in sorted(values) if self.options[k].study},
        }
        text = json.dumps(described, sort_keys=True, default=_jsonable, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    # --- words --------------------------------------------------------------------------------------
    def default_words(self, option: str, methods: Iterable[str] | None = None) -> str:
        """The default of ``option`` in words, over ``methods`` (default: those taking it)."""
        opt = self.options[option]
        names = [n for n in (methods or self.taking(option)) if self.methods[n].takes(option)]
        if opt.default_text is not None and not any(option in self.methods[n].defaults for n in names):
            return opt.default_text
        # a method's own default in words; the option's text for the methods that keep the option's default
        words = {n: _words(self.default_of(n, option)) if option in self.methods[n].defaults or opt.default_text is None
                 else opt.default_text for n in names}
        distinct = list(dict.fromkeys(words.values()))
        if len(distinct) <= 1:
            if opt.default_text is not None and not distinct:
                return opt.default_text
            return distinct[0] if distinct else _words(opt.default)
        groups: dict[str, list[str]] = {}
        for n, w in words.items():
            groups.setdefault(w, []).append(n)
        return "; ".join(f"{v} for {self.describe(ns, members=False)}" for v, ns in groups.items())

    def help(self, option: str, methods: Iterable[str] | None = None) -> str:
        """``--help``'s text of an option: what it does, which methods take it, its default."""
        opt = self.options[option]
        takers = self.taking(option)
        scope = "" if set(takers) >= set(methods or self.methods) else f"{self.describe(takers, members=False)}: "
        if opt.switch:
            return f"{scope}{opt.help}"
        return f"{scope}{opt.help} (default {self.default_words(option)})"

    def method_help(self) -> str:
        """``--method``'s help: every method with its summary, the default first."""
        lines = []
        for name, m in self.methods.items():
            tag = " (default)" if name == self.default else ""
            lines.append(f"{name}{tag}: {m.summary}")
        for alias, target in self.aliases.items():
            lines.append(f"{alias}: {target}")
        return "; ".join(lines)


def _words(value) -> str:
    if value is None:
        return "none"
    if isinstance(value, bool):
        return "on" if value else "off"
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, (list, tuple, set, frozenset)):
        return ",".join(_words(v) for v in value) if value else "none"  # an empty set is said
    return str(value)


def _jsonable(value):
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        return float(value)
    if isinstance(value, (set, frozenset)):
        return sorted(value)
    if isinstance(value, Mapping):
        return dict(value)
    if isinstance(value, Sequence):
        return list(value)
    return repr(value)

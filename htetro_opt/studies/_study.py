"""A study: scenarios × methods × seeds of one task, checked as a whole before any trial runs.

What a method entry may set, which methods run once per seed, and what the exact reference is all come
from the task's spec (:mod:`htetro_opt._spec`); nothing here restates them.
"""

from __future__ import annotations

import numbers
import os
import re
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path
from typing import Any

from htetro_opt._spec import TaskSpec
from htetro_opt._validation import check_int
from htetro_opt.errors import HtetroError, ParameterError, StudyError
from htetro_opt.studies._trial import Trial, _plain, reference_trial, spec_of

__all__ = ["METRICS", "TASKS", "MethodEntry", "Study", "list_studies", "load_study"]

TASKS = ("plan", "tile", "sequence", "cover")
"""The tasks a study can run: the command-line verbs of the same names (``plan`` on grid or on
continuous scenarios)."""

METRICS = {
    "plan": ("objectives", "generations", "fitness", "gap", "heat_fitness", "front", "history", "hv_curve"),
    "tile": (),
    "sequence": ("gap",),
    "cover": ("gap",),
}
"""Optional metrics per task, beyond those every record holds (see :mod:`htetro_opt.studies.runner`)."""

_DEFAULT_METRICS = ("gap",)  # where the task has it (_check_metrics keeps the task's own)
_GA_METRICS = ("front", "history", "hv_curve")  # of a population: the exact planners have none
_TOP_KEYS = ("name", "description", "task", "scenarios", "seeds", "metrics", "methods")
_ENTRY_KEYS = ("method", "label", "scenarios", "per_scenario")
_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*")


@dataclass(frozen=True)
class MethodEntry:
    """One method of a study: its name, the label its rows carry, its options (for every scenario, and
    per scenario on top of them), and the scenarios it runs on (None: all the study's)."""

    method: str
    label: str
    options: Mapping[str, Any] = field(default_factory=dict)
    per_scenario: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    scenarios: tuple[str, ...] | None = None

    def runs_on(self, scenario: str) -> bool:
        """Whether the method runs on ``scenario`` (a study's resolved scenario)."""
        return self.scenarios is None or scenario in self.scenarios

    def parameters(self, scenario: str) -> dict:
        """The options of a trial on ``scenario``, its own overrides applied, sorted by name."""
        merged = {**self.options, **self.per_scenario.get(scenario, {})}
        return {k: merged[k] for k in sorted(merged)}

    def as_entry(self) -> dict:
        """The study-file entry of this method."""
        entry = {"method": self.method, "label": self.label, **self.options}
        if self.scenarios is not None:
            entry["scenarios"] = list(self.scenarios)
        if self.per_scenario:
            entry["per_scenario"] = {k: dict(v) for k, v in self.per_scenario.items()}
        return entry


@dataclass(frozen=True)
class Study:
    """Scenarios × methods × seeds of one task, checked as a whole when made.

    Parameters
    ----------
    name : str
        Names the results files (``<name>.jsonl``, ``.csv``, ``.md``): letters, digits, ``_.-``.
    task : {"plan", "tile", "sequence", "cover"}
    scenarios : sequence of str
        Bundled names or files (``sequence``: labelled tilesets too, or scenarios to tile first; ``plan``:
        all grid or all continuous scenarios).
    methods : sequence of mapping or MethodEntry
        Each a study-file entry: ``method`` (a method of the task's spec), an optional ``label``
        (default: the method's name, with its options when several entries share it), the method's
        options as the spec names them, ``scenarios`` (optional: run it on these of the study's
        scenarios only) and ``per_scenario`` (scenario → options overriding them there).
    seeds : int or sequence of int
        N for seeds 0 … N−1, or the seeds themselves (default 1). A method whose spec says it does not
        draw from the seed (for its options) runs once.
    metrics : sequence of str, optional
        Optional metrics of the task (:data:`METRICS`). Default ``["gap"]`` where the task has it,
        so that a summary sets every method beside the exact reference; ``[]`` measures none.
    description : str
    source : str, optional
        The study file, named in error messages; relative scenario paths start from its folder.

    Raises
    ------
    StudyError
        Naming the file (or study), the entry and the key of the first mistake.

    Examples
    --------
    >>> study = Study(name="demo", task="plan", scenarios=["three_slit"], seeds=2,
    ...               methods=[{"method": "exact"}, {"method": "htetro-ga", "pop_size": 10}])
    >>> [(t.label, t.seed) for t in study.trials()]
    [('exact', None), ('htetro-ga', 0), ('htetro-ga', 1)]
    >>> Study(name="d", task="plan", scenarios=["three_slit"], methods=[{"method": "astar", "pop_size": 10}])
    Traceback (most recent call last):
    ...
    htetro_opt.errors.StudyError: study 'd', methods[0]: pop_size applies to the GA methods (htetro-ga, htetro-ga-paper, nsga2, nsga3, smsemoa, agemoea) only, not to astar
    """

    name: str
    task: str
    scenarios: tuple[str, ...]
    methods: tuple[MethodEntry, ...]
    seeds: tuple[int, ...] = (0,)
    metrics: tuple[str, ...] | None = None
    description: str = ""
    source: str | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        where = f"study file {self.source!r}" if self.source else f"study {self.name!r}"
        if not isinstance(self.name, str) or not _NAME.fullmatch(self.name):
            raise StudyError(f"{where}: name must be letters, digits, '_', '.' or '-' (it names the results "
                             f"files), got {self.name!r}")
        if self.task not in TASKS:
            raise StudyError(f"{where}: task must be one of {', '.join(TASKS)} (a command-line verb), "
                             f"got {self.task!r}")
        if not isinstance(self.description, str):
            raise StudyError(f"{where}: description must be a string, got {self.description!r}")
        base = Path(self.source).parent if self.source else None
        scenarios, written = _check_scenarios(self.task, self.scenarios, base, where)
        spec = _spec_of_scenarios(self.task, scenarios, where)
        seeds = _check_seeds(self.seeds, f"{where}: seeds")
        metrics = _check_metrics(self.task, _DEFAULT_METRICS if self.metrics is None else self.metrics, where)
        methods = _check_methods(self.task, spec, self.methods, scenarios, written, where)
        for i, entry in enumerate(methods):
            _check_ga_metrics(spec, entry.method, metrics, f"{where}, methods[{i}]")
        object.__setattr__(self, "scenarios", scenarios)
        object.__setattr__(self, "seeds", seeds)
        object.__setattr__(self, "metrics", metrics)
        object.__setattr__(self, "methods", methods)

    @property
    def spec(self) -> TaskSpec:
        """The task's spec its trials run (``plan``: the grid-path or the continuous task)."""
        return spec_of(self.task, self.scenarios[0])

    def with_seeds(self, seeds: int | Sequence[int]) -> Study:
        """The same study with other seeds (an int N: 0 … N−1)."""
        return replace(self, seeds=seeds)

    def trials(self) -> list[Trial]:
        """Every trial, scenario by scenario, method by method, seed by seed (once, seed None, for a
        method that does not draw from the seed)."""
        spec, out = self.spec, []
        for scenario in self.scenarios:
            for entry in self.methods:
                if not entry.runs_on(scenario):
                    continue
                parameters = entry.parameters(scenario)
                seeds = self.seeds if spec.method(entry.method).draws(parameters) else (None,)
                out.extend(Trial(self.task, scenario, entry.method, parameters, seed, entry.label, self.metrics)
                           for seed in seeds)
        return out

    def references(self) -> dict[str, Trial]:
        """The reference trial (the task's exact method) of each trial that asks for a gap, by trial key
        (none for a task without an exact method: ``cover`` measures its gap to its own lower bound)."""
        if "gap" not in self.metrics or self.spec.exact is None:
            return {}
        return {trial.key: reference_trial(trial) for trial in self.trials()}


def _check_scenarios(task, scenarios, base, where) -> tuple[tuple[str, ...], dict[str, str]]:
    if isinstance(scenarios, str) or not isinstance(scenarios, Sequence) or not scenarios:
        raise StudyError(f"{where}: scenarios must be a non-empty list of scenario names or files, got {scenarios!r}")
    resolved, written = [], {}
    for i, name in enumerate(scenarios):
        path = _resolve_scenario(task, name, base, f"{where}: scenarios[{i}]")
        if path in resolved:
            raise StudyError(f"{where}: scenarios[{i}] {name!r} is listed twice")
        resolved.append(path)
        written[name] = written[path] = path
    return tuple(resolved), written


def _resolve_scenario(task: str, name, base: Path | None, where: str) -> str:
    """The scenario's name if bundled, else its path (relative paths from the study file's folder),
    checked by posing it as the task's problem."""
    from htetro_opt.scenarios import list_scenarios, list_tilesets

    if not isinstance(name, str) or not name:
        raise StudyError(f"{where} must be a scenario name or file path, got {name!r}")
    bundled = list_scenarios() + (list_tilesets() if task == "sequence" else [])
    resolved = name
    if "/" in name or name not in bundled:
        path = Path(name)
        if base is not None and not path.is_absolute():
            path = base / path
        if not path.is_file():
            kinds = "scenario or tileset" if task == "sequence" else "scenario"
            raise StudyError(f"{where}: unknown {kinds} {name!r}: not a bundled name ({', '.join(bundled)}) "
                             "nor a file")
        resolved = str(path.resolve())
    if task != "sequence":  # a scenario to tile is posed (tiled) by its trials only: tiling takes time
        try:
            spec_of(task, resolved).pose(resolved, naming="key")
        except HtetroError as err:
            raise StudyError(f"{where} {name!r}: {' '.join(str(err).split())}") from err
    return resolved


def _spec_of_scenarios(task: str, scenarios, where: str) -> TaskSpec:
    specs = {spec_of(task, s).name for s in scenarios}
    if len(specs) > 1:
        raise StudyError(f"{where}: scenarios mix {' and '.join(sorted(specs))}: a plan study plans grid "
                         "scenarios or continuous ones")
    return spec_of(task, scenarios[0])


def _check_seeds(seeds, where: str) -> tuple[int, ...]:
    if isinstance(seeds, (str, bytes)) or not isinstance(seeds, (numbers.Integral, Sequence)) or \
            isinstance(seeds, bool) or (isinstance(seeds, Sequence) and not seeds):
        raise StudyError(f"{where} must be a positive integer N (seeds 0 … N−1) or a non-empty list of seeds, "
                         f"got {seeds!r}")
    try:
        if isinstance(seeds, numbers.Integral):
            return tuple(range(check_int(seeds, where, minimum=1)))
        out = tuple(check_int(s, f"{where}[{i}]", minimum=0) for i, s in enumerate(seeds))
    except ParameterError as err:
        raise StudyError(str(err)) from err
    if len(set(out)) < len(out):
        raise StudyError(f"{where} lists a seed twice: {list(out)}")
    return out


def _check_metrics(task, metrics, where) -> tuple[str, ...]:
    known = METRICS[task]
    if isinstance(metrics, str) or not isinstance(metrics, Sequence):
        raise StudyError(f"{where}: metrics must be a list of names ({', '.join(known) or 'none for ' + task}), "
                         f"got {metrics!r}")
    if metrics is _DEFAULT_METRICS:
        return tuple(m for m in known if m in metrics)
    for i, metric in enumerate(metrics):
        if metric not in known:
            raise StudyError(f"{where}: metrics[{i}]: unknown metric {metric!r} for task {task}: expected "
                             f"{', '.join(known) if known else 'none (its records hold every metric)'}")
    return tuple(m for m in known if m in metrics)


def _check_ga_metrics(spec: TaskSpec, method: str, metrics, where) -> None:
    """Refuse a metric of a population (:data:`_GA_METRICS`) for a method that has none."""
    for metric in metrics:
        if metric in _GA_METRICS and "ga" not in spec.method(method).family:
            takers = [name for name, m in spec.methods.items() if "ga" in m.family]
            raise StudyError(f"{where}: metric {metric!r} applies to {spec.describe(takers)} only, not to {method}: "
                             f"{spec.describe([method])} has no population, hence no front (metric 'gap' compares a "
                             "plan with the optimum)")


def _check_options(task: str, spec: TaskSpec, method: str, options, scenarios, where: str) -> dict:
    """A method entry's options, each checked by the spec; ``scenarios`` the study's scenarios they apply to."""
    if not isinstance(options, Mapping):
        raise StudyError(f"{where} must be a table of options, got {options!r}")
    for key in options:
        if key == "seed":
            raise StudyError(f"{where}: seed: the study's `seeds` give every trial its seed; "
                             "a method entry takes none")
        if key in spec.options and not spec.options[key].study:
            raise StudyError(f"{where}: {key} cannot be set in a study file (a library option)")
    try:  # as JSON holds them (a tuple of weights as a list): a trial's key hashes them, its record keeps them
        out = {k: _plain(v) for k, v in spec.check(method, options, naming="key", fill=False).items()}
    except ParameterError as err:
        raise StudyError(f"{where}: {err}") from err
    if task == "cover" and "stripes" in out:
        _check_stripes_fit(out["stripes"], scenarios, where)
    if task == "sequence" and "shapes" in out:
        from htetro_opt.solvers.sequencing._spec import is_tileset

        tilesets = [s for s in scenarios if is_tileset(s)]
        if tilesets:
            raise StudyError(f"{where}: shapes applies only to scenarios to tile, not to the tileset "
                             f"{tilesets[0]!r} (give it under per_scenario)")
    return out


def _check_stripes_fit(value, scenarios, where) -> None:
    """Stripe widths that fit every one of ``scenarios``: a width at most its height, widths summing to it."""
    from htetro_opt.scenarios import load_scenario
    from htetro_opt.solvers.coverage import stripe_widths

    for scenario in scenarios:
        grid = load_scenario(scenario)
        try:
            stripe_widths(value, grid.workspace.height)
        except ParameterError as err:
            raise StudyError(f"{where}: {err} (scenario {grid.name!r}, {grid.workspace.height} rows; give its "
                             "widths under per_scenario)") from err


def _check_methods(task, spec, methods, scenarios, written, where) -> tuple[MethodEntry, ...]:
    if isinstance(methods, (str, Mapping)) or not isinstance(methods, Sequence) or not methods:
        raise StudyError(f"{where}: methods must be a non-empty list of method entries ([[methods]] tables), "
                         f"got {methods!r}")
    entries = [m.as_entry() if isinstance(m, MethodEntry) else m for m in methods]
    checked = []
    for i, entry in enumerate(entries):
        here = f"{where}, methods[{i}]"
        if not isinstance(entry, Mapping):
            raise StudyError(f"{here} must be a table with a method and its options, got {entry!r}")
        if "method" not in entry:
            raise StudyError(f"{here}: method is missing (one of {', '.join(spec.names)})")
        name = entry["method"]
        if not isinstance(name, str) or name not in spec.names:
            raise StudyError(f"{here}: unknown {task} method {name!r}: expected one of {', '.join(spec.names)}")
        method = spec.method(name).name  # an alias resolved
        label = entry.get("label")
        if label is not None and (not isinstance(label, str) or not label.strip()):
            raise StudyError(f"{here}: label must be a non-empty string, got {label!r}")
        own = _check_entry_scenarios(entry.get("scenarios"), scenarios, written, here)
        options = _check_options(task, spec, method, {k: v for k, v in entry.items() if k not in _ENTRY_KEYS},
                                 scenarios if own is None else own, here)
        per_scenario = entry.get("per_scenario", {})
        if not isinstance(per_scenario, Mapping):
            raise StudyError(f"{here}: per_scenario must be a table of scenario → options, got {per_scenario!r}")
        overrides = {}
        for scenario, scenario_options in per_scenario.items():
            if scenario not in written:
                raise StudyError(f"{here}: per_scenario.{scenario}: {scenario!r} is not one of the study's "
                                 f"scenarios ({', '.join(map(repr, scenarios))})")
            if own is not None and written[scenario] not in own:
                raise StudyError(f"{here}: per_scenario.{scenario}: {scenario!r} is not one of the entry's "
                                 "scenarios, on which alone it runs")
            overrides[written[scenario]] = _check_options(task, spec, method, scenario_options, [written[scenario]],
                                                          f"{here}, per_scenario.{scenario}")
        checked.append((name, label, method, options, overrides, own))
    names = [name for name, *_ in checked]
    out, labels = [], {}
    for i, (name, label, method, options, overrides, own) in enumerate(checked):
        if label is None:
            label = name
            if names.count(name) > 1 and options:
                label += " (" + ", ".join(f"{k}={_text(options[k])}" for k in sorted(options)) + ")"
        if label in labels:
            raise StudyError(f"{where}, methods[{i}]: label {label!r} is also methods[{labels[label]}]'s: "
                             "give each entry its own label")
        labels[label] = i
        out.append(MethodEntry(method, label, options, overrides, own))
    return tuple(out)


def _check_entry_scenarios(own, scenarios, written, where) -> tuple[str, ...] | None:
    """A method entry's ``scenarios``: some of the study's (resolved), in the study's order; None if not given."""
    if own is None:
        return None
    if isinstance(own, str) or not isinstance(own, Sequence) or not own:
        raise StudyError(f"{where}: scenarios must be a non-empty list of the study's scenarios, got {own!r}")
    chosen = set()
    for i, name in enumerate(own):
        if not isinstance(name, str) or name not in written:
            raise StudyError(f"{where}: scenarios[{i}] {name!r} is not one of the study's scenarios "
                             f"({', '.join(map(repr, scenarios))})")
        if written[name] in chosen:
            raise StudyError(f"{where}: scenarios[{i}] {name!r} is listed twice")
        chosen.add(written[name])
    return tuple(s for s in scenarios if s in chosen)


def _text(value) -> str:
    if isinstance(value, (list, tuple)):
        return ",".join(f"{v:g}" if isinstance(v, float) else str(v) for v in value)
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


# --- study files -----------------------------------------------------------------------------------
def _data_dir() -> Path:
    return Path(str(resources.files("htetro_opt.studies") / "data"))


def list_studies() -> list[str]:
    """Names of the bundled study files, sorted.

    Examples
    --------
    >>> {"small", "table4", "sequencing"} <= set(list_studies())
    True
    """
    return sorted(p.stem for p in _data_dir().glob("*.toml"))


def load_study(name_or_path: str | os.PathLike) -> Study:
    """Read a study: a bundled name (:func:`list_studies`) or a TOML file.

    Top-level keys: ``name`` (default: the file's stem), ``description``, ``task``, ``scenarios``,
    ``seeds``, ``metrics`` and the ``[[methods]]`` entries, see :class:`Study`.

    Raises
    ------
    StudyError
        If there is no such study, the file is not TOML, or anything in it is invalid (naming the
        file, the entry and the key).

    Examples
    --------
    >>> study = load_study("small")
    >>> study.task, study.scenarios, [m.label for m in study.methods], len(study.trials())
    ('plan', ('random', 'three_slit', 'h_shape'), ['dijkstra', 'htetro-ga'], 12)
    """
    if not isinstance(name_or_path, (str, os.PathLike)):
        raise StudyError(f"a study must be a bundled name or a file path, got {name_or_path!r}")
    bundled = _data_dir() / f"{name_or_path}.toml"
    if isinstance(name_or_path, str) and "/" not in name_or_path and bundled.is_file():
        path = bundled
    else:
        path = Path(name_or_path)
        if not path.is_file():
            what = "no such file" if str(name_or_path).endswith(".toml") or "/" in str(name_or_path) else \
                f"not a bundled study ({', '.join(list_studies())}) nor a file"
            raise StudyError(f"no study {str(name_or_path)!r}: {what}")
    where = f"study file {str(path)!r}"
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as err:
        raise StudyError(f"{where}: cannot read it: {getattr(err, 'strerror', None) or err}") from err
    except tomllib.TOMLDecodeError as err:
        raise StudyError(f"{where}: not valid TOML: {err}") from err
    for key in data:
        if key not in _TOP_KEYS:
            raise StudyError(f"{where}: unknown key {key!r}: a study file has {', '.join(_TOP_KEYS)}")
    for key in ("task", "scenarios", "methods"):
        if key not in data:
            raise StudyError(f"{where}: {key} is missing")
    return Study(name=data.get("name", path.stem), task=data["task"], scenarios=data["scenarios"],
                 methods=data["methods"], seeds=data.get("seeds", 1), metrics=data.get("metrics"),
                 description=data.get("description", ""), source=str(path))

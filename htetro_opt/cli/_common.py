"""What every command of the command line shares: options built from the task specs, output files checked
before any work, progress, plots, and the result kept when an output fails after the work.

Importing this loads no solver: a command imports what it runs when it runs.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path

from htetro_opt._console import Console
from htetro_opt._spec import Method, TaskSpec
from htetro_opt._validation import MAX_TIME_LIMIT, check_real
from htetro_opt.errors import HtetroError, OutputError, ParameterError, ScenarioError

__all__ = ["LateOutputError", "add_method", "add_outputs", "add_task_options", "check_outputs", "console",
           "given_options", "grid_scenario", "late", "save_gif", "save_plot"]

_PREFIX = "opt_"  # argparse destinations of the specs' options, apart from the commands' own


# --- options from the specs -------------------------------------------------------------------------
def whole_number(text: str) -> int:
    """A count as a user types it: ``100``, ``100_000`` or ``1e5`` (so that ``--pop-size 1e9`` meets the
    option's own bound, which says what that many would cost, rather than a parse error)."""
    try:
        return int(text)
    except ValueError:  # not a plain integer: read below as a number such as 1e5
        pass
    try:
        value = float(text)
    except ValueError:
        value = None
    if value is None or not value.is_integer():
        raise argparse.ArgumentTypeError(f"must be a whole number, got {text!r}")
    return int(value)


def add_method(parser: argparse.ArgumentParser, specs: Mapping[str, TaskSpec], *, extra: str = "") -> None:
    """``--method``: the choices of every spec, its help their summaries (default: the spec's default)."""
    names = list(dict.fromkeys(name for spec in specs.values() for name in spec.names))
    if len(specs) == 1:
        (spec,) = specs.values()
        text = spec.method_help()
    else:
        text = "; ".join(f"{label}: {spec.method_help()}" for label, spec in specs.items())
    parser.add_argument("--method", choices=names, metavar="METHOD", help=f"{text}{extra}")


def add_task_options(parser: argparse.ArgumentParser, specs: Mapping[str, TaskSpec], *,
                     skip: Sequence[str] = ()) -> None:
    """One argument per option with a flag in the ``specs`` (label → spec), its help the spec's: an option
    two specs share (``--weights`` of the heat planner and of the enhanced GA) is one flag whose help
    names both. Every default is None, so that a flag given is told from one left out."""
    merged: dict[str, list[tuple[str, TaskSpec]]] = {}
    for label, spec in specs.items():
        for name, option in spec.options.items():
            if option.flags and name not in skip:
                merged.setdefault(name, []).append((label, spec))
    for name, owners in merged.items():
        option = owners[0][1].options[name]
        texts = [spec.help(name) for _, spec in owners]
        text = texts[0] if len(owners) == len(specs) == 1 else "; ".join(
            f"{label}, {t}" for (label, _), t in zip(owners, texts))
        dest = _PREFIX + name
        if option.switch:
            group = parser.add_mutually_exclusive_group() if len(option.flags) > 1 else parser
            if option.flag:
                group.add_argument(option.flag, dest=dest, action="store_const", const=True, default=None, help=text)
            if option.off_flag:
                group.add_argument(option.off_flag, dest=dest, action="store_const", const=False, default=None,
                                   help=text if not option.flag else argparse.SUPPRESS)
        else:
            kind = whole_number if option.type is int else option.type
            parser.add_argument(option.flag, dest=dest, type=kind, choices=option.choices,
                                metavar=option.metavar, default=None, help=text)


def given_options(args: argparse.Namespace, spec: TaskSpec, method: Method, *,
                  others: Mapping[str, TaskSpec] = {}) -> dict:
    """The options given on the command line for ``method`` of ``spec``, checked by the spec (messages name
    the flags): a flag of another spec only (``others``: label → spec) is refused naming where it applies."""
    given = {name[len(_PREFIX):]: value for name, value in vars(args).items()
             if name.startswith(_PREFIX) and value is not None}
    for name in given:
        if name not in spec.options:
            label = next(label for label, other in others.items() if name in other.options)
            flag = next(other.label(name, "flag") for other in others.values() if name in other.options)
            raise ParameterError(f"{flag} applies to {label} only")
    return spec.check(method, given, naming="flag", fill=False)


def check_method(spec: TaskSpec, name: str | None, *, what: str = "") -> Method:
    """The method ``--method`` names (the spec's default when not given)."""
    try:
        return spec.method(spec.default if name is None else name)
    except ParameterError:
        raise ParameterError(f"--method {name} is not a method of {spec.name}{what}: use one of "
                             f"{', '.join(spec.names)}") from None


def time_limit_flag(value: float | None) -> float | None:
    """A command's own ``--time-limit`` (a study's): absent, or a positive, finite number of seconds."""
    if value is None:
        return None
    return check_real(value, "--time-limit (seconds)", minimum=0.0, include_minimum=False, maximum=MAX_TIME_LIMIT)


# --- outputs ----------------------------------------------------------------------------------------
def add_outputs(parser, *, json: str = "print one JSON object", plot: str | None = None,
                gif: str | None = None) -> None:
    """The output options every command shares: --json, --quiet, and --plot / --gif where it draws."""
    parser.add_argument("--json", action="store_true", help=json)
    parser.add_argument("--quiet", action="store_true", help="no progress on stderr (shown only on a terminal)")
    if plot:
        parser.add_argument("--plot", metavar="FILE", help=f"save {plot} (format from the extension)")
    if gif:
        parser.add_argument("--gif", metavar="FILE", help=f"save {gif}")


def check_outputs(args, *names: tuple[str, str]) -> None:
    """Check every output path of a command before any work starts."""
    from htetro_opt._files import check_output_path

    for attribute, what in names:
        if getattr(args, attribute, None):
            check_output_path(getattr(args, attribute), what=what)
    if getattr(args, "plot", None):
        from htetro_opt.viz import figure_format

        figure_format(args.plot)
    if getattr(args, "gif", None) and not str(args.gif).lower().endswith(".gif"):
        raise ParameterError(f"--gif {args.gif!r}: the animation is a GIF, name the file *.gif")


class LateOutputError(Exception):
    """An output file failed after the work was done: the command's result is still printed."""

    def __init__(self, out: dict, error: HtetroError) -> None:
        super().__init__(str(error))
        self.out, self.error = out, error


def late(out: dict, write) -> None:
    """Run one output write; if it fails, carry the finished result along with the error."""
    try:
        write()
    except OutputError as err:
        raise LateOutputError(out, err) from err


def _stderr_is_terminal() -> bool:
    return sys.stderr.isatty()


def console(args) -> Console:
    """Progress bars on stderr: on a terminal, unless ``--quiet``; there, a first compile of the kernels is
    said too (it takes seconds once)."""
    shown = Console(enabled=not getattr(args, "quiet", False) and _stderr_is_terminal())
    if shown.enabled:
        from htetro_opt._jit import on_compile

        on_compile(lambda text: print(text, file=sys.stderr, flush=True))
    return shown


def _files_only_backend() -> None:
    """The command line only writes files: matplotlib's Agg, never a window (and no display needed)."""
    import matplotlib

    matplotlib.use("Agg")


def save_plot(shown: Console, figure_of, path: str) -> None:
    """Draw (``figure_of()``) and save a plot, showing progress: long paths take a while."""
    _files_only_backend()
    from htetro_opt.viz import save_figure

    with shown.step(f"plotting {path}"):
        save_figure(figure_of(), path)


def save_gif(shown: Console, workspace, commands, start, *, roadmap, hidden, title: str, path: str) -> None:
    """Animate the commands from ``start`` and save the GIF, showing progress."""
    _files_only_backend()
    from htetro_opt.viz import animate_path, save_gif as write_gif

    with shown.step(f"animating {path}"):
        write_gif(animate_path(workspace, commands, start, roadmap=roadmap, hidden=hidden, title=title), path)


# --- scenarios --------------------------------------------------------------------------------------
def grid_scenario(name: str):
    from htetro_opt.scenarios import Scenario, load_scenario

    scenario = load_scenario(name)
    if not isinstance(scenario, Scenario):
        raise ScenarioError(f"scenario {scenario.name!r} is continuous; this command needs a grid scenario")
    return scenario


def folder_flag(out: str | None) -> Path | None:
    """``--out DIR``, checked before the work: a folder, or creatable inside a writable one."""
    import os

    if not out:
        return None
    folder = Path(out)
    if folder.exists() and not folder.is_dir():
        raise ParameterError(f"--out {out!r} is a file, not a folder")
    existing = folder
    while not existing.exists():
        existing = existing.parent
    if not os.access(existing, os.W_OK | os.X_OK):
        raise ParameterError(f"--out {out!r}: cannot write in {str(existing)!r}")
    return folder

"""The ``htetro-opt`` command line.

Every command takes a SCENARIO, a bundled name (``htetro-opt scenarios`` lists them) or a path to a
scenario TOML file; ``sequence`` also takes a labelled tileset (a bundled name, ``htetro-opt
scenarios`` lists them too, or a file). Errors print one ``error: …`` line and exit with status 2.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import sys
import time
from dataclasses import replace
from pathlib import Path
from typing import Sequence

import numpy as np

from htetro_opt import __version__
from htetro_opt._argparse import Parser, UsageError
from htetro_opt._console import Console
from htetro_opt._files import check_output_path, write_text
from htetro_opt._validation import MAX_TIME_LIMIT, check_int, check_real
from htetro_opt.errors import HtetroError, OutputError, ParameterError, PlanningError, ScenarioError
from htetro_opt.model import Simulator, parse_commands
from htetro_opt.model.commands import DIAGONAL_COMMANDS, SEED000_COMMANDS
from htetro_opt.model.robot import STATE_NAMES
from htetro_opt.problems import FITNESS_NAMES, SequencingInstance, check_weights
from htetro_opt.scenarios import (
    Scenario,
    format_tileset,
    list_scenarios,
    list_tilesets,
    load_scenario,
    load_tileset,
    save_tileset,
    scenario_path,
    tileset_path,
)
from htetro_opt.solvers.grid_paths import EXACT_METHODS, HEAT_ELEMENTS, PLAN_METHODS, plan_path
from htetro_opt.solvers.sequencing import SEQUENCE_METHODS, TIME_LIMIT_TEXT, sequence_waypoints
from htetro_opt.solvers.tiling import DEFAULT_TIME_LIMIT as TILING_TIME_LIMIT  # one bound, the library's
from htetro_opt.solvers.tiling import TILING_METHODS, tile_workspace

__all__ = ["main", "main_entry", "build_parser"]


EXIT_ERROR = 2
GA_DEFAULTS = {"pop_size": 50, "max_gen": 1000, "patience": None, "converge": "best", "max_length": None, "seed": 0,
               "replan_window": None, "replan_members": None, "seed_exact": False, "pick": "balanced",
               "reach_patience": None, "polish_window": None, "conservative": False}
"""Defaults of ``plan``'s GA options (None in the parser, so that one given to an exact method is refused;
None here: plan_ga's default for the algorithm)."""
GA_PICKS = ("balanced", "fastest", "smoothest", "safest")  # htetro_opt.algorithms.PICKS, without loading pymoo


def _add_outputs(p, *, json: str = "print one JSON object", plot: str | None = None, gif: str | None = None) -> None:
    """The output options every command shares: --json, --quiet, and --plot / --gif where it draws."""
    p.add_argument("--json", action="store_true", help=json)
    p.add_argument("--quiet", action="store_true", help="no progress on stderr (shown only on a terminal)")
    if plot:
        p.add_argument("--plot", metavar="FILE", help=f"save {plot} (format from the extension)")
    if gif:
        p.add_argument("--gif", metavar="FILE", help=f"save {gif}")


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="htetro-opt", description="Path planning for the hTetro reconfigurable robot.",
                    epilog="The robot model, the scenario and tileset formats and the JSON output are described in "
                    "docs/model.md and docs/formats.md of the htetro-opt repository. Times are in seconds under the "
                    "default timing. Long work shows progress on stderr when it is a terminal (--quiet: none).")
    parser.add_argument("--version", action="version", version=f"htetro-opt {__version__}")
    sub = parser.add_subparsers(dest="command", parser_class=Parser, metavar="COMMAND")

    p = sub.add_parser("scenarios", help="list the bundled scenarios")
    _add_outputs(p)

    p = sub.add_parser("plan", help="plan a path through a scenario's roadmap")
    p.add_argument("scenario", help="bundled scenario name or path to a scenario TOML file")
    p.add_argument("--method", choices=(*PLAN_METHODS, *CONTINUOUS_ONLY_METHODS),
                   help="continuous scenarios (Nazarahari et al. 2019): ega (default): its enhanced GA with our "
                        "additions, ega-paper: as published, nsga2: pymoo's NSGA-II over the same path bases "
                        "(--pop-size 10, --max-gen 20 unless given), exact: the visibility-graph optimum, astar: "
                        "A* on the --grid lattice, prm: a roadmap of the paper's samples per map, rrt: OMPL's "
                        "RRTConnect (the paper's B-RRT; pip install 'htetro-opt[ompl]'), pso: pymoo's PSO from the "
                        "APF paths; each robot alone. Grid scenarios: "
                        "dijkstra (default), astar: the minimum-time plan (the same optimum); htetro-ga: the "
                        "multi-objective GA over command chromosomes of Cheng et al. 2020 with our additions "
                        "(htetro-ga-paper: as published); nsga2, nsga3, smsemoa, agemoea: pymoo's algorithms "
                        "on the same problem; heat: Do et al. 2021's search up a heat-conduction field "
                        "(diagonals included, static maps)")
    p.add_argument("--pop-size", type=int, help=f"GA methods: population size n_pop (default {GA_DEFAULTS['pop_size']})")
    p.add_argument("--max-gen", type=int,
                   help=f"GA methods: generations per roadmap leg at most (default {GA_DEFAULTS['max_gen']})")
    p.add_argument("--patience", type=int,
                   help="GA methods: stop a leg after this many generations without improvement "
                        "once its goal is reached (default 100); 20 by default with --converge hypervolume")
    p.add_argument("--converge", choices=("best", "hypervolume"),
                   help="GA methods: what counts as an improvement for --patience: best (default), a rise of the "
                        "goal-reaching members' best f_t, f_sm, f_sf or fitness sum; hypervolume, of the best f_t "
                        "or of their front's hypervolume (half the generations, a slightly smaller front)")
    p.add_argument("--max-length", type=int,
                   help="GA methods: l_p,max, the initial chromosome length (default, per leg: the least multiple "
                        "of 100 whose time is at least 1.5 times the leg's exact minimum time, as the paper's 100 "
                        "and 200 on its maps)")
    p.add_argument("--seed", type=int,
                   help=f"GA methods: random seed, the same seed giving the same plan (default {GA_DEFAULTS['seed']})")
    p.add_argument("--replan-window", type=int, metavar="W",
                   help="GA methods: windowed exact re-planning of ours, each generation a window of up to W executed "
                        "commands of the fastest and of --replan-members random goal-reaching members replaced by the "
                        "minimum-time path between its ends (default 40 in htetro-ga; off (0) in htetro-ga-paper and "
                        "pymoo's algorithms, which take it through their mating when given)")
    p.add_argument("--replan-members", type=int, metavar="K",
                   help="GA methods: random goal-reaching members re-planned each generation besides the fastest "
                        "(default 3)")
    p.add_argument("--reach-patience", type=int, metavar="N",
                   help="htetro-ga: reach repair of ours, when no member has reached the goal and the best goal "
                        "reachability has not risen for N generations, the member nearest to the goal gets the "
                        "minimum-time path to it (default 100; off (0) in htetro-ga-paper)")
    p.add_argument("--polish-window", type=int, metavar="W",
                   help="htetro-ga: balanced polish of ours, when each leg's run ends the largest-sum leading-front "
                        "member has windows of up to W commands of its path (the whole path when it has at most W) "
                        "re-planned exactly for the largest fitness sum (default 40; off (0) in htetro-ga-paper)")
    p.add_argument("--conservative", action="store_true", default=None,
                   help="nsga2, nsga3, smsemoa, agemoea: add the hTetro-GA's conservative offspring set (removal, "
                        "rearrangement, shortcut of every member) to their mating, so that an algorithm swap compares "
                        "algorithms, not operator sets (the hTetro-GA always makes it)")
    p.add_argument("--seed-exact", action="store_true", default=None,
                   help="GA methods: put each leg's exact minimum-time plan into its initial population; the JSON "
                        "then reports the gaps to the exact optimum")
    p.add_argument("--pick", choices=GA_PICKS,
                   help="GA methods: the solution each leg returns, balanced (default: the largest sum of the four "
                        "fitnesses), or the best f_t, f_sm or f_sf")
    p.add_argument("--diagonals", action="store_true", help="dijkstra, astar: allow diagonal translations")
    p.add_argument("--weights", metavar="WT,WSM,WSF",
                   help="heat: weights of time, smoothness and safety (default 1,0,0); continuous ega/ega-paper: "
                        "W_L,W_S,W_R of eq. 6 (default 1,0,0)")
    p.add_argument("--t-max", type=float, metavar="S",
                   help="heat: t_max of f_t in seconds (default: half an O-shape boustrophedon of the empty map)")
    p.add_argument("--element", choices=HEAT_ELEMENTS,
                   help="heat: the field's element, bilinear q1 (default, the paper's) or cell-centred p0")
    p.add_argument("--no-monotone", action="store_true",
                   help="heat: drop the rule that translations never go down the temperature field")
    p.add_argument("--band", metavar="auto|full|R",
                   help="heat: search the whole pose graph (full), or a band of R cells around the field's ascent "
                        "line, widened until a path is found (default auto: full up to 4 million poses, else R 8)")
    p.add_argument("--sensor-range", type=float, metavar="R",
                   help="heat: run in the true world (hidden obstacles), sensing cells within R cells of the blocks "
                        "and replanning when the plan meets a new obstacle (Do et al. 2021: 6)")
    p.add_argument("--path", choices=("linear", "spline"),
                   help="continuous, ega/ega-paper/nsga2: straight between the path bases (default) or a cubic spline")
    p.add_argument("--normalise", action="store_true", default=None,
                   help="continuous, ega/ega-paper: weights from three single-term runs (Nazarahari et al. 2019, §5.3) "
                        "instead of --weights")
    p.add_argument("--safety", choices=("paper", "min"),
                   help="continuous, ega/ega-paper/nsga2: eq. 5's sum of the path bases' clearances (paper; ega "
                        "default) or the smallest clearance along the path (min; nsga2 default)")
    p.add_argument("--grid", type=float, metavar="D",
                   help="continuous, ega/ega-paper/nsga2: the APF lattice and the mutations' step; astar: the lattice "
                        "(default 1)")
    p.add_argument("--robot-radius", metavar="R|SHAPE",
                   help="continuous: the robots' radius instead of the scenario's, a number or a morphology letter "
                        "(the disc around that hTetro footprint, e.g. O)")
    p.add_argument("--time-limit", type=float, metavar="S",
                   help="continuous, rrt: seconds per robot before giving up (default 120, the paper's)")
    p.add_argument("--clearance", type=float, default=0.0, help="clearance δ in cells around every block (default 0)")
    _add_outputs(p, plot="a plot of the map and the path", gif="an animated GIF of the plan, step by step")

    p = sub.add_parser(
        "simulate",
        help="execute a command sequence in a scenario",
        description="Execute a command sequence from the scenario's start in the true world (hidden "
        "obstacles included). 'reached' means the whole sequence is valid, passes through the roadmap's "
        "configurations in order and ends on the goal; 'executed' counts the commands run before the "
        "first invalid one.",
    )
    p.add_argument("scenario", help="bundled scenario name or path to a scenario TOML file")
    p.add_argument("--commands", required=True,
                   help='comma- or space-separated tokens, e.g. "x+,x+,sI"; @FILE reads them from a file, - from stdin')
    p.add_argument("--clearance", type=float, default=0.0, help="clearance δ in cells around every block")
    _add_outputs(p, plot="a plot of the map and the executed path",
                 gif="an animated GIF of the executed commands, step by step")

    p = sub.add_parser(
        "tile",
        help="tile a scenario's free cells with tetrominoes (Le et al. 2018) and label the waypoints",
        description="Tile the free cells of a grid scenario with the robot's tetrominoes and label every "
        "tile's blocks a-d by Algorithm 1 of Le et al. 2018. Writes the labelled tileset (to --out, or prints it).",
    )
    p.add_argument("scenario", help="bundled scenario name or path to a scenario TOML file")
    p.add_argument("--shapes", help="allowed morphologies, e.g. TZ or O (default: all seven, IOLJZST)")
    p.add_argument("--method", choices=TILING_METHODS, default="auto",
                   help="auto (default): backtracking for a few steps, then a compiled sweep repaired by small "
                        "exact covers, then CP-SAT band by band, then region by region; backtracking: the paper's "
                        "search; cpsat: exact cover with OR-Tools CP-SAT")
    p.add_argument("--overlap", action="store_true",
                   help="if the map cannot be tiled, cover it by two overlapping sub-workspaces (the paper's Fig. 5)")
    p.add_argument("--shuffle", action="store_true",
                   help="shuffle the placement order by --seed, for another tiling (default: the fixed order)")
    p.add_argument("--seed", type=int, help="with --shuffle: its random seed (default 0)")
    p.add_argument("--time-limit", type=float, default=TILING_TIME_LIMIT,
                   help=f"give up after this many seconds (default {TILING_TIME_LIMIT:g})")
    p.add_argument("--out", metavar="FILE", help="write the labelled tileset to FILE")
    _add_outputs(p, plot="a plot of the tileset")

    p = sub.add_parser(
        "sequence",
        help="order a tileset's waypoints (the TSP of Le et al. 2018) or a TSPLIB instance with one method",
        description="Order the waypoints of a labelled tileset as an open path from a start tile, "
        "minimising the eq.-2 cost (weighted displacement of the blocks a-d). TILESET is a labelled "
        "tileset (bundled name or file) or a scenario, which is tiled first, or a TSPLIB file (.tsp, .atsp), "
        "whose nodes are ordered as a closed tour by default, priced under TSPLIB's rounding.",
    )
    p.add_argument("tileset", metavar="TILESET",
                   help="labelled tileset (bundled name or file), scenario (name or .toml) or TSPLIB file (.tsp)")
    p.add_argument("--method", choices=SEQUENCE_METHODS, default="auto",
                   help="auto (default): exact up to 40 waypoints, local beyond ("
                        "ortools for asymmetric costs); ga: the paper's GA "
                        "on DEAP with a 2-opt/Or-opt step (ga-plain: without); ortools: routing with "
                        "guided local search; exact: CP-SAT optimum (<= 40 waypoints); local: nearest "
                        "neighbour + 2-opt/Or-opt; zigzag, zigzag2, spiral, spiral2, greedy: the paper's baselines; "
                        "fast-tsp: the fast-tsp package (optional, MIT); lkh: LKH-3 through the elkai package "
                        "(optional; non-commercial use only)")
    p.add_argument("--start", default="1", help="label of the start tile or TSPLIB node (default 1), or 'free'")
    p.add_argument("--end", help="open paths: label of the tile or TSPLIB node the order ends at (default: free)")
    tour = p.add_mutually_exclusive_group()
    tour.add_argument("--closed", action="store_true",
                      help="a closed tour, back to the start (the default for TSPLIB files)")
    tour.add_argument("--open", action="store_true", help="an open path (the default for tilesets)")
    p.add_argument("--weights", help="tilesets: eq. 2's weights α,β,λ,γ of blocks a,b,c,d (default 0.25 each)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0; deterministic methods ignore it)")
    p.add_argument("--time-limit", type=float,
                   help=f"time budget in seconds; by default, sized to the instance: {TIME_LIMIT_TEXT}")
    p.add_argument("--restarts", type=int,
                   help="local (and auto when it runs local): kicks of the iterated local search (default 0)")
    p.add_argument("--runs", type=int, help="lkh: LKH's independent runs, the best kept (default 1)")
    p.add_argument("--shapes", help="when TILESET is a scenario: allowed morphologies for the tiling")
    _add_outputs(p, plot="a plot of the tileset and the order")
    p = sub.add_parser(
        "study",
        help="run a study (scenarios x methods x seeds) and summarise it",
        description="Run a study: a bundled one by name (small, table4, sequencing) or a study TOML file "
        "(task, scenarios, seeds, [[methods]] with the command's options), every trial recorded to "
        "DIR/NAME.jsonl as it ends, then summarised per scenario and method (mean, std, median, success "
        "rate, gap to the exact reference). 'le2018' re-runs the tables of Le et al. 2018 beside the paper's; "
        "'do2021' those of Do et al. 2021 (Tables 6-8, Fig. 13; DIR/do2021.md and .csv hold its report); "
        "'cheng2019' those of Cheng et al. 2019 (Table 2, the 16 x 7 map, baselines and larger maps, every "
        "coverage plan beside its lower bound; DIR/cheng2019.md and .csv hold its report); 'nazarahari2019' "
        "those of Nazarahari et al. 2019 (Table 2, the (IS, PS) pairs, normalised weights, four robots, every "
        "length beside the exact optimum; in this process; DIR/nazarahari2019.md and .csv).",
    )
    p.add_argument("study", metavar="NAME|FILE",
                   help="a bundled study name, cheng2019, do2021, le2018, nazarahari2019, or a study TOML file")
    p.add_argument("--executor", choices=("serial", "processes", "dask"), default="processes",
                   help="where trials run: this process, local worker processes (default), or a Dask cluster")
    p.add_argument("--workers", type=int, help="processes / dask: number of workers (default: the local cores)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="dask: join an existing cluster at tcp://HOST:PORT (default: start a local one)")
    p.add_argument("--seeds", type=int, help="run seeds 0 … N−1 instead of the study's own")
    p.add_argument("--out", metavar="DIR", help="write DIR/NAME.jsonl (every trial), DIR/NAME.csv and DIR/NAME.md")
    p.add_argument("--resume", action="store_true", help="skip the trials already recorded in DIR/NAME.jsonl")
    p.add_argument("--retries", type=int, default=0, help="re-run a failing trial up to N times (default 0)")
    p.add_argument("--time-limit", type=float,
                   help="le2018 only: cap in seconds for each method that takes one (a study file sets its own)")
    p.add_argument("--figures", action="store_true",
                   help="cheng2019 only: also save the paper's Figs. 8b, 14 and 15 redrawn as PNGs in DIR (needs --out)")
    _add_outputs(p, json="print one JSON object instead of the summary table")

    p = sub.add_parser(
        "cover",
        help="plan complete coverage of a scenario (Cheng et al. 2019)",
        description="Plan commands (Cheng et al. 2019's 13) that cover every free cell the robot can cover in the "
        "allowed morphology layers: stripes of rows cut into regions, each searched for its cheapest covering walk, "
        "joined by one auxiliary DAG; or a baseline (a one-layer boustrophedon, tiling + TSP). Cells no allowed pose "
        "covers are reported.",
    )
    p.add_argument("scenario", help="bundled scenario name or path to a scenario TOML file")
    p.add_argument("--method", choices=("stripes", "stripes-paper", "boustrophedon", "tiling-tsp"), default="stripes",
                   help="stripes (default): the paper's stripes, regions and auxiliary DAG; stripes-paper: its Alg. 5 "
                        "as written (simple paths, cuts at forced poses); boustrophedon: lanes in the first layer; "
                        "tiling-tsp: tile with the shapes, order the tiles, drive through them (baselines)")
    p.add_argument("--shapes", default="O,vI,hI",
                   help="morphology layers: O, vI, hI or SHAPE@H, comma-separated (default O,vI,hI)")
    p.add_argument("--stripes", default="4",
                   help="stripe width W (H // W bands, the last taking the remainder) or widths bottom up, e.g. "
                        "2,3,2 (default 4)")
    p.add_argument("--region-columns", type=int, default=4, help="columns of a region (default 4)")
    p.add_argument("--budget", type=int, default=20_000,
                   help="search nodes per region before its greedy walk is taken (default 20000)")
    p.add_argument("--ends", choices=("sweep", "both"), default="sweep",
                   help="stripe methods: leave a stripe at its sweep's far end (sweep, default) or at either end "
                        "(both: every stripe swept either way, or out and back; never costlier)")
    p.add_argument("--start", choices=("scenario", "auto"), default="scenario",
                   help="scenario (default): the roadmap's first pose as start and last as goal (auto when the "
                        "scenario has none); auto: the bottom-left pose of the first layer, a free end")
    p.add_argument("--clearance", type=float, default=0.0, help="clearance δ in cells around every block (default 0)")
    p.add_argument("--time-limit", type=float,
                   help="seconds; past them the remaining regions take their greedy walk (default: none)")
    _add_outputs(p, plot="a plot of the map, the stripes, the regions and the plan (the paper's Figs. 14a, 15a)")
    p.add_argument("--coverage-plot", metavar="FILE",
                   help="save the pixel coverage times and their histogram (the paper's Figs. 14b-c, 15b-c)")
    return parser


class _LateOutputError(Exception):
    """An output file failed after the work was done: the command's result is still printed."""

    def __init__(self, out: dict, error: HtetroError) -> None:
        super().__init__(str(error))
        self.out, self.error = out, error


def _late(out: dict, write) -> None:
    """Run one output write; if it fails, carry the finished result along with the error."""
    try:
        write()
    except OutputError as err:
        raise _LateOutputError(out, err) from err


def _stderr_is_terminal() -> bool:
    return sys.stderr.isatty()


def _console(args) -> Console:
    """Progress bars on stderr: on a terminal, unless ``--quiet``."""
    return Console(enabled=not getattr(args, "quiet", False) and _stderr_is_terminal())


def _files_only_backend() -> None:
    """The command line only writes files: matplotlib's Agg, never a window (and no display needed)."""
    import matplotlib

    matplotlib.use("Agg")


def _save_plot(console: Console, figure_of, path: str) -> None:
    """Draw (``figure_of()``) and save a plot, showing progress: long paths take a while."""
    _files_only_backend()
    from htetro_opt.viz import save_figure

    with console.step(f"plotting {path}"):
        save_figure(figure_of(), path)


def _save_gif(console: Console, workspace, commands, start, *, roadmap, hidden, title: str, path: str) -> None:
    """Animate the commands from ``start`` and save the GIF, showing progress."""
    _files_only_backend()
    from htetro_opt.viz import animate_path, save_gif

    with console.step(f"animating {path}"):
        save_gif(animate_path(workspace, commands, start, roadmap=roadmap, hidden=hidden, title=title), path)


def _grid_scenario(name: str) -> Scenario:
    scenario = load_scenario(name)
    if not isinstance(scenario, Scenario):
        raise ScenarioError(f"scenario {scenario.name!r} is continuous; this command needs a grid scenario")
    return scenario


def _pose_dict(row) -> dict:
    x, y, s, h = (int(v) for v in row)
    return {"x": x, "y": y, "shape": STATE_NAMES[s], "heading": h}


def _cli_time_limit(value: float | None) -> float | None:
    """``--time-limit``: absent (the method's default) or a positive, finite number of seconds."""
    if value is None:
        return None
    return check_real(value, "--time-limit (seconds)", minimum=0.0, include_minimum=False, maximum=MAX_TIME_LIMIT)


def _check_clearance(value: float) -> float:
    return check_real(value, "--clearance (cells)", minimum=0.0, maximum=10.0, include_maximum=False)


def _outputs(args, *names: tuple[str, str]) -> None:
    """Check every output path of a command before any work starts."""
    for attribute, what in names:
        if getattr(args, attribute, None):
            check_output_path(getattr(args, attribute), what=what)
    if getattr(args, "plot", None):
        from htetro_opt.viz import figure_format

        figure_format(args.plot)
    if getattr(args, "gif", None) and not str(args.gif).lower().endswith(".gif"):
        raise ParameterError(f"--gif {args.gif!r}: the animation is a GIF, name the file *.gif")


def _cmd_scenarios(args) -> dict:
    rows = []
    for name in list_scenarios():
        sc = load_scenario(name)
        if isinstance(sc, Scenario):
            rows.append({"name": name, "size": [sc.workspace.width, sc.workspace.height],
                         "roadmap": len(sc.roadmap), "moving": len(sc.workspace.moving), "source": sc.source})
        else:
            rows.append({"name": name, "size": [sc.width, sc.height], "roadmap": 0, "moving": 0, "source": sc.source})
    tilesets = []
    for name in list_tilesets():
        ts = load_tileset(tileset_path(name))
        tilesets.append({"name": name, "size": [ts.width, ts.height], "tiles": len(ts),
                         "source": "Le et al., Electronics 2018: the paper's labelled tileset"})
    if not args.json:
        width = max((len(r["name"]) for r in rows + tilesets), default=4)
        for r in rows:
            size = "x".join(str(v) for v in r["size"])
            print(f"{r['name']:<{width}}  {size:>9}  {r['source']}")
        if tilesets:
            print("\nlabelled tilesets (for 'sequence'):")
        for r in tilesets:
            size = "x".join(str(v) for v in r["size"])
            print(f"{r['name']:<{width}}  {size:>9}  {r['tiles']} tiles, {r['source']}")
    return {"scenarios": rows, "tilesets": tilesets}


CONTINUOUS_ONLY_METHODS = ("ega", "ega-paper", "exact", "prm", "rrt", "pso")
"""``plan --method`` names for continuous scenarios only (``astar`` and ``nsga2`` plan both kinds)."""
_CONTINUOUS_METHODS = ("ega", "ega-paper", "nsga2", "exact", "astar", "prm", "rrt", "pso")
_CONTINUOUS_FLAGS = {"path": "--path", "normalise": "--normalise", "safety": "--safety", "grid": "--grid",
                     "robot_radius": "--robot-radius", "time_limit": "--time-limit"}
_GRID_FLAGS = {"patience": "--patience", "converge": "--converge", "max_length": "--max-length",
               "replan_window": "--replan-window", "replan_members": "--replan-members", "seed_exact": "--seed-exact",
               "reach_patience": "--reach-patience", "polish_window": "--polish-window",
               "conservative": "--conservative",
               "pick": "--pick", "diagonals": "--diagonals", "t_max": "--t-max", "element": "--element",
               "no_monotone": "--no-monotone", "band": "--band", "sensor_range": "--sensor-range", "gif": "--gif"}


def _only_for(args, flags: dict, where: str) -> None:
    """Refuse the options of ``flags`` (attribute → flag) that were given: they apply ``where`` only."""
    given = [flag for name, flag in flags.items() if getattr(args, name, None) not in (None, False)]
    if given:
        raise ParameterError(f"{', '.join(given)} {'applies' if len(given) == 1 else 'apply'} to {where} only")


def _continuous_weights(text: str) -> tuple[float, float, float]:
    """``--weights W_L,W_S,W_R`` of eq. 6, each error naming the option."""
    from htetro_opt.problems import check_path_weights

    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        raise ParameterError(f"--weights must be three comma-separated numbers W_L,W_S,W_R, got {text!r}") from None
    return check_path_weights(values, "--weights")


def _cmd_plan_continuous(scenario, args) -> dict:
    """``plan`` on a continuous scenario: one of :data:`_CONTINUOUS_METHODS`, every robot."""
    from htetro_opt.solvers.continuous import plan_continuous

    _only_for(args, _GRID_FLAGS, "grid scenarios")
    if args.clearance:
        raise ParameterError("--clearance applies to grid scenarios only (give a continuous scenario's robots "
                             "a --robot-radius)")
    method = args.method or "ega"
    if method not in _CONTINUOUS_METHODS:
        raise ParameterError(f"--method {method} plans grid scenarios; {scenario.name!r} is continuous: use one of "
                             f"{', '.join(_CONTINUOUS_METHODS)}")
    _outputs(args, ("plot", "plot"))
    if args.robot_radius is not None:
        try:
            radius = float(args.robot_radius)
        except ValueError:
            radius = args.robot_radius  # a morphology letter
        scenario = scenario.with_robot_radius(radius)
    genetic = method in ("ega", "ega-paper", "nsga2")
    options = {}
    if args.grid is not None:
        options["grid"] = check_real(args.grid, "--grid", minimum=0.0, include_minimum=False,
                                     maximum=min(scenario.width, scenario.height) / 2)
    if args.time_limit is not None:
        if method != "rrt":
            raise ParameterError(f"--time-limit applies to --method rrt only, not to --method {method}")
        options["time_limit"] = _cli_time_limit(args.time_limit)
    ga_only = {"path": "--path", "safety": "--safety", "weights": "--weights", "normalise": "--normalise"}
    if method in ("prm", "rrt", "pso"):  # the paper's seeded baselines, each robot alone
        _only_for(args, ga_only, "the GA methods (ega, ega-paper, nsga2)")
        options["seed"] = check_int(0 if args.seed is None else args.seed, "--seed", minimum=0)
        if method == "pso":
            options.update(pop_size=check_int(10 if args.pop_size is None else args.pop_size, "--pop-size", minimum=2),
                           max_gen=check_int(20 if args.max_gen is None else args.max_gen, "--max-gen", minimum=0))
        else:
            _only_for(args, {"pop_size": "--pop-size", "max_gen": "--max-gen"}, "the GA methods and pso")
            if args.grid is not None:
                raise ParameterError(f"--grid applies to --method astar, pso and the GA methods, not to {method}")
    elif genetic:
        options.update(pop_size=check_int(10 if args.pop_size is None else args.pop_size, "--pop-size", minimum=2),
                       max_gen=check_int(20 if args.max_gen is None else args.max_gen, "--max-gen", minimum=0),
                       seed=check_int(0 if args.seed is None else args.seed, "--seed", minimum=0))
        for name in ("path", "safety"):
            if getattr(args, name) is not None:
                options[name] = getattr(args, name)
        if method != "nsga2":
            if args.weights is not None and args.normalise:
                raise ParameterError("give --weights or --normalise, not both")
            if args.weights is not None:
                options["weights"] = _continuous_weights(args.weights)
            options["normalise"] = bool(args.normalise)
        else:
            _only_for(args, {"weights": "--weights", "normalise": "--normalise"}, "--method ega and ega-paper")
    else:
        given = {"pop_size": "--pop-size", "max_gen": "--max-gen", "seed": "--seed", "path": "--path",
                 "safety": "--safety", "weights": "--weights", "normalise": "--normalise"}
        _only_for(args, given, "the GA methods (ega, ega-paper, nsga2)")
        if method == "exact" and args.grid is not None:
            raise ParameterError("--grid applies to --method astar and the GA methods, not to exact")
    console = _console(args)
    with console.step(f"planning ({method})"):
        plan = plan_continuous(scenario, method=method, **options)
    out = plan.as_dict()
    out["runtime_s"] = round(plan.runtime_s, 6)
    if method == "nsga2":
        out["front"] = out["info"].pop("front")
    if args.plot:
        from htetro_opt.viz import plot_continuous

        status = "reached" if plan.reached else "NOT reached"
        title = f"{scenario.name}: {method}, length {plan.length:.2f}, {status}"
        _late(out, lambda: _save_plot(console, lambda: plot_continuous(scenario, plan, title=title), args.plot))
    if not args.json:
        status = "reached" if plan.reached else "NOT reached: " + ", ".join(
            f"robot {k}" for k, ok in enumerate(plan.robots_reached) if not ok)
        closest = "" if plan.min_robot_distance is None else (
            f"; closest approach {plan.min_robot_distance:.3f} (d_s {plan.safety_distance:g}, "
            f"{len(plan.conflicts)} conflict(s))")
        print(f"{scenario.name}: {status} ({method}, {plan.runtime_s:.3f} s); length {plan.length:.3f}, "
              f"smoothness {np.nansum(plan.smoothness_deg):.1f} deg{closest}")
    return out


def _cmd_plan(args) -> dict:
    scenario = load_scenario(args.scenario)
    if not isinstance(scenario, Scenario):  # Nazarahari et al. 2019's continuous workspaces
        return _cmd_plan_continuous(scenario, args)
    _only_for(args, _CONTINUOUS_FLAGS, "continuous scenarios")
    if args.method in CONTINUOUS_ONLY_METHODS:
        raise ParameterError(f"--method {args.method} plans continuous scenarios; {scenario.name!r} is a grid scenario")
    args.method = args.method or "dijkstra"
    clearance = _check_clearance(args.clearance)
    _outputs(args, ("plot", "plot"), ("gif", "animation"))
    if scenario.goal is None:
        raise PlanningError(f"scenario {scenario.name!r} has no roadmap with a start and a goal to plan for")
    heat = args.method == "heat"
    genetic = args.method not in EXACT_METHODS and not heat
    given = {name: getattr(args, name) for name in GA_DEFAULTS if getattr(args, name) is not None}
    heat_given = [flag for flag, value in (("--weights", args.weights), ("--t-max", args.t_max),
                                           ("--element", args.element), ("--no-monotone", args.no_monotone),
                                           ("--band", args.band), ("--sensor-range", args.sensor_range))
                  if value is not None and value is not False]
    if heat_given and not heat:
        raise ParameterError(f"{', '.join(heat_given)} applies to --method heat only")
    if heat:
        if given or args.diagonals:
            flags = [("--" + name.replace("_", "-")) for name in given] + (["--diagonals"] if args.diagonals else [])
            raise ParameterError(f"{', '.join(flags)} does not apply to --method heat (its commands include the "
                                 "diagonals; it has no population or randomness)")
        options = dict(weights=_heat_weights(args.weights), monotone=not args.no_monotone)
        if args.t_max is not None:
            options["t_max"] = check_real(args.t_max, "--t-max (seconds)", minimum=0.0, include_minimum=False)
        if args.element:
            options["element"] = args.element
        if args.band is not None:
            options["band"] = args.band if args.band in ("auto", "full") else _band_radius(args.band)
        if args.sensor_range is not None:
            check_real(args.sensor_range, "--sensor-range (cells)", minimum=0.0, include_minimum=False)
        if args.plot:
            options["keep_fields"] = True
    elif genetic:
        if args.diagonals:
            raise ParameterError(f"--diagonals is not available with --method {args.method} "
                                 "(the command chromosomes of Cheng et al. 2020 have no diagonal commands)")
        for name, default in GA_DEFAULTS.items():
            setattr(args, name, given.get(name, default))
        options = dict(pop_size=check_int(args.pop_size, "--pop-size", minimum=2),
                       max_gen=check_int(args.max_gen, "--max-gen", minimum=1),
                       patience=check_int(args.patience, "--patience", minimum=1, allow_none=True),
                       convergence=args.converge,
                       max_length=check_int(args.max_length, "--max-length", minimum=1, allow_none=True),
                       seed=check_int(args.seed, "--seed", minimum=0),
                       seed_exact=bool(args.seed_exact), pick=args.pick)
        for name in ("replan_window", "replan_members", "reach_patience", "polish_window"):  # None: the default
            if getattr(args, name) is not None:
                options[name] = check_int(getattr(args, name), "--" + name.replace("_", "-"), minimum=0)
        for name in ("reach_patience", "polish_window"):  # the hTetro-GA's own steps, named by their flag
            if options.get(name) and not args.method.startswith("htetro-ga"):
                raise ParameterError(f"--{name.replace('_', '-')} applies to the hTetro-GA (htetro-ga, htetro-ga-paper), "
                                     f"not to --method {args.method}")
        if args.conservative:
            if args.method.startswith("htetro-ga"):
                raise ParameterError(f"--conservative applies to pymoo's algorithms (nsga2, nsga3, smsemoa, agemoea), "
                                     f"not to --method {args.method}, which always makes the conservative offspring set")
            options["conservative"] = True
    else:
        if given:
            flags = ", ".join("--" + name.replace("_", "-") for name in given)
            raise ParameterError(f"{flags} applies to the GA methods only, not to --method {args.method} "
                                 "(an exact method has no population, generations or randomness)")
        options = dict(diagonals=args.diagonals)
    console = _console(args)
    with console.step(f"planning ({args.method})", options.get("max_gen"), "generations") as progress:
        if genetic:
            options["progress"] = progress
        if heat and args.sensor_range is not None:
            plan, run = _replanned(scenario, args.sensor_range, clearance, options)
        else:
            plan, run = plan_path(scenario.workspace, scenario.roadmap, method=args.method, clearance=clearance,
                                  **options), None
    out = {
        "scenario": scenario.name,
        "method": plan.method,
        "reached": plan.reached,
        "commands": plan.tokens,
        "time": plan.time,
        "objectives": plan.objectives(),
        "runtime_s": round(plan.runtime_s, 6),
    }
    if genetic:
        out.update(_ga_fields(plan, args))
    if heat:
        out.update({key: plan.info[key] for key in ("fitness", "weights", "t_max", "relaxed", "surrogate", "band", "field")
                    if key in plan.info})
        if run is not None:
            record = run.as_dict()
            out.update({key: record[key] for key in ("sensor_range", "plans", "replans")})
    if args.plot:
        from htetro_opt.viz import plot_ga_plan, plot_path

        method = f"{args.method} (n_pop {args.pop_size}, seed {args.seed})" if genetic else args.method
        status = "reached" if plan.reached else f"goal NOT reached (leg {plan.failed_leg + 1} {'not solved' if genetic else 'has no path'})"
        title = f"{scenario.name}: {method}, time {plan.time:g} s, {len(plan.tokens)} commands, {status}"
        if genetic:
            def figure():
                return plot_ga_plan(scenario.workspace, plan, roadmap=scenario.roadmap, hidden=scenario.hidden,
                                    title=title)
        elif heat and plan.info.get("fields"):
            from htetro_opt.viz import plot_heat_plan

            def figure():
                return plot_heat_plan(scenario.workspace, plan, plan.info["fields"],
                                      replans=run.replans if run is not None else None, roadmap=scenario.roadmap,
                                      hidden=scenario.hidden, title=title)
        else:
            def figure():
                return plot_path(scenario.workspace, plan.poses, roadmap=scenario.roadmap, hidden=scenario.hidden,
                                 title=title)
        _late(out, lambda: _save_plot(console, figure, args.plot))
    if args.gif:
        title = f"{scenario.name}: {plan.method}, time {plan.time:g} s"
        _late(out, lambda: _save_gif(console, scenario.workspace, plan.commands, scenario.roadmap[0],
                                     roadmap=scenario.roadmap, hidden=scenario.hidden, title=title, path=args.gif))
    if not args.json:
        legs = len(scenario.roadmap) - 1
        failure = "was not solved" if genetic else "has no path"
        status = "reached" if plan.reached else f"NOT reached: leg {plan.failed_leg + 1} of {legs} {failure}"
        print(f"{scenario.name}: {status} ({plan.method}, {plan.runtime_s:.3f} s); time {plan.time:g} s, "
              f"{len(plan.tokens)} commands")
        if genetic:
            fitness = ", ".join(f"{k} {v:.3f}" for k, v in out["fitness"].items())
            first = out["reach_generation"]
            print(f"generations {out['generations']}, goal first reached "
                  f"{'in generation ' + str(first) if first is not None else 'in no generation'}; "
                  f"{'multi-objective' if args.pick == 'balanced' else args.pick} solution: {fitness}; "
                  f"leading front: {len(out['front'])} members")
            if "gap" in out:
                print(f"gap to the exact optimum ({out['gap']['exact']:g} s): {args.pick} {out['gap']['picked']:.1%}, "
                      f"fastest {out['gap']['fastest']:.1%}")
        if plan.tokens:
            print(" ".join(plan.tokens))
    return out


def _ga_fields(plan, args) -> dict:
    """The GA's extra JSON fields: the last leg's front, every leg's record, and with --seed-exact the
    gaps of the returned plan and of the legs' fastest members to the exact optimum."""
    from htetro_opt.algorithms import PICKS
    legs = [
        {
            "start": leg.start.as_dict(),
            "goal": leg.goal.as_dict(),
            "reached": leg.reached,
            "reach_generation": leg.reach_generation,
            "generations": leg.generations,
            "converged": leg.converged,
            "runtime_s": round(leg.runtime_s, 6),
            "selected": {name: member.as_dict() for name, member in leg.selected.items()},
            "front": [member.as_dict() for member in leg.front],
        }
        for leg in plan.legs
    ]
    fitness = np.mean([leg.selected[PICKS[args.pick]].fitness for leg in plan.legs], axis=0)
    out = {
        "pop_size": args.pop_size,
        "seed": args.seed,
        "pick": args.pick,
        "reach_generation": plan.reach_generation,
        "generations": sum(leg.generations for leg in plan.legs),
        "fitness": {name: float(v) for name, v in zip(FITNESS_NAMES, fitness)},
        "front": legs[-1]["front"],
        "legs": legs,
    }
    exact = plan.info.get("exact_times")
    if exact is not None and plan.reached and None not in exact and sum(exact) > 0:
        # each leg's optimum from where and when the returned plan starts it
        fastest = sum(leg.selected["time"].time for leg in plan.legs)
        out["gap"] = {"exact": float(sum(exact)), "picked": (plan.time - sum(exact)) / sum(exact),
                      "fastest": (fastest - sum(exact)) / sum(exact)}
    return out


def _cmd_simulate(args) -> dict:
    scenario = _grid_scenario(args.scenario)
    clearance = _check_clearance(args.clearance)
    _outputs(args, ("plot", "plot"), ("gif", "animation"))
    if scenario.start is None:
        raise PlanningError(f"scenario {scenario.name!r} has no start configuration to simulate from")
    text = _commands_text(args.commands)
    sequence = parse_commands(text)
    used = sorted(set(SEED000_COMMANDS) | set(DIAGONAL_COMMANDS) | {t for t in text.replace(",", " ").split()})
    world = scenario.true_workspace()
    sim = Simulator(world, commands=used, clearance=clearance)
    result = sim.run([sequence], scenario.start, roadmap=scenario.roadmap[1:])
    first_invalid = int(result.first_invalid[0])
    out = {
        "scenario": scenario.name,
        "valid": bool(result.valid[0]),
        "reached": bool(result.valid[0] and result.reached[0]),
        "executed": int(result.executed[0]),
        "first_invalid": None if first_invalid < 0 else first_invalid,
        "final": _pose_dict(result.final[0]),
        "time": float(result.time[0]),
    }
    if args.plot:
        from htetro_opt.viz import plot_path

        state = "valid" if out["valid"] else f"invalid at command index {first_invalid} (0-based)"
        title = f"{scenario.name}: {out['executed']} of {len(sequence)} commands executed ({state})"
        _late(out, lambda: _save_plot(_console(args), lambda: plot_path(
            world, result.poses(0), roadmap=scenario.roadmap, hidden=scenario.hidden, title=title), args.plot))
    if args.gif:  # the executed prefix: an invalid command is where the run stopped
        title = f"{scenario.name}: {out['executed']} of {len(sequence)} commands executed"
        _late(out, lambda: _save_gif(_console(args), world, result.prefix(0), scenario.start, roadmap=scenario.roadmap,
                                     hidden=scenario.hidden, title=title, path=args.gif))
    if not args.json:
        f = out["final"]
        print(f"{'valid' if out['valid'] else f'INVALID at command index {first_invalid} (0-based)'}; "
              f"executed {out['executed']} of {len(sequence)}; reached: {out['reached']}; "
              f"final ({f['x']}, {f['y']}) {f['shape']} heading {f['heading']}; time {out['time']:g} s")
    return out


def _tileset_of_scenario(name: str, *, shapes, method="backtracking", shuffle=False, seed=None,
                         time_limit=TILING_TIME_LIMIT, overlap=False):
    scenario = _grid_scenario(name)
    return tile_workspace(scenario.workspace, shapes=shapes, method=method, shuffle=shuffle, seed=seed,
                          time_limit=time_limit, overlap=overlap, name=scenario.name)


def _cmd_tile(args) -> dict:
    time_limit = _cli_time_limit(args.time_limit)
    if args.seed is not None and not args.shuffle:
        raise ParameterError("--seed applies only with --shuffle (without it the tiling is the same every time)")
    seed = check_int(0 if args.seed is None else args.seed, "--seed", minimum=0)
    _outputs(args, ("out", "tileset"), ("plot", "plot"))
    shapes = list(args.shapes) if args.shapes else None
    console = _console(args)
    began = time.perf_counter()
    with console.step(f"tiling ({args.method})"):
        tileset = _tileset_of_scenario(args.scenario, shapes=shapes, method=args.method, shuffle=args.shuffle,
                                       seed=seed, time_limit=time_limit, overlap=args.overlap)
    runtime = time.perf_counter() - began
    counts = {shape: tileset.shapes.count(shape) for shape in sorted(set(tileset.shapes))}
    out = {"scenario": tileset.name, "method": args.method, "tiles": len(tileset), "shapes": counts,
           "overlapping": tileset.overlapping, "runtime_s": round(runtime, 6), "out": args.out}
    if args.plot:  # before the tileset file: a failed plot leaves no tileset written either
        from htetro_opt.viz import plot_tileset

        title = f"{tileset.name}: {len(tileset)} tiles ({args.method})"
        _late(out, lambda: _save_plot(console, lambda: plot_tileset(tileset, title=title), args.plot))
    if args.out:
        try:
            _late(out, lambda: save_tileset(tileset, args.out))
        except _LateOutputError:
            if args.plot:  # a failed command leaves no output behind
                os.unlink(args.plot)
            raise
    if args.json:
        if not args.out:
            out["tileset"] = format_tileset(tileset)
    elif args.out:
        print(f"{tileset.name}: {len(tileset)} tiles in {runtime:.3f} s "
              f"({', '.join(f'{k} {v}' for k, v in counts.items())}); written to {args.out}")
    else:
        print(format_tileset(tileset))
    return out


def _band_radius(text: str) -> int:
    """``--band R``: a radius in cells (``auto`` and ``full`` are taken before)."""
    try:
        return check_int(int(text), "--band radius", minimum=1)
    except ValueError:
        raise ParameterError(f"--band must be auto, full or a radius in cells (an integer >= 1), got {text!r}") from None


def _replanned(scenario, sensor_range: float, clearance: float, options: dict):
    """Do et al. 2021's run in the true world, replanning on what the robot senses, as a plan (its
    executed commands) and the run itself."""
    from htetro_opt.solvers.grid_paths import Plan, replan_heat

    run = replan_heat(scenario, sensor_range=sensor_range, clearance=clearance, **options)
    plan = Plan(method="heat (replanning)", commands=run.executed, reached=run.reached, time=run.time,
                poses=run.poses, leg_ends=(len(run.executed),) if run.reached else (),
                failed_leg=-1 if run.reached else 0, runtime_s=run.runtime_s,
                info={"fitness": run.fitness, "weights": run.info["weights"], "t_max": run.info["t_max"],
                      "fields": run.fields})
    return plan, run


def _heat_weights(text: str | None) -> tuple[float, float, float]:
    """``--weights WT,WSM,WSF`` of the heat planner (Do et al. 2021's eq. 12)."""
    from htetro_opt.problems import check_heat_weights

    return (1.0, 0.0, 0.0) if text is None else check_heat_weights(text, "--weights")


def _weights(text: str) -> np.ndarray:
    """``--weights a,b,c,d`` as eq. 2's weights, each error naming the option."""
    parts = [v.strip() for v in text.split(",")]
    try:
        values = [float(v) for v in parts]
    except ValueError:
        raise ParameterError(f"--weights must be four comma-separated numbers a,b,c,d, got {text!r}") from None
    if len(values) != 4:
        raise ParameterError(f"--weights must be four comma-separated numbers a,b,c,d, got {len(values)}: {text!r}")
    if not all(0 <= v <= 1e6 for v in values) or sum(values) <= 0:  # huge weights overflow the costs
        raise ParameterError(f"--weights must be numbers in [0, 1e6] with a positive sum, got {text!r}")
    return check_weights(values)


def _commands_text(argument: str) -> str:
    """``--commands``: the tokens themselves, ``@FILE`` for a file of them, or ``-`` for stdin
    (a long sequence does not fit on a command line)."""
    if argument == "-":
        return sys.stdin.read()
    if argument.startswith("@"):
        path = Path(argument[1:])
        try:
            return path.read_text(encoding="utf-8-sig")
        except (OSError, UnicodeDecodeError) as err:
            raise ParameterError(f"--commands {argument}: cannot read {str(path)!r}: "
                                 f"{getattr(err, 'strerror', None) or err}") from err
    return argument


def _is_scenario(name: str) -> bool:
    if name.endswith(".toml"):
        return True
    if name in list_tilesets():
        return False
    return name in list_scenarios()


def _is_tsplib(name: str) -> bool:
    return name.lower().endswith((".tsp", ".atsp"))


def _label(text: str | None, flag: str, *, free: bool) -> int | None:
    """``--start`` / ``--end``: a tile or node label, or 'free'."""
    if text is None or (free and text == "free"):
        return None
    try:
        return int(text)
    except ValueError as err:
        raise ParameterError(f"{flag} must be a tile label{' or ' + repr('free') if free else ''}, got {text!r}") from err


def _index_of(label: int | None, ids, flag: str, what: str) -> int | None:
    if label is None:
        return None
    try:
        return list(ids).index(label)
    except ValueError:
        raise ParameterError(f"{flag} {label}: there is no {what} {label}") from None


def _sequence_options(args, instance) -> dict:
    """``--restarts`` and ``--runs``, each only for the method that has it."""
    from htetro_opt.solvers.sequencing import auto_method

    options = {}
    runs = auto_method(instance) if args.method == "auto" else args.method
    if args.restarts is not None:
        if runs != "local":
            raise ParameterError(f"--restarts applies to --method local (auto runs it above 40 waypoints); "
                                 f"here the method is {runs}")
        options["restarts"] = check_int(args.restarts, "--restarts", minimum=0)
    if args.runs is not None:
        if runs != "lkh":
            raise ParameterError(f"--runs applies to --method lkh; here the method is {runs}")
        options["runs"] = check_int(args.runs, "--runs", minimum=1)
    return options


def _cmd_sequence(args) -> dict:
    time_limit = _cli_time_limit(args.time_limit)
    seed = check_int(args.seed, "--seed", minimum=0)
    _outputs(args, ("plot", "plot"))
    start = _label(args.start, "--start", free=True)
    end = _label(args.end, "--end", free=False)
    console = _console(args)
    if _is_tsplib(args.tileset):
        return _sequence_tsplib(args, console, start=start, end=end, time_limit=time_limit, seed=seed)
    weights = _weights(args.weights or "0.25,0.25,0.25,0.25")
    if _is_scenario(args.tileset):
        scenario_path(args.tileset)  # a clear error for a missing file
        with console.step("tiling (backtracking)"):
            tileset = _tileset_of_scenario(args.tileset, shapes=list(args.shapes) if args.shapes else None)
        name = tileset.name
    else:
        if args.shapes:
            raise ParameterError("--shapes applies only when TILESET is a scenario to tile")
        tileset = load_tileset(tileset_path(args.tileset))
        name = Path(args.tileset).stem  # the name the user gave, never an install path
    instance = SequencingInstance.from_tileset(tileset, start=start, weights=weights)
    if args.closed or end is not None:
        instance = replace(instance, closed=args.closed,  # keeps an implicit instance's weights
                           end=_index_of(end, instance.ids, "--end", "tile"))
    options = _sequence_options(args, instance)
    with console.step(f"sequencing {instance.n} waypoints ({args.method})") as progress:
        result = sequence_waypoints(instance, method=args.method, seed=seed, time_limit=time_limit, progress=progress,
                                    **options)
    out = {"tileset": name, "waypoints": instance.n, "start": args.start, "weights": weights.tolist(),
           **({"closed": True} if args.closed else {}), **({"end": args.end} if end is not None else {}),
           **result.as_dict()}
    if args.plot:
        from htetro_opt.viz import plot_tileset

        title = f"{name}: {result.method}, cost {result.cost:.3f} cells"
        _late(out, lambda: _save_plot(console, lambda: plot_tileset(tileset, order=result.tiles, title=title),
                                      args.plot))
    if not args.json:
        print(f"{name}: {instance.n} waypoints, {result.method}, cost {result.cost:.4f} "
              f"in {result.runtime_s:.3f} s")
        print(" ".join(str(t) for t in result.tiles))
    return out


def _sequence_tsplib(args, console, *, start, end, time_limit, seed) -> dict:
    """``sequence FILE.tsp``: the nodes as a closed tour (``--open``: a path), costs under TSPLIB's rounding."""
    from htetro_opt.scenarios.tsplib import load_tsplib

    for flag, given in (("--weights", args.weights), ("--shapes", args.shapes), ("--plot", args.plot)):
        if given:
            raise ParameterError(f"{flag} does not apply to a TSPLIB file (it has no tiles)")
    tsp = load_tsplib(args.tileset)
    closed = not args.open
    if closed and end is not None:
        raise ParameterError("--end applies to open paths: add --open (a TSPLIB file is a closed tour by default)")
    nodes = range(1, tsp.dimension + 1)
    instance = SequencingInstance.from_matrix(tsp.cost, closed=closed, start=_index_of(start, nodes, "--start", "node"),
                                              end=_index_of(end, nodes, "--end", "node"))
    options = _sequence_options(args, instance)
    with console.step(f"sequencing {instance.n} nodes ({args.method})") as progress:
        result = sequence_waypoints(instance, method=args.method, seed=seed, time_limit=time_limit, progress=progress,
                                    **options)
    record = result.as_dict()
    if float(result.cost).is_integer():  # TSPLIB's costs are integers: so is every tour's
        record["cost"] = int(result.cost)
    out = {"tsplib": tsp.name, "type": tsp.type, "edge_weight_type": tsp.edge_weight_type, "waypoints": instance.n,
           "closed": closed, "start": args.start, **({"end": args.end} if end is not None else {}), **record}
    if not args.json:
        print(f"{tsp.name}: {instance.n} nodes, {'closed tour' if closed else 'open path'}, {result.method}, "
              f"cost {record['cost']} in {result.runtime_s:.3f} s")
        print(" ".join(str(t) for t in result.tiles))
    return out


def _int_list(text: str, flag: str) -> list[int]:
    try:
        values = [int(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise ParameterError(f"{flag} must be comma-separated integers, got {text!r}") from None
    if not values:
        raise ParameterError(f"{flag} must name at least one integer")
    return values


def _study_folder(out: str | None) -> Path | None:
    """The results folder, checked before the study runs: a folder, or creatable inside a writable one."""
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


def _cmd_study(args) -> dict:
    if args.study == "nazarahari2019":
        return _nazarahari2019(args)
    if args.study == "le2018":
        if args.figures:
            raise ParameterError("--figures applies to cheng2019 only, not to study 'le2018'")
        return _le2018(args)
    from htetro_opt.studies.runner import load_study, run_study

    if args.time_limit is not None:
        raise ParameterError("--time-limit applies to le2018 only; a study file sets each method's time_limit")
    if args.scheduler and args.executor != "dask":
        raise ParameterError("--scheduler applies only with --executor dask")
    if args.resume and not args.out:
        raise ParameterError("--resume needs --out DIR, the folder holding the study's results")
    study = load_study(args.study)  # the whole file is checked before any trial runs
    seeds = None if args.seeds is None else check_int(args.seeds, "--seeds", minimum=1)
    workers = check_int(args.workers, "--workers", minimum=1, allow_none=True)
    retries = check_int(args.retries, "--retries", minimum=0)
    out = _study_folder(args.out)
    if study.name == "cheng2019":  # Cheng et al. 2019: its report beside the paper's, figures on request
        return _cheng2019(args, study, seeds, workers, retries, out)
    if args.figures:
        raise ParameterError(f"--figures applies to cheng2019 only, not to study {study.name!r}")
    if study.name == "do2021":  # Do et al. 2021: Tables 6-7 on the runner, Table 8 and Fig. 13 beside them
        return _do2021(args, study, seeds, workers, retries, out)
    # Table 4 of Cheng et al. 2020 records the paper's own measures, and its report sets them beside the paper's
    paper = None
    if study.name == "table4":
        from htetro_opt.studies import table4 as paper
    console = _console(args)
    with console.step(f"study {study.name}", 1, "trials") as progress:
        run = run_study(study, out=out, executor=args.executor, workers=workers, scheduler=args.scheduler,
                        seeds=seeds, resume=args.resume, retries=retries, progress=progress,
                        trial=None if paper is None else paper.trial)
    if run.dashboard and not args.quiet:
        print(f"dask dashboard: {run.dashboard}", file=sys.stderr)
    if paper is not None and out is not None:
        _late(run.as_dict(), lambda: write_text(out / f"{study.name}_paper.md", paper.report(run), what="study report"))
    if not args.json:
        from htetro_opt.studies.runner import markdown_summary

        print(paper.report(run) if paper is not None else markdown_summary(run.summary), end="")
        if run.path is not None:
            print(f"\n{len(run.records)} trials ({run.failed} failed) recorded in {run.path}")
    return run.as_dict()


def _do2021(args, study, seeds, workers, retries, out) -> dict:
    """Do et al. 2021's Tables 6-8 and Fig. 13 beside the paper's: Tables 6 and 7 on the study runner
    (the bundled study, or a study file named do2021), Table 8 and Fig. 13 (single runs) in this process;
    DIR/do2021.md and DIR/do2021.csv hold the report."""
    from htetro_opt.studies import do2021

    console = _console(args)
    with console.step("do2021 study (Tables 6, 7)", 1, "trials") as progress:
        run = do2021.run_do2021(study.seeds if seeds is None else seeds, study=study, executor=args.executor,
                                  workers=workers, scheduler=args.scheduler, out=out, resume=args.resume,
                                  retries=retries, progress=progress)
    if run.dashboard and not args.quiet:
        print(f"dask dashboard: {run.dashboard}", file=sys.stderr)
    with console.step("do2021 Table 8 and Fig. 13"):
        table8, fig13 = do2021.run_table8(), do2021.run_fig13()
    result = {**run.as_dict(), "table8": table8, "fig13": fig13}
    if out is not None:
        _late(result, lambda: do2021.write_report(out, run, table8=table8, fig13=fig13))
    if not args.json:
        print(do2021.report(run, table8=table8, fig13=fig13), end="")
        if run.path is not None:
            print(f"\n{len(run.records)} trials ({run.failed} failed) recorded in {run.path}")
    return result


def _cheng2019(args, study, seeds, workers, retries, out) -> dict:
    """Cheng et al. 2019's study beside the paper's: every trial on the study runner (the bundled study,
    or a study file named cheng2019); DIR/cheng2019.md and .csv hold the report, and with --figures
    DIR/cheng2019_fig*.png the paper's Figs. 8b, 14 and 15 redrawn."""
    from htetro_opt.studies import cheng2019

    if seeds is not None:
        raise ParameterError("--seeds does not apply to cheng2019: every coverage method is deterministic")
    if args.figures and out is None:
        raise ParameterError("--figures needs --out DIR, the folder the figures are saved in")
    console = _console(args)
    with console.step("cheng2019 study", 1, "trials") as progress:
        run = cheng2019.run_cheng2019(study=study, executor=args.executor, workers=workers, scheduler=args.scheduler,
                                      out=out, resume=args.resume, retries=retries, progress=progress)
    if run.dashboard and not args.quiet:
        print(f"dask dashboard: {run.dashboard}", file=sys.stderr)
    figures: dict[str, str] = {}
    result = {**run.as_dict(), "figures": figures}
    if args.figures:
        from htetro_opt.viz import plot_cover, plot_cover_heat

        for name, (workspace, plan, title) in cheng2019.figure_plans().items():
            def path_plot(workspace=workspace, plan=plan, title=title):
                return plot_cover(workspace, plan, title=title)

            def heat_plot(plan=plan, title=title):
                return plot_cover_heat(plan, title=title)

            # Fig. 8b is a plan; Figs. 14 and 15 a plan (a) and its coverage times (b, c)
            drawings = {name: path_plot} if name == "fig8b" else {f"{name}a": path_plot, f"{name}bc": heat_plot}
            for figure, draw in drawings.items():
                path = f"cheng2019_{figure}.png"
                _late(result, lambda draw=draw, path=path: _save_plot(console, draw, str(out / path)))
                figures[figure] = path
    if out is not None:
        _late(result, lambda: cheng2019.write_report(out, run, figures=figures))
    if not args.json:
        print(cheng2019.report(run, figures=figures), end="")
        if run.path is not None:
            print(f"\n{len(run.records)} trials ({run.failed} failed) recorded in {run.path}")
    return result


def _nazarahari2019(args) -> dict:
    """Nazarahari et al. 2019's Table 2, §5.1, §5.3 and four robots beside the paper's, in this process
    (every trial needs its map's exact optimum; the runner's tasks plan grid scenarios)."""
    from htetro_opt.studies import nazarahari2019

    given = [flag for name, flag in (("figures", "--figures"), ("resume", "--resume"), ("scheduler", "--scheduler"),
                                     ("workers", "--workers"), ("time_limit", "--time-limit"))
             if getattr(args, name, None) not in (None, False)]
    if given or args.retries or args.executor not in ("processes", "serial"):
        raise ParameterError(f"{', '.join(given) or '--executor/--retries'} does not apply to nazarahari2019 "
                             "(it runs in this process; options: --seeds, --out)")
    seeds = check_int(5 if args.seeds is None else args.seeds, "--seeds", minimum=1)
    out = _study_folder(args.out)
    console = _console(args)
    with console.step("nazarahari2019 study", None, "trials") as progress:
        run = nazarahari2019.run_nazarahari2019(seeds, progress=progress)
    text = nazarahari2019.report(run)
    result = {"study": "nazarahari2019", "seeds": run.seeds, "exact": run.exact, "table2": run.table2,
              "pairs": run.pairs, "normalised": run.normalised, "cross4": run.cross4, "seconds": run.seconds}
    if out is not None:
        _late(result, lambda: nazarahari2019.write_report(out, run))
    if not args.json:
        print(text, end="")
    return result


def _le2018(args) -> dict:
    """Le et al. 2018's Tables 1–5 beside the paper's: Tables 1, 2, 4 and 5 on the study runner, Table 3
    (tilings shuffled by seed, which a sequencing study cannot express) in this process."""
    from htetro_opt.studies import le2018

    if args.scheduler:
        raise ParameterError("--scheduler does not apply to le2018 (processes or serial)")
    if args.executor == "dask":
        raise ParameterError("--executor dask does not apply to le2018 (processes or serial)")
    if args.resume and not args.out:
        raise ParameterError("--resume needs --out DIR, the folder holding the study's results")
    seeds = list(range(check_int(5 if args.seeds is None else args.seeds, "--seeds", minimum=1)))
    time_limit = _cli_time_limit(args.time_limit)
    workers = check_int(args.workers, "--workers", minimum=1, allow_none=True)
    out = _study_folder(args.out)
    console = _console(args)
    with console.step("le2018 study", 1, "trials") as progress:
        run = le2018.run_le2018(seeds, time_limit=time_limit, executor=args.executor, workers=workers,
                                  out=out, resume=args.resume, progress=progress)
    with console.step("le2018 Table 3 (our tilings)"):
        table3 = le2018.run_table3(seeds=seeds[:2])  # two seeds, as the study always ran it
    text = le2018.report(run, table3=table3) + "\n"
    result = {**run.as_dict(), "table3": table3}
    if out is not None:
        _late(result, lambda: write_text(out / "le2018_paper.md", text, what="study report"))
    if not args.json:
        print(text, end="")
    return result


def _cmd_cover(args) -> dict:
    from htetro_opt.solvers.coverage import plan_coverage

    _outputs(args, ("plot", "plot"), ("coverage_plot", "coverage plot"))
    if args.coverage_plot:
        from htetro_opt.viz import figure_format

        figure_format(args.coverage_plot)
    scenario = _grid_scenario(args.scenario)
    clearance = _check_clearance(args.clearance)
    time_limit = _cli_time_limit(args.time_limit)
    region_columns = check_int(args.region_columns, "--region-columns", minimum=1)
    budget = check_int(args.budget, "--budget", minimum=1)
    start = goal = None
    if args.start == "scenario" and scenario.roadmap:
        start, goal = scenario.start, scenario.goal
    console = _console(args)
    with console.step(f"covering ({args.method})"):
        plan = plan_coverage(scenario.workspace, args.shapes, method=args.method, stripes=args.stripes, start=start,
                             goal=goal, region_columns=region_columns, budget=budget, clearance=clearance,
                             time_limit=time_limit, ends=args.ends)
    out = {"scenario": scenario.name, **plan.as_dict()}
    title = f"{scenario.name}: {args.method}"
    if args.plot:
        from htetro_opt.viz import plot_cover

        _late(out, lambda: _save_plot(console, lambda: plot_cover(scenario.workspace, plan, title=title), args.plot))
    if args.coverage_plot:
        from htetro_opt.viz import plot_cover_heat

        _late(out, lambda: _save_plot(console, lambda: plot_cover_heat(plan, title=title), args.coverage_plot))
    if not args.json:
        state = "complete" if plan.complete else f"incomplete ({len(plan.uncoverable)} free cells uncoverable)"
        print(f"{scenario.name}: {args.method} with {','.join(plan.layers)}: {plan.action_cost} commands, {state}, "
              f"average coverage time {plan.average_coverage_time:.3f}, {plan.regions_optimal} of {plan.regions} "
              f"region searches optimal, {plan.runtime_s:.3f} s")
        print(",".join(plan.tokens))
    return out


_COMMANDS = {"scenarios": _cmd_scenarios, "plan": _cmd_plan, "simulate": _cmd_simulate,
             "tile": _cmd_tile, "sequence": _cmd_sequence, "study": _cmd_study, "cover": _cmd_cover}


class Terminated(BaseException):
    """SIGTERM, turned into an exception so that ``finally`` blocks (temporary files) run."""


EXIT_INTERRUPTED = 130  # 128 + SIGINT, as shells report it
EXIT_TERMINATED = 143  # 128 + SIGTERM


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit status (0 success, 2 error, 130 interrupted, 143 terminated)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        if args.command is None:
            parser.print_help(sys.stderr)
            return EXIT_ERROR
        out = _COMMANDS[args.command](args)
    except (UsageError, HtetroError) as err:
        print("error: " + " ".join(str(err).split()), file=sys.stderr)
        return EXIT_ERROR
    except _LateOutputError as late:  # the work is done: its result is not thrown away with the file
        if getattr(args, "json", False):
            print(json.dumps(late.out))
        print("error: " + " ".join(str(late.error).split()), file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except Terminated:
        print("terminated", file=sys.stderr)
        return EXIT_TERMINATED
    except SystemExit as done:  # --help and --version
        return int(done.code or 0)
    if getattr(args, "json", False):
        print(json.dumps(out))
    return 0


def _terminate(signum, frame) -> None:
    raise Terminated()


def main_entry() -> None:
    """Console-script entry point: SIGTERM ends the command like Ctrl-C, one line and no traceback."""
    signal.signal(signal.SIGTERM, _terminate)
    try:
        code = main()
        sys.stdout.flush()
    except BrokenPipeError:  # output piped into e.g. `head`, which closed it: not an error of ours
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        code = 1
    except KeyboardInterrupt:  # a second Ctrl-C while the first was being handled
        code = EXIT_INTERRUPTED
    sys.exit(code)


if __name__ == "__main__":  # pragma: no cover
    main_entry()

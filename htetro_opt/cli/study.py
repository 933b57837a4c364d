"""``htetro-opt study NAME|FILE``: a study (scenarios × methods × seeds) run and summarised, or one of the
papers' studies beside the paper's tables."""

from __future__ import annotations

import sys

from htetro_opt._files import write_text
from htetro_opt._validation import check_int
from htetro_opt.cli._common import add_outputs, console, folder_flag, late, save_plot, time_limit_flag
from htetro_opt.errors import ParameterError

__all__ = ["add_parser", "run"]

PAPER_STUDIES = ("cheng2019", "do2021", "le2018", "nazarahari2019")
"""The papers' studies, each with its report beside the paper's tables."""


def add_parser(sub) -> None:
    from htetro_opt.studies.runner import EXECUTORS

    p = sub.add_parser(
        "study",
        help="run a study (scenarios x methods x seeds) and summarise it",
        description="Run a study: a bundled one by name (small, table4, sequencing, ga_replan) or a study TOML file "
        "(task, scenarios, seeds, [[methods]] with the command's options), every trial recorded to "
        "DIR/NAME.jsonl as it ends, then summarised per scenario and method (mean, std, median, success "
        "rate, gap to the exact reference). 'le2018' re-runs the tables of Le et al. 2018 beside the paper's; "
        "'do2021' those of Do et al. 2021 (Tables 6-8, Fig. 13; DIR/do2021.md and .csv hold its report); "
        "'cheng2019' those of Cheng et al. 2019 (Table 2, the 16 x 7 map, baselines and larger maps, every "
        "coverage plan beside its lower bound; DIR/cheng2019.md and .csv hold its report); 'nazarahari2019' "
        "those of Nazarahari et al. 2019 (Table 2, the (IS, PS) pairs, normalised weights, four robots, every "
        "length beside the exact optimum; its trials on local worker processes, --workers of them, or in this "
        "process with --executor serial; DIR/nazarahari2019.md and .csv).",
    )
    p.add_argument("study", metavar="NAME|FILE",
                   help="a bundled study name, cheng2019, do2021, le2018, nazarahari2019, or a study TOML file")
    p.add_argument("--executor", choices=EXECUTORS, default="processes",
                   help="where trials run: this process, local worker processes (default), or a Dask cluster")
    p.add_argument("--workers", type=int, help="processes / dask: number of workers (default: the local cores)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="dask: join an existing cluster at tcp://HOST:PORT (default: start a local one)")
    p.add_argument("--seeds", type=int, help="run seeds 0 … N−1 instead of the study's own")
    p.add_argument("--out", metavar="DIR", help="write DIR/NAME.jsonl (every trial), DIR/NAME.csv and DIR/NAME.md")
    p.add_argument("--resume", action="store_true",
                   help="skip the trials already recorded in DIR/NAME.jsonl (re-running those whose method's "
                        "code or settings changed since)")
    p.add_argument("--retries", type=int, default=0, help="re-run a failing trial up to N times (default 0)")
    p.add_argument("--time-limit", type=float,
                   help="le2018 only: cap in seconds for each method that takes one (a study file sets its own)")
    p.add_argument("--figures", action="store_true",
                   help="cheng2019 only: also save the paper's Figs. 8b, 14 and 15 redrawn as PNGs in DIR "
                        "(needs --out)")
    add_outputs(p, json="print one JSON object instead of the summary table")


def _stale(run) -> None:
    """One line on stderr when resuming re-ran records whose method's code or settings had changed."""
    if getattr(run, "stale", 0):
        print(f"{run.stale} recorded trial(s) re-run: their method's code or settings changed since", file=sys.stderr)


def run(args) -> dict:
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
    out = folder_flag(args.out)
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
    shown = console(args)
    with shown.step(f"study {study.name}", 1, "trials") as progress:
        run = run_study(study, out=out, executor=args.executor, workers=workers, scheduler=args.scheduler,
                        seeds=seeds, resume=args.resume, retries=retries, progress=progress,
                        trial=None if paper is None else paper.trial)
    if run.dashboard and not args.quiet:
        print(f"dask dashboard: {run.dashboard}", file=sys.stderr)
    _stale(run)
    if paper is not None and out is not None:
        late(run.as_dict(), lambda: write_text(out / f"{study.name}_paper.md", paper.report(run), what="study report"))
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

    shown = console(args)
    with shown.step("do2021 study (Tables 6, 7)", 1, "trials") as progress:
        run = do2021.run_do2021(study.seeds if seeds is None else seeds, study=study, executor=args.executor,
                                  workers=workers, scheduler=args.scheduler, out=out, resume=args.resume,
                                  retries=retries, progress=progress)
    if run.dashboard and not args.quiet:
        print(f"dask dashboard: {run.dashboard}", file=sys.stderr)
    _stale(run)
    with shown.step("do2021 Table 8 and Fig. 13"):
        table8, fig13 = do2021.run_table8(), do2021.run_fig13()
    result = {**run.as_dict(), "table8": table8, "fig13": fig13}
    if out is not None:
        late(result, lambda: do2021.write_report(out, run, table8=table8, fig13=fig13))
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
    shown = console(args)
    with shown.step("cheng2019 study", 1, "trials") as progress:
        run = cheng2019.run_cheng2019(study=study, executor=args.executor, workers=workers, scheduler=args.scheduler,
                                      out=out, resume=args.resume, retries=retries, progress=progress)
    if run.dashboard and not args.quiet:
        print(f"dask dashboard: {run.dashboard}", file=sys.stderr)
    _stale(run)
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
                late(result, lambda draw=draw, path=path: save_plot(shown, draw, str(out / path)))
                figures[figure] = path
    if out is not None:
        late(result, lambda: cheng2019.write_report(out, run, figures=figures))
    if not args.json:
        print(cheng2019.report(run, figures=figures), end="")
        if run.path is not None:
            print(f"\n{len(run.records)} trials ({run.failed} failed) recorded in {run.path}")
    return result


def _nazarahari2019(args) -> dict:
    """Nazarahari et al. 2019's Table 2, §5.1, §5.3 and four robots beside the paper's: its trials on local
    worker processes (``--workers``), or in this process with ``--executor serial``."""
    from htetro_opt.studies import nazarahari2019

    given = [flag for name, flag in (("figures", "--figures"), ("resume", "--resume"), ("scheduler", "--scheduler"),
                                     ("time_limit", "--time-limit"))
             if getattr(args, name, None) not in (None, False)]
    if given or args.retries or args.executor == "dask":
        raise ParameterError(f"{', '.join(given) or '--executor dask/--retries'} does not apply to nazarahari2019 "
                             "(its options: --seeds, --out, --workers, --executor processes or serial)")
    seeds = check_int(5 if args.seeds is None else args.seeds, "--seeds", minimum=1)
    workers = check_int(args.workers, "--workers", minimum=1, allow_none=True)
    if args.executor == "serial":
        if workers is not None:
            raise ParameterError("--workers applies to the processes executor, not to serial")
        workers = 1
    out = folder_flag(args.out)
    shown = console(args)
    with shown.step("nazarahari2019 study", None, "trials") as progress:
        run = nazarahari2019.run_nazarahari2019(seeds, jobs=workers, progress=progress)
    text = nazarahari2019.report(run)
    result = {"study": "nazarahari2019", "seeds": run.seeds, "exact": run.exact, "table2": run.table2,
              "pairs": run.pairs, "normalised": run.normalised, "cross4": run.cross4, "seconds": run.seconds}
    if out is not None:
        late(result, lambda: nazarahari2019.write_report(out, run))
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
    time_limit = time_limit_flag(args.time_limit)
    workers = check_int(args.workers, "--workers", minimum=1, allow_none=True)
    out = folder_flag(args.out)
    shown = console(args)
    with shown.step("le2018 study", 1, "trials") as progress:
        run = le2018.run_le2018(seeds, time_limit=time_limit, executor=args.executor, workers=workers,
                                  out=out, resume=args.resume, progress=progress)
    with shown.step("le2018 Table 3 (our tilings)"):
        table3 = le2018.run_table3(seeds=seeds[:2])  # two seeds, as the study always ran it
    text = le2018.report(run, table3=table3) + "\n"
    result = {**run.as_dict(), "table3": table3}
    if out is not None:
        late(result, lambda: write_text(out / "le2018_paper.md", text, what="study report"))
    if not args.json:
        print(text, end="")
    return result



"""Running a study: its trials serially, on local worker processes or on a Dask cluster, each record
appended to the results file as it ends, resumable, stale records (another fingerprint) re-run."""

from __future__ import annotations

import functools
import json
import os
import sys
import uuid
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from htetro_opt._interrupt import release
from htetro_opt._progress import check_progress, report
from htetro_opt._validation import check_bool, check_int
from htetro_opt.errors import OutputError, ParameterError, StudyError, WorkerLost
from htetro_opt.studies._study import Study, load_study
from htetro_opt.studies._summary import summarise, write_summary
from htetro_opt.studies._trial import Trial, _finite, run_reference, run_trial, spec_of, trial_record

__all__ = ["EXECUTORS", "StudyRun", "read_records", "run_study"]

EXECUTORS = ("serial", "processes", "dask")
"""Where the trials run: in this process, on a local process pool, on a Dask cluster."""


_GAP = {"grid-path planning": ("time", "reached"), "continuous planning": ("length", "reached"),
        "sequencing": ("cost", "optimal")}
"""Per task with an exact method: what a gap compares, and the reference's field that says it is the optimum."""


def _with_gap(record: dict, reference: Mapping[str, Any] | None) -> dict:
    """``record`` with ``reference`` and ``gap`` (relative, to the exact optimum) after its metrics."""
    if record.get("error") is not None:
        return record
    value_key, proven = _GAP[spec_of(record["task"], record["scenario"]).name]
    value = record.get(value_key)
    best = reference.get(value_key) if reference and reference.get(proven) else None
    gaps = {"gap": _relative_gap(value, best)}
    if "fastest_time" in record:
        gaps["fastest_gap"] = _relative_gap(record["fastest_time"], best)
    out = {}
    for k, v in record.items():
        if k == "runtime_s":
            out["reference"] = best
            out.update(gaps)
        out[k] = v
    return out


def _relative_gap(value, best) -> float | None:
    """(value − best) / best; None where either is missing (or best is 0 and value is not)."""
    if value is None or best is None:
        return None
    return _finite((value - best) / best if best > 0 else (0.0 if value == best else None))


# --- executors -------------------------------------------------------------------------------------
def _attempts(function: Callable, args: tuple, retries: int) -> tuple[str, Any]:
    """Run ``function(*args)`` up to ``retries + 1`` times: ("ok", record) or ("error", "Type: message").

    Errors travel as text: an exception of a user's trial function need not pickle."""
    for _ in range(retries + 1):
        try:
            return "ok", function(*args)
        except Exception as err:  # noqa: BLE001 -- any failure of a trial is its result, recorded
            error = _error_text(err)
    return "error", error


def _error_text(err: BaseException) -> str:
    return f"{type(err).__name__}: {' '.join(str(err).split())}"


Call = tuple[Trial, Callable]


def _serial(calls: Sequence[Call], retries: int) -> Iterator[tuple[Trial, tuple[str, Any]]]:
    for trial, function in calls:
        yield trial, _attempts(function, (), retries)


def _die_with(parent: int) -> None:
    """A worker's initializer: it ends with the study process ``parent``, however that ends.

    - Linux: ``prctl(PR_SET_PDEATHSIG, SIGKILL)``, so the kernel kills the worker when its parent dies,
      even by SIGKILL (then nothing of the study process runs), and whatever the worker is doing.
    - Everywhere, a daemon thread that checks once a second whether ``parent`` still runs (the worker's
      parent process changed and ``parent`` is gone), for systems without ``prctl`` and in case it failed.
    - SIGINT ignored: Ctrl-C at a terminal reaches every process of the group, and the study process,
      which records what has finished, ends its workers itself (:func:`_kill_workers`), without a
      traceback from each; SIGTERM back to its default (a forked worker inherits the command line's
      handler, which would send the trial back as an exception): it ends the worker at once.

    Without it (issue 26), the workers of a study process killed with ``kill -9`` were still running 7
    minutes later; with it, they are gone within 0.2 s (tests/test_interrupt.py checks that they go).
    """
    import signal
    import threading
    import time

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    release()  # the command line's process-wide handling, inherited by a fork, is the parent's
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, int(signal.SIGKILL), 0, 0, 0)  # 1: PR_SET_PDEATHSIG
        except (OSError, AttributeError):  # a libc without prctl: the parent-watch thread below ends the worker
            pass
    if _orphaned(parent):  # the parent died before prctl: nothing will kill this worker
        os._exit(1)

    def watch() -> None:
        while not _orphaned(parent):
            time.sleep(1.0)
        os._exit(1)

    threading.Thread(target=watch, name="htetro-parent-watch", daemon=True).start()


def _orphaned(parent: int) -> bool:
    """Whether the study process ``parent`` is gone: this process's parent is no longer it (a worker of a
    fork server has another parent from the start) and no process ``parent`` exists."""
    if os.getppid() == parent:
        return False
    try:
        os.kill(parent, 0)
    except ProcessLookupError:
        return True
    except PermissionError:  # another user's process took the number: ours is gone
        return True
    return False


def _kill_workers(pool: ProcessPoolExecutor) -> None:
    """End the pool's workers now (their trials are not recorded: a resume runs them again)."""
    kill = getattr(pool, "kill_workers", None)  # Python >= 3.14
    if kill is not None:
        kill()
        return
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        try:
            process.kill()
        except (OSError, ValueError, AttributeError):  # already gone
            pass


def _processes(calls: Sequence[Call], retries: int, workers: int | None) -> Iterator[tuple[Trial, tuple[str, Any]]]:
    pool = ProcessPoolExecutor(max_workers=min(workers or os.cpu_count() or 1, len(calls)),
                               initializer=_die_with, initargs=(os.getpid(),))
    finished = False
    try:
        futures = {pool.submit(_attempts, function, (), retries): trial for trial, function in calls}
        for future in as_completed(futures):
            trial = futures.pop(future)
            try:
                outcome = future.result()
            except BrokenProcessPool as err:
                raise WorkerLost(f"a worker process died while running {trial.scenario} {trial.label} "
                                 f"seed {trial.seed} ({err}); the trials recorded so far are kept: "
                                 "resume continues the study") from err
            yield trial, outcome
        finished = True
    finally:
        if not finished:  # Ctrl-C, SIGTERM, an error: the running trials' results would be thrown away
            _kill_workers(pool)
        pool.shutdown(wait=finished, cancel_futures=True)


@contextmanager
def _dask_client(scheduler, workers: int | None):
    try:
        from distributed import Client, LocalCluster
    except ImportError as err:
        raise ParameterError("executor 'dask' needs dask.distributed: pip install 'htetro-opt[dask]'") from err
    if isinstance(scheduler, Client):  # the caller's: theirs to close
        yield scheduler
        return
    import logging

    cluster = None
    try:
        if scheduler is None:
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, dashboard_address=":0",
                                   silence_logs=logging.ERROR)
            client = Client(cluster)
        else:
            client = Client(scheduler, timeout="10s")
    except (OSError, TimeoutError) as err:
        if cluster is not None:
            cluster.close()
        where = "a local Dask cluster" if scheduler is None else f"the Dask scheduler {scheduler!r}"
        raise ParameterError(f"cannot connect to {where}: {err}") from err
    try:
        yield client
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _dask(calls: Sequence[Call], retries: int, client) -> Iterator[tuple[Trial, tuple[str, Any]]]:
    from distributed import as_completed as dask_completed

    futures = {}
    run = uuid.uuid4().hex[:8]  # a key of this run's own: an earlier run's failed task may linger on the cluster
    for trial, function in calls:
        # references first: the gaps of the trials wait for them
        future = client.submit(function, key=f"{trial.kind}-{trial.key[:16]}-{run}", retries=retries,
                               priority=1 if trial.kind == "reference" else 0)
        futures[future] = trial
    try:
        for future in dask_completed(list(futures)):
            trial = futures.pop(future)
            if future.status == "finished":
                outcome = ("ok", future.result())
            else:
                error = future.exception() if future.status == "error" else None
                outcome = ("error", _error_text(error) if error is not None else f"Cancelled: {future.status}")
            future.release()
            yield trial, outcome
    finally:
        for future in futures:
            future.cancel()


def _dashboard(client) -> str | None:
    try:
        return client.dashboard_link
    except (KeyError, AttributeError):  # a scheduler started without its dashboard
        return None


# --- results files ---------------------------------------------------------------------------------
def read_records(path: str | os.PathLike, *, repair: bool = False) -> list[dict]:
    """The records of a results file (JSON Lines), in file order.

    A last line without its newline was torn by a process killed while writing it: it is left out,
    and with ``repair`` cut from the file.

    Raises
    ------
    StudyError
        If a complete line is not a record (naming the file and the line).
    OSError
        If the file cannot be read.
    """
    if not isinstance(path, (str, os.PathLike)):
        raise ParameterError(f"path must be a results file path, got {path!r}")
    path = Path(path)
    data = path.read_bytes()
    lines = data.split(b"\n")
    torn = lines.pop()
    records = []
    for number, line in enumerate(lines, start=1):
        try:
            record = json.loads(line)
        except ValueError:
            record = None
        if not isinstance(record, dict) or not isinstance(record.get("key"), str):
            raise StudyError(f"results file {str(path)!r}, line {number}: not a trial record "
                             f"({line[:60].decode('utf-8', 'replace')!r}…)")
        records.append(record)
    if torn and repair:
        with open(path, "r+b") as handle:
            handle.truncate(len(data) - len(torn))
            handle.flush()
            os.fsync(handle.fileno())
    return records


@contextmanager
def _appender(path: Path | None) -> Iterator[Callable[[Mapping[str, Any]], None]]:
    """A function appending one JSON line per record, flushed and synced, so that a kill loses at
    most the line being written (dropped by the next resume); None: records are not kept."""
    if path is None:
        yield lambda record: None
        return
    try:
        handle = open(path, "a", encoding="utf-8")  # noqa: SIM115 -- open for the whole run
    except OSError as err:
        raise OutputError(f"cannot write results file {str(path)!r}: {err.strerror or err}") from err

    def append(record: Mapping[str, Any]) -> None:
        handle.write(json.dumps(record, ensure_ascii=False, separators=(",", ":"), allow_nan=False) + "\n")
        handle.flush()
        os.fsync(handle.fileno())

    with handle:
        yield append


def _folder(out) -> Path | None:
    if out is None:
        return None
    if not isinstance(out, (str, os.PathLike)):
        raise ParameterError(f"out must be a folder path or None, got {out!r}")
    folder = Path(out)
    if folder.exists() and not folder.is_dir():
        raise OutputError(f"cannot write the study's results in {str(folder)!r}: it is a file, not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise OutputError(f"cannot create the results folder {str(folder)!r}: {err.strerror or err}") from err
    return folder


# --- running a study -------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class StudyRun:
    """What :func:`run_study` did: the study's records (in trial order, resumed ones included), its
    summary, the results file, the Dask dashboard, and counts (``resumed``: records kept from the
    results file; ``stale``: records found there from another code or settings, re-run)."""

    study: Study
    records: list[dict]
    references: list[dict]
    summary: list[dict]
    path: Path | None
    dashboard: str | None = None
    resumed: int = 0
    failed: int = 0
    stale: int = 0

    def as_dict(self) -> dict:
        """JSON-ready (for ``--json``)."""
        return {"study": self.study.name, "task": self.study.task,
                "path": None if self.path is None else str(self.path), "dashboard": self.dashboard,
                "trials": len(self.records), "resumed": self.resumed, "failed": self.failed, "stale": self.stale,
                "summary": self.summary, "records": self.records, "references": self.references}


def _is_client(value) -> bool:
    try:
        from distributed import Client
    except ImportError:
        return False
    return isinstance(value, Client)


def _check_run_options(executor, workers, scheduler, retries, resume, out) -> None:
    if executor not in EXECUTORS:
        raise ParameterError(f"executor must be one of {', '.join(EXECUTORS)}, got {executor!r}")
    check_int(workers, "workers", minimum=1, allow_none=True)
    check_int(retries, "retries", minimum=0)
    check_bool(resume, "resume")
    if workers is not None and executor == "serial":
        raise ParameterError("workers applies to the processes and dask executors, not to serial")
    if scheduler is not None:
        if executor != "dask":
            raise ParameterError(f"scheduler applies to the dask executor only, not to {executor}")
        if workers is not None:
            raise ParameterError("workers applies to a local Dask cluster, not to one joined at a scheduler address")
        if not isinstance(scheduler, str) and not _is_client(scheduler):
            raise ParameterError(f"scheduler must be an address such as 'tcp://127.0.0.1:8786' or a "
                                 f"distributed.Client, got {scheduler!r}")
    if resume and out is None:
        raise ParameterError("resume needs out, the folder of the results file to resume")


def run_study(study: Study | str | os.PathLike, *, out: str | os.PathLike | None = None,
              executor: str = "processes", workers: int | None = None, scheduler=None,
              seeds: int | Sequence[int] | None = None, resume: bool = False, retries: int = 0,
              progress=None, trial: Callable | None = None) -> StudyRun:
    """Run every trial of a study, recording each as it finishes.

    Parameters
    ----------
    study : Study, or str or path
        A study, or a bundled study's name or a study file (:func:`load_study`).
    out : str or path, optional, keyword-only
        Folder of the results (created if missing): ``<name>.jsonl``, one line per trial, and the
        summary ``<name>.csv`` and ``<name>.md`` at the end. None: records are only returned.
    executor : {"serial", "processes", "dask"}, keyword-only
        ``processes`` (default): a local process pool; ``dask``: a ``distributed`` cluster.
    workers : int, optional, keyword-only
        Processes of the pool, or workers of a local Dask cluster (default: the machine's cores).
    scheduler : str or distributed.Client, optional, keyword-only
        ``dask`` only: join the cluster of this scheduler address (``"tcp://HOST:PORT"``), or run
        on this client. Default: start a local cluster for the run.
    seeds : int or sequence of int, optional, keyword-only
        Override the study's seeds (N: 0 … N−1).
    resume : bool, keyword-only
        Keep the trials already recorded in ``out``'s results file and run the others, and those whose
        record carries another fingerprint than today's code gives (:attr:`Trial.fingerprint`: the
        method's revision, defaults or options changed since; :attr:`StudyRun.stale` counts them). Without
        it, a results file that holds records is an error (rather than overwritten).
    retries : int, keyword-only
        Re-run a trial that raised up to this many times before recording its error.
    progress : callable, optional, keyword-only
        ``progress(done, total, note)`` after each trial (:mod:`htetro_opt._progress`); the note
        names the last trial and counts the failures so far (and the Dask dashboard at the start).
    trial : callable, optional, keyword-only
        A module-level function with :func:`run_trial`'s signature to run instead (benchmarks,
        tests); the references stay :func:`run_reference`.

    Returns
    -------
    StudyRun

    Raises
    ------
    StudyError, ParameterError
        On an invalid study or option, before any trial runs and before any file is written.
    OutputError
        If the results cannot be written, or ``out`` already holds this study's results and
        ``resume`` is off.
    WorkerLost
        If a worker process of the pool died; the records so far are kept.

    Examples
    --------
    >>> study = Study(name="demo", task="plan", scenarios=["three_slit"], methods=[{"method": "dijkstra"}])
    >>> run = run_study(study, executor="serial")
    >>> [(r["label"], r["reached"], r["time"]) for r in run.records]
    [('dijkstra', True, 33.0)]
    >>> run.summary[0]["success_rate"], run.summary[0]["time_mean"]
    (1.0, 33.0)
    """
    study = study if isinstance(study, Study) else load_study(study)
    if seeds is not None:
        study = study.with_seeds(seeds)
    _check_run_options(executor, workers, scheduler, retries, resume, out)
    progress = check_progress(progress)
    if trial is not None and not callable(trial):
        raise ParameterError(f"trial must be a function like run_trial, got {trial!r}")
    function = run_trial if trial is None else trial

    trials = study.trials()
    references_of = study.references()
    references = list({ref.key: ref for ref in references_of.values()}.values())
    folder = _folder(out)
    path = None if folder is None else folder / f"{study.name}.jsonl"
    recorded: dict[str, dict] = {}
    if path is not None and path.exists():
        existing = read_records(path, repair=resume)
        if existing and not resume:
            raise OutputError(f"results file {str(path)!r} already holds {len(existing)} records: resume continues "
                              "the study; remove the file to start it over")
        for record in existing:  # the last record of a trial is its latest: a stale one re-run is appended
            recorded[record["key"]] = record

    current = {t.key: t.fingerprint for t in (*references, *trials)}
    stale = {key for key, fingerprint in current.items()
             if key in recorded and recorded[key].get("fingerprint") != fingerprint}
    for key in stale:
        del recorded[key]
    wanted = set(current)
    resumed = sum(key in recorded for key in wanted)
    todo = [r for r in references if r.key not in recorded] + [t for t in trials if t.key not in recorded]
    calls = [(t, _bind(t, function)) for t in todo]
    total, done = len(wanted), resumed
    failed = sum(recorded[k].get("error") is not None for k in wanted if k in recorded)
    waiting: dict[str, list[dict]] = {}  # reference key -> trial records waiting for it

    def finish(record: dict) -> None:
        nonlocal done, failed
        record["fingerprint"] = current[record["key"]]  # a user's trial function's records too
        append(record)
        recorded[record["key"]] = record
        done += 1
        failed += record.get("error") is not None
        note = f"{record['scenario']} {record['label']}" + ("" if record["seed"] is None else f" seed {record['seed']}")
        report(progress, done, total, f"{note}; {failed} failed")

    before = f"{resumed} recorded before" if resumed else ""
    if stale:
        before += f"{'; ' if before else ''}{len(stale)} stale (code or settings changed), re-run"
    report(progress, done, total, before)
    runner = _outcomes(calls, executor, workers, scheduler, retries)
    with _appender(path) as append, runner as (outcomes, dashboard):
        if dashboard:
            report(progress, done, total, f"Dask dashboard: {dashboard}")
        for item, (status, value) in outcomes:
            record = value if status == "ok" else trial_record(item.head(), {}, {}, None, value)
            if item.kind == "reference":
                finish(record)
                for pending in waiting.pop(item.key, []):
                    finish(_with_gap(pending, record))
                continue
            if item.key in references_of:
                reference = references_of[item.key].key
                if reference not in recorded:
                    waiting.setdefault(reference, []).append(record)
                    continue
                record = _with_gap(record, recorded[reference])
            finish(record)

    records = [recorded[t.key] for t in trials]
    summary = summarise(records)
    if folder is not None:
        write_summary(summary, folder, name=study.name)
    return StudyRun(study, records, [recorded[r.key] for r in references], summary, path, dashboard,
                    resumed, failed, len(stale))


def _bind(trial: Trial, function: Callable) -> Callable:
    """The call of one trial, picklable (a partial of a module-level function)."""
    if trial.kind == "reference":
        return functools.partial(run_reference, trial.task, trial.scenario, trial.parameters)
    return functools.partial(function, trial.task, trial.scenario, trial.method, trial.parameters, trial.seed,
                             label=trial.label, metrics=trial.metrics)


@contextmanager
def _outcomes(calls, executor, workers, scheduler, retries):
    """(iterator of (trial, outcome) in completion order, the Dask dashboard or None)."""
    if not calls:
        yield iter(()), None
    elif executor == "serial":
        yield _serial(calls, retries), None
    elif executor == "processes":
        outcomes = _processes(calls, retries, workers)
        try:
            yield outcomes, None
        finally:
            outcomes.close()
    else:
        with _dask_client(scheduler, workers) as client:
            outcomes = _dask(calls, retries, client)
            try:
                yield outcomes, _dashboard(client)
            finally:
                outcomes.close()



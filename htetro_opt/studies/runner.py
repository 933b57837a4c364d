"""Studies at scale: scenarios × methods × seeds, on one machine or a Dask cluster, resumable.

A **study** (:class:`Study`) names a task (the command-line verb it stands for: ``plan``, ``tile``,
``sequence`` or ``cover``), the scenarios to run it on, the methods with their options, the seeds, and the
optional metrics to record. It is built in Python or read from a TOML file (:func:`load_study`: a
bundled name, ``htetro-opt``'s ``studies/data/*.toml``, or a path), which reads like the command line
it stands for: ``task`` is the verb, each method's keys are the options of the task's spec (the
command's flags with underscores)::

    name = "small"
    task = "plan"
    scenarios = ["random", "three_slit", "h_shape"]
    seeds = 3                     # or a list of seeds
    [[methods]]
    method = "dijkstra"
    [[methods]]
    method = "htetro-ga"
    pop_size = 20
    max_gen = 40

Top-level keys: ``name`` (default: the file's stem; it names the results files), ``description``,
``task``, ``scenarios`` (bundled names or files; relative paths start from the study file's folder),
``seeds`` (N for 0 … N−1, or a list), ``metrics`` (optional metrics, :data:`METRICS`) and the
``[[methods]]``. A method entry holds ``method``, an optional ``label`` (the name of its rows), the
method's options, ``[methods.per_scenario.<scenario>]`` tables of options for one scenario, and an
optional ``scenarios`` (some of the study's, on which alone it runs).

**What a method takes is its task's spec's** (:mod:`htetro_opt._spec`; ``htetro_opt.solvers.<task>.SPEC``,
the command's ``--help``): its options with their checks and defaults, whether it draws from the seed
(a method that does not, for its options, runs once per scenario with seed None), and the task's exact
method. ``plan`` runs the grid-path task on grid scenarios and the continuous task on continuous ones (a
study does not mix them). Seeds come from the study, never from a method entry. The whole study is
checked before any trial runs (:class:`StudyError` names the file, the method entry ``methods[i]``,
counted from 0, and the key).

A **trial** (:func:`run_trial`) is one method on one scenario with one seed: the task's
``spec.solve(scenario, …)`` and its result as a flat, JSON-ready record of its inputs, metrics, runtime,
solution (the commands or order, comma-separated), the package version, ``key`` (a hash of its inputs)
and ``fingerprint`` (a hash of the method's spec, revision and option values: what the code that ran it
stands for). The gap to the exact optimum (metric ``"gap"``) comes from one **reference** trial per
scenario and problem (:func:`reference_trial`, :func:`run_reference`: the task's exact method with the
options that define the problem, the trial's method's own problem on top), recorded in the results file
like the others. A ``cover`` trial has no optimum to compare with: its record always holds the lower
bound ⌈(coverable − 4) / g⌉ on its action cost (:func:`coverage_bound`; g: the most new cells one command
adds, 2 for {O}, 4 with an I), and metric ``"gap"`` sets ``reference`` to that bound.

:func:`run_study` runs the trials ``serial``-ly, on local ``processes`` (the default) or on a ``dask``
cluster (a local one, or the scheduler at an address), appends one JSON line per trial to
``DIR/<name>.jsonl`` as each finishes (flushed and synced), on ``resume`` keeps the recorded trials and
re-runs those whose fingerprint changed, and writes the :func:`summarise` table to ``DIR/<name>.csv`` and
``DIR/<name>.md``. The same study and seeds give the same records (:data:`RUNTIME_FIELDS` aside),
whatever the executor and however often the run was interrupted; a method that stops on a time budget
rather than by itself (``ortools``, ``time_limit`` cut-offs) depends on the machine's speed, as it does on
the command line.

The metrics beyond those every record holds (plan: ``reached``, ``time``, ``n_commands`` — on continuous
scenarios ``length``, ``smoothness_deg``, ``safety``, ``min_clearance``, ``min_robot_distance``,
``conflicts``; tile: ``tiles``, ``overlapping``, ``n_I`` … ``n_T``; sequence: ``cost``, ``waypoints``,
``optimal``; cover: ``action_cost``, ``time``, ``complete``, ``coverable``, ``covered``,
``lower_bound``, the paper's measures and the planner's counts):

- ``objectives``: ``translations``, ``rotations``, ``shapeshifts``, ``path_length`` (:meth:`Plan.objectives`);
- ``generations``: the GAs' ``generations`` (summed over the legs), ``reach_generation`` and
  ``reach_time_s``;
- ``fitness``: the GAs' ``f_gr``, ``f_t``, ``f_sm``, ``f_sf`` of the multi-objective solution,
  averaged over the legs (Cheng et al. 2020's Table 4);
- ``gap``: ``reference`` (the exact optimum's time, length or cost) and ``gap`` = (value − reference) /
  reference; for the GAs also ``fastest_time``, the summed time of each leg's fastest goal-reaching front
  member, and ``fastest_gap``; for ``sequence`` only where the optimum is proven (≤ 40 waypoints);
- ``heat_fitness``: Do et al. 2021's costs of any plan (eqs. 9–12 with Fig. 5's safety): ``heat_f_t``,
  ``heat_f_sm``, ``heat_f_sf``, and ``heat_f`` with the heat planner's weights, (1, 1, 1) for every other
  method (a choice of ours: they optimise no such weighting); plus ``shapes_used``;
- ``front`` (the GAs): the last leg's leading front as distinct ``[f_gr, f_t, f_sm, f_sf]`` rows and its
  hypervolume ``hv`` against :data:`HV_REFERENCE`; the summary adds ``igd_plus`` (:func:`front_metrics`,
  :mod:`htetro_opt.studies._summary` gives the choices);
- ``history`` (the GAs): the last leg's multi-objective solution's fitnesses per generation;
- ``hv_curve`` (the GAs): the last leg's front's hypervolume by generation.

This module is the studies' public face; the work is done in ``_study`` (the study and its checks),
``_trial`` (one trial and its record), ``_execution`` (the executors and results files) and ``_summary``.
"""

from __future__ import annotations

from htetro_opt.errors import StudyError, WorkerLost
from htetro_opt.studies._execution import EXECUTORS, StudyRun, read_records, run_study
from htetro_opt.studies._study import METRICS, TASKS, MethodEntry, Study, list_studies, load_study
from htetro_opt.studies._summary import (
    front_metrics,
    hypervolume,
    markdown_summary,
    rows_csv,
    summarise,
    write_report,
    write_summary,
)
from htetro_opt.studies._trial import (
    HV_REFERENCE,
    RUNTIME_FIELDS,
    Trial,
    coverage_bound,
    reference_trial,
    run_reference,
    run_trial,
    trial_record,
)

__all__ = [
    "EXECUTORS",
    "HV_REFERENCE",
    "METRICS",
    "RUNTIME_FIELDS",
    "TASKS",
    "MethodEntry",
    "Study",
    "StudyError",
    "StudyRun",
    "Trial",
    "WorkerLost",
    "coverage_bound",
    "front_metrics",
    "hypervolume",
    "list_studies",
    "load_study",
    "markdown_summary",
    "read_records",
    "reference_trial",
    "rows_csv",
    "run_reference",
    "run_study",
    "run_trial",
    "summarise",
    "trial_record",
    "write_report",
    "write_summary",
]

"""pymoo algorithms and terminations over Cheng et al. 2020's command chromosomes.

- :class:`HTetroGA`: the paper's hTetro-GA (Cheng et al. 2020) as a pymoo ``GeneticAlgorithm``, with
  our additions switchable (:meth:`HTetroGA.as_published` turns them off);
- :func:`make_algorithm`: that or one of pymoo's algorithms by name (:data:`GA_ALGORITHMS`), with the
  same operators;
- :class:`FrontConvergence`: stop at a generation cap or when the leading front stops improving;
- :func:`leading_front`, :func:`select_solutions`, :class:`ConvergenceRecorder`: the paper's output
  solutions and their convergence record.
"""

from htetro_opt._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "HTetroGA": ".htetro_ga", "trim_reached": ".htetro_ga",
    "FrontConvergence": ".termination",
    "GA_ALGORITHMS": ".factory", "make_algorithm": ".factory",
    "SELECTIONS": ".solutions", "PICKS": ".solutions", "leading_front": ".solutions", "select_solutions": ".solutions",
    "ConvergenceRecorder": ".solutions",
})

"""pymoo algorithms and terminations over Cheng et al. 2020's command chromosomes.

- :class:`HTetroGA`: the paper's hTetro-GA (Cheng et al. 2020) as a pymoo ``GeneticAlgorithm``, with
  our additions switchable (:meth:`HTetroGA.as_published` turns them off);
- :func:`make_algorithm`: that or one of pymoo's algorithms by name (:data:`GA_ALGORITHMS`), with the
  same operators;
- :class:`FrontConvergence`: stop at a generation cap or when the goal-reaching front stops improving
  (by its best fitnesses, or by its best time and :func:`reaching_hypervolume`); :class:`HypervolumeWindow`:
  the same over a sliding window of generations (measured, not a default);
- :func:`leading_front`, :func:`select_solutions`, :class:`ConvergenceRecorder`: the paper's output
  solutions and their convergence record;
- :class:`EnhancedGA`, :func:`make_path_algorithm` (Nazarahari et al. 2019): the enhanced GA over
  path-base chromosomes, or one of pymoo's algorithms with the same operators.
"""

from htetro_opt._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "HTetroGA": ".htetro_ga", "trim_reached": ".htetro_ga", "check_additions": ".htetro_ga",
    "GA_ADDITIONS": ".names",
    "EGA_ADDITIONS": ".names",
    "FrontConvergence": ".termination", "HypervolumeWindow": ".termination", "CONVERGENCE_MEASURES": ".names", "reaching_hypervolume": ".termination",
    "GA_ALGORITHMS": ".names", "make_algorithm": ".factory", "ReplanMating": ".factory",
    "ConservativeMating": ".factory",
    "SELECTIONS": ".names", "PICKS": ".names", "leading_front": ".solutions", "select_solutions": ".solutions",
    "ConvergenceRecorder": ".solutions",
    "EnhancedGA": ".enhanced_ga", "make_path_algorithm": ".enhanced_ga", "PATH_ALGORITHMS": ".enhanced_ga",
})

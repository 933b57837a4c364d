"""Complete coverage planning (Cheng et al. 2019): :func:`plan_coverage` with ``method=``.

- ``"stripes"``: the paper's graph-theory coverage in our reading: morphology layers
  (:class:`LayerGraph`, Def. 4–5), stripes of rows (Def. 6–7) cut into regions, a best-first branch
  and bound per region (Alg. 5's RBT) and one auxiliary DAG over ports and cut-edges solved by
  a Dijkstra (Def. 8–10, eq. 8, Alg. 1), then a mop-up of what the stripes left: the
  paper's Alg. 5 with our additions (:data:`STRIPES_ADDITIONS`, each switched by ``additions``);
- ``"stripes-paper"``: Alg. 5 as published, none of them: what it leaves uncovered, and the region
  searches that spend their node budget, are reported (``missed``, ``failed_regions``), not rescued;
- ``"boustrophedon"``: lanes in one layer, the baseline.

Every method returns a :class:`CoveragePlan`, re-validated in the simulator. Importing this package
imports neither pymoo nor DEAP.
"""

from htetro_opt._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "plan_coverage": "._dispatch", "SPEC": "._spec", "DEFAULT_LAYERS": "._spec",
    "CoveragePlan": "._result", "UNCOVERABLE_REASONS": "._result", "RECOVERED_TIME": "._result",
    "parse_layers": "._layers", "Layer": "._layers", "LayerGraph": "._layers",
    "workspace_graph": "._layers", "stripe_graph": "._layers",
    "stripe_widths": "._stripes", "ENDS": "._spec", "MOPUP_ORDERS": "._spec", "STRIPES_ADDITIONS": "._spec",
})

"""Initial chromosomes by the paper's Algorithm 1: proportionate choice of commands until t_max."""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
from pymoo.core.sampling import Sampling

from htetro_opt._validation import check_real
from htetro_opt.errors import ParameterError
from htetro_opt.model.commands import TOKENS, command_id
from htetro_opt.operators.commands._chromosome import as_column

__all__ = ["CommandSampling", "sample_commands", "DEFAULT_SAMPLING_WEIGHTS"]

DEFAULT_SAMPLING_WEIGHTS = {"x+": 0.25, "x-": 0.25, "y+": 0.25, "y-": 0.25}
"""λ_mc of the paper: 0.25 for the four translations, 0 for rotations and shapeshifts."""


def sample_commands(
    rng: np.random.Generator,
    n: int,
    *,
    commands: np.ndarray,
    weights: np.ndarray,
    durations: np.ndarray,
    t_max: float,
) -> list[np.ndarray]:
    """Draw ``n`` chromosomes: commands in proportion to ``weights`` until their time reaches ``t_max``.

    Algorithm 1 pushes commands while the accumulated time is below ``t_max``, so a chromosome's
    last command may end after it. A draw of ``rnd`` that falls past ``Σ λ`` pushes nothing in the
    paper; that is the same as normalising the weights, which is what this does.

    Parameters
    ----------
    rng : numpy.random.Generator
    n : int
    commands : ndarray of int
        Global ids to draw from.
    weights : ndarray of float
        λ of each command (non-negative, not all zero).
    durations : ndarray of float
        Duration of every global command id.
    t_max : float

    Returns
    -------
    list of ndarray of int

    Examples
    --------
    >>> from htetro_opt.model import Timing, parse_commands
    >>> rng = np.random.default_rng(0)
    >>> [s] = sample_commands(rng, 1, commands=parse_commands("x+,sI"), weights=np.array([0.5, 0.5]),
    ...                       durations=Timing().durations(), t_max=10.0)
    >>> float(Timing().durations()[s].sum()) >= 10.0
    True
    """
    commands = np.asarray(commands, dtype=np.int64)
    p = np.asarray(weights, dtype=float)
    p = p / p.sum()
    drawn = durations[commands[p > 0]]
    if (drawn <= 0).any():
        raise ParameterError("sampling needs every command with a positive weight to take a positive time")
    width = int(np.ceil(t_max / drawn.min())) + 1
    genes = rng.choice(commands, size=(n, width), p=p)
    before = np.cumsum(durations[genes], axis=1) - durations[genes]  # time when each command starts
    lengths = (before < t_max).sum(axis=1)
    return [genes[i, : lengths[i]].copy() for i in range(n)]


class CommandSampling(Sampling):
    """Algorithm 1 as a pymoo sampling of command chromosomes.

    Parameters
    ----------
    weights : mapping of token to float, optional
        λ_mc of each command of the problem's alphabet (default :data:`DEFAULT_SAMPLING_WEIGHTS`); commands
        left out weigh 0.
    include : sequence of int arrays, keyword-only
        Chromosomes (global command ids) put first in the sample, e.g. an exact plan (ours: the
        paper draws every initial chromosome); the rest are drawn, so an empty ``include`` (the
        default) draws exactly what Algorithm 1 draws.

    Raises
    ------
    ParameterError
        If a weight is negative or all are zero, or ``include`` is not a sequence of command-id arrays.
    UnknownCommandError
        If a token is not a command.
    """

    def __init__(self, weights: Mapping[str, float] | None = None, *, include: Sequence = ()) -> None:
        super().__init__()
        try:
            self.include = [np.asarray(s, dtype=np.int64).reshape(-1) for s in include]
        except (TypeError, ValueError) as err:
            raise ParameterError(f"include must be a sequence of command-id arrays, got {include!r}") from err
        weights = dict(DEFAULT_SAMPLING_WEIGHTS if weights is None else weights)
        for token, w in weights.items():
            command_id(token)
            weights[token] = check_real(w, f"sampling weight of {token!r}", minimum=0.0)
        if sum(weights.values()) <= 0:
            raise ParameterError("sampling weights are all zero")
        self.weights = weights

    def _do(self, problem, n_samples, *args, random_state=None, **kwargs):
        alphabet = problem.command_ids
        weights = np.array([self.weights.get(TOKENS[c], 0.0) for c in alphabet])
        outside = sorted(set(self.weights) - {TOKENS[c] for c in alphabet})
        if outside:
            raise ParameterError(f"sampling weights name commands outside the problem's set: {', '.join(outside)}")
        if weights.sum() <= 0:
            raise ParameterError("sampling weights give zero weight to every command of the problem's set")
        include = self.include[:n_samples]
        seqs = sample_commands(random_state, n_samples - len(include), commands=alphabet, weights=weights,
                               durations=problem.durations, t_max=problem.t_max)
        return as_column(include + seqs)

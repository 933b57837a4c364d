"""The motion-command vocabulary of shared/MODEL.md §3, its timing, and token parsing.

Command ids are positions in :data:`COMMANDS`; every table of the model is indexed by them. Tokens
(``x+``, ``r-``, ``sO``, ``3l`` …) are what files, the CLI and JSON use.

Cheng et al. 2019's single-block commands follow its Table 1: ``l`` turns a block counter-clockwise (+90°),
``r`` clockwise; ``1l/1r`` move B1 about H1, ``3l/3r`` move B3 with B4 about H2, ``4l/4r`` move B4
about H3, ``2l/2r`` turn the whole robot about B2 (the same motion as ``r+``/``r-``). Two ``3r`` take
the I-shape to the O-shape, as the paper states.
"""

from __future__ import annotations

import math
import re
import reprlib
from dataclasses import dataclass, fields
from collections.abc import Iterable

import numpy as np

from htetro_opt._validation import check_bool, check_int, check_real
from htetro_opt.errors import ParameterError, UnknownCommandError
from htetro_opt.model.robot import SHAPES

__all__ = [
    "Command",
    "COMMANDS",
    "TOKENS",
    "N_COMMANDS",
    "Timing",
    "command_id",
    "parse_commands",
    "format_commands",
    "command_set",
    "SEED000_COMMANDS",
    "DIAGONAL_COMMANDS",
    "SEED004_COMMANDS",
]


@dataclass(frozen=True)
class Command:
    """One motion command.

    ``kind`` is one of ``translation``, ``diagonal``, ``rotation``, ``shapeshift``, ``block`` (seed
    004's hinge commands ``1l`` … ``4r``, whose ``2l/2r`` turn the whole robot) or ``stop``; it picks
    the command's duration in :class:`Timing`. ``shift`` is the (dx, dy) of a translation in the workspace frame, ``turn`` the number
    of quarter turns of the whole robot, ``target`` the shape index of a shapeshift, and
    ``hinge_delta`` the change of (θH1, θH2, θH3) in units of π/2 of a single-block command.
    """

    token: str
    kind: str
    shift: tuple[int, int] = (0, 0)
    turn: int = 0
    target: int = -1
    hinge_delta: tuple[int, int, int] = (0, 0, 0)


def _build_commands() -> tuple[Command, ...]:
    commands = [
        Command("x+", "translation", shift=(1, 0)),
        Command("x-", "translation", shift=(-1, 0)),
        Command("y+", "translation", shift=(0, 1)),
        Command("y-", "translation", shift=(0, -1)),
        Command("x+y+", "diagonal", shift=(1, 1)),
        Command("x+y-", "diagonal", shift=(1, -1)),
        Command("x-y+", "diagonal", shift=(-1, 1)),
        Command("x-y-", "diagonal", shift=(-1, -1)),
        Command("r+", "rotation", turn=1),
        Command("r-", "rotation", turn=-1),
    ]
    commands += [Command("s" + name, "shapeshift", target=i) for i, name in enumerate(SHAPES)]
    commands += [
        Command("stop", "stop"),
        # B1 about H1: θH1 = π/2 + θB1 − θB2 grows when B1 turns counter-clockwise.
        Command("1l", "block", hinge_delta=(1, 0, 0)),
        Command("1r", "block", hinge_delta=(-1, 0, 0)),
        Command("2l", "block", turn=1),
        Command("2r", "block", turn=-1),
        # B3 (with B4) about H2: θH2 = π/2 + θB2 − θB3 shrinks when B3 turns counter-clockwise.
        Command("3l", "block", hinge_delta=(0, -1, 0)),
        Command("3r", "block", hinge_delta=(0, 1, 0)),
        # B4 about H3: θH3 = π/2 + θB4 − θB3 grows when B4 turns counter-clockwise.
        Command("4l", "block", hinge_delta=(0, 0, 1)),
        Command("4r", "block", hinge_delta=(0, 0, -1)),
    ]
    return tuple(commands)


COMMANDS: tuple[Command, ...] = _build_commands()
TOKENS: tuple[str, ...] = tuple(c.token for c in COMMANDS)
N_COMMANDS = len(COMMANDS)
_TOKEN_INDEX = {token: i for i, token in enumerate(TOKENS)}

SEED000_COMMANDS: tuple[str, ...] = ("x+", "x-", "y+", "y-", "r+", "r-") + tuple("s" + s for s in SHAPES)
"""Cheng et al. 2020's command set: the four translations, two rotations and seven shapeshifts."""
DIAGONAL_COMMANDS: tuple[str, ...] = ("x+y+", "x+y-", "x-y+", "x-y-")
"""Do et al. 2021's four diagonal translations."""
SEED004_COMMANDS: tuple[str, ...] = (
    "stop", "y+", "y-", "x-", "x+", "1l", "1r", "2l", "2r", "3l", "3r", "4l", "4r",
)
"""Cheng et al. 2019's 13 commands (stop, F, B, L, R and the eight block rotations), in its Table 1 order."""


@dataclass(frozen=True)
class Timing:
    """Duration of each kind of command (shared/MODEL.md §3), all configurable.

    Examples
    --------
    >>> Timing().duration("r+")
    2.0
    """

    translation: float = 1.0
    diagonal: float = math.sqrt(2.0)
    rotation: float = 2.0
    shapeshift: float = 3.0
    block: float = 1.0
    stop: float = 1.0

    def __post_init__(self) -> None:
        for f in fields(self):
            object.__setattr__(self, f.name, check_real(getattr(self, f.name), f"Timing.{f.name}", minimum=0.0))

    def durations(self) -> np.ndarray:
        """Duration of every command, indexed by command id."""
        return np.array([getattr(self, c.kind) for c in COMMANDS], dtype=float)

    def duration(self, token: str) -> float:
        """Duration of one command given by its token."""
        return float(self.durations()[command_id(token)])


def command_id(token: str) -> int:
    """Id of a command token.

    Raises
    ------
    UnknownCommandError
        If ``token`` is not in the vocabulary.
    """
    try:
        return _TOKEN_INDEX[token]
    except (KeyError, TypeError) as err:
        raise UnknownCommandError(
            f"unknown command {token!r}: expected one of {' '.join(TOKENS)}"
        ) from err


def parse_commands(commands: str | Iterable[str]) -> np.ndarray:
    """Parse command tokens into an integer array of command ids.

    Parameters
    ----------
    commands : str or iterable of str
        Tokens separated by commas and/or whitespace (``"x+, x+ sI"``), or a sequence of tokens.

    Returns
    -------
    ndarray of int64

    Raises
    ------
    UnknownCommandError
        Naming the first unknown token and its position (1-based).
    ParameterError
        If ``commands`` is neither a string nor a sequence.

    Examples
    --------
    >>> parse_commands("x+,y+ r-").tolist()
    [0, 2, 9]
    """
    if isinstance(commands, str):
        tokens = [t for t in re.split(r"[,\s]+", commands) if t]
    else:
        tokens = _token_list(commands, "commands")
    ids = np.empty(len(tokens), dtype=np.int64)
    for position, token in enumerate(tokens, start=1):
        index = _TOKEN_INDEX.get(token) if isinstance(token, str) else None
        if index is None:
            raise UnknownCommandError(
                f"unknown command {reprlib.repr(token)} at position {position}: expected one of {' '.join(TOKENS)}"
            )
        ids[position - 1] = index
    return ids


def _token_list(tokens, name: str) -> list:
    """A sequence of command tokens as a list (its items checked by the caller)."""
    if isinstance(tokens, bytes) or not isinstance(tokens, Iterable):
        raise ParameterError(f"{name} must be a string of command tokens or a sequence of them, "
                             f"got {type(tokens).__name__} {reprlib.repr(tokens)}")
    return list(tokens)


def format_commands(ids: Iterable[int]) -> list[str]:
    """Tokens of a sequence of command ids.

    Raises
    ------
    UnknownCommandError
        Naming the first item that is not a command id.
    ParameterError
        If ``ids`` is not a sequence.

    Examples
    --------
    >>> format_commands([0, 2, 9])
    ['x+', 'y+', 'r-']
    """
    if isinstance(ids, (str, bytes)) or not isinstance(ids, Iterable):
        raise ParameterError(f"ids must be a sequence of command ids, got {type(ids).__name__} {reprlib.repr(ids)}")
    tokens = []
    for position, i in enumerate(np.asarray(ids).reshape(-1).tolist() if isinstance(ids, np.ndarray) else ids, start=1):
        try:
            check_int(i, "command id", minimum=0, maximum=N_COMMANDS - 1)
        except ParameterError:
            raise UnknownCommandError(f"command id {i!r} at position {position} is not a command "
                                      f"(ids are 0…{N_COMMANDS - 1})") from None
        tokens.append(TOKENS[int(i)])
    return tokens


def command_set(*, diagonals: bool = False, seed004: bool = False, tokens: Iterable[str] | None = None) -> tuple[int, ...]:
    """Ids of a command set: Cheng et al. 2020's by default, plus diagonals, or Cheng et al. 2019's
    (``seed004``), or given tokens (a sequence, or a string as :func:`parse_commands` reads it).

    Repeated tokens count once.

    Raises
    ------
    UnknownCommandError
        If a token is not in the vocabulary.
    ParameterError
        If the set is empty, ``tokens`` is not a string or sequence, or a flag is not True or False.

    Examples
    --------
    >>> len(command_set()), len(command_set(diagonals=True)), len(command_set(seed004=True))
    (13, 17, 13)
    """
    diagonals, seed004 = check_bool(diagonals, "diagonals"), check_bool(seed004, "seed004")
    if tokens is not None:
        chosen = tokens if isinstance(tokens, str) else _token_list(tokens, "tokens")
    elif seed004:
        chosen = list(SEED004_COMMANDS) + (list(DIAGONAL_COMMANDS) if diagonals else [])
    else:
        chosen = list(SEED000_COMMANDS) + (list(DIAGONAL_COMMANDS) if diagonals else [])
    ids = parse_commands(chosen).tolist()
    if not ids:
        raise ParameterError("a command set needs at least one command")
    return tuple(dict.fromkeys(ids))

"""An argparse parser whose usage errors are exceptions, for command lines that report every error
as one ``error: …`` line with exit status 2 (the CLI and the studies' ``main``)."""

from __future__ import annotations

import argparse
import re

__all__ = ["UsageError", "Parser"]


class UsageError(Exception):
    """A command-line usage error: one line, exit status 2."""


class Parser(argparse.ArgumentParser):
    """``argparse.ArgumentParser`` that raises :class:`UsageError` instead of printing usage and exiting.

    A value that starts with a minus and a digit (``--weights -1,1,1,1``, ``--seed -3``) is a value,
    not an unknown option: the option's own check then says what is wrong with it.
    """

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        # argparse's own pattern knows only plain negative numbers ("-3", "-.5"); no option of ours
        # starts with a digit, so any "-<digit>…" is a value
        self._negative_number_matcher = re.compile(r"^-\.?\d")

    def error(self, message: str):
        raise UsageError(message)

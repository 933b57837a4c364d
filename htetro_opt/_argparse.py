"""An argparse parser whose usage errors are exceptions, for command lines that report every error
as one ``error: …`` line with exit status 2 (the CLI and the studies' ``main``)."""

from __future__ import annotations

import argparse

__all__ = ["UsageError", "Parser"]


class UsageError(Exception):
    """A command-line usage error: one line, exit status 2."""


class Parser(argparse.ArgumentParser):
    """``argparse.ArgumentParser`` that raises :class:`UsageError` instead of printing usage and exiting."""

    def error(self, message: str):
        raise UsageError(message)

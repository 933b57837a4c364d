"""The README stays true: its Quick start matches CI, its Python examples run, and its command-line
synopsis names only options and methods the CLI has."""

import re
from pathlib import Path

import pytest

from htetro_opt.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()


def quick_start_commands():
    section = README.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"^\s*(\S.*)$", section.split("```", 2)[1], flags=re.M)


def test_quick_start_has_exactly_two_commands():
    commands = quick_start_commands()
    assert len(commands) == 2
    assert commands[0].startswith("pip install . && htetro-opt plan ")


def test_ci_runs_the_readme_test_command():
    test_command = quick_start_commands()[1]
    ci = (ROOT / ".ci" / "run").read_text().splitlines()
    assert test_command in [line.strip() for line in ci]


def test_the_python_examples_run(tmp_path, monkeypatch, capsys):
    blocks = re.findall(r"```python\n(.*?)```", README, flags=re.S)
    assert len(blocks) >= 3
    monkeypatch.chdir(tmp_path)
    for block in blocks:  # each in a namespace of its own: every example runs when pasted alone
        exec(compile(block, "README.md", "exec"), {})
    printed = capsys.readouterr().out
    assert "dijkstra True" in printed and "htetro-ga True" in printed  # both plans reached the goal


def _subparsers(parser):
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    return sub.choices


def _subcommands():
    """Command name ("plan", "study", …) → its parser."""
    return dict(_subparsers(build_parser()))


def _command_of(entry: str) -> str:
    return entry.split()[1]


def _synopsis():
    section = README.split("## Command line", 1)[1].split("\n## ", 1)[0]
    text = section.split("```", 2)[1]
    entries, current = [], None
    for line in text.splitlines():
        if line.startswith("htetro-opt "):
            current = [line]
            entries.append(current)
        elif line.strip() and current is not None:
            current.append(line)
    return [" ".join(entry) for entry in entries]


@pytest.mark.parametrize("entry", _synopsis())
def test_the_synopsis_names_real_options_and_methods(entry):
    command = _command_of(entry)
    parser = _subcommands()[command]
    options = {s: a for a in parser._actions for s in a.option_strings}
    for flag in re.findall(r"(--[a-z-]+)", entry):
        assert flag in options, f"{command}: the README names {flag}, the CLI has no such option"
    for listed in re.findall(r"--method ([a-z0-9|-]+)", entry):
        choices = set(options["--method"].choices)
        assert set(listed.split("|")) <= choices, (command, set(listed.split("|")) - choices)


def test_every_method_is_in_the_synopsis():
    listed = set()
    for entry in _synopsis():
        for names in re.findall(r"--method ([a-z0-9|-]+)", entry):
            listed |= {(_command_of(entry), name) for name in names.split("|")}
    for command, parser in _subcommands().items():
        for action in parser._actions:
            if "--method" in action.option_strings:
                missing = {c for c in action.choices if (command, c) not in listed}
                assert not missing, f"{command} --method {missing} missing from the README"


def _relative_links(text):
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if not re.match(r"[a-z]+:", target):  # http:, https:, mailto:
            yield target.split("#", 1)[0]


@pytest.mark.parametrize("page", ["README.md", *sorted(str(p.relative_to(ROOT)) for p in (ROOT / "docs").rglob("*.md"))])
def test_every_relative_link_leads_to_a_file(page):
    source = ROOT / page
    missing = [t for t in _relative_links(source.read_text(encoding="utf-8")) if t and not (source.parent / t).exists()]
    assert not missing, f"{page} links to {missing}"


def test_the_readme_stays_short():
    words = len(re.findall(r"\S+", README))
    assert words <= 2500, f"README.md has {words} words: details belong in docs/ and benchmarks/README.md"

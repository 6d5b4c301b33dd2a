"""Every example of the README runs as written.

Extracted from README.md: fenced ```python blocks (run in a fresh namespace), the command lines
of fenced ```bash blocks (run through ``hunting.cli.main``, in a temporary directory) and the
transcripts of indented ``$ hunting ...`` lines (run, and their first printed line compared with
the one shown). A block or command preceded by ``<!-- slow -->``, and the chapter reproductions,
run in the slow suite only; a block that reads the shared data directory is skipped when it is
absent. Installing (pip) and the test suite itself (pytest) are not run from here."""
import contextlib
import io
import re
import shlex
from pathlib import Path

import pytest

from hunting.cli import main

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
SHARED = ROOT.parent / "shared" / "data"
SLOW_COMMANDS = ("reproduce", "demo", "continue")


def _fenced(text: str, lang: str) -> list[tuple[str, bool]]:
    """(code, slow) of every ```lang block; slow when the line before is <!-- slow -->."""
    out = []
    for m in re.finditer(rf"(<!-- slow -->\s*\n)?```{lang}\n(.*?)```", text, flags=re.S):
        out.append((m.group(2), bool(m.group(1))))
    return out


def _commands() -> list[tuple[str, bool]]:
    cmds = []
    for code, slow in _fenced(README, "bash"):
        for line in code.splitlines():
            for part in line.split("&&"):
                part = part.strip()
                if part.startswith("hunting "):
                    cmds.append((part, slow or part.split()[1] in SLOW_COMMANDS))
    return cmds


def _transcripts() -> list[tuple[str, str]]:
    """(command, first line shown) of every indented '$ hunting ...' line."""
    return re.findall(r"^    \$ (hunting [^\n]+)\n    ([^\n]+)", README, flags=re.M)


def _param(item, slow, label):
    return pytest.param(item, marks=[pytest.mark.slow] if slow else [], id=label)


PYTHON = [_param(code, slow, f"python-{i}-" + code.split("\n", 1)[0][:30]) for i, (code, slow)
          in enumerate(_fenced(README, "python"))]
COMMANDS = [_param(cmd, slow, cmd[:60]) for cmd, slow in _commands()]


def test_the_readme_has_examples():
    assert len(PYTHON) >= 4 and len(COMMANDS) >= 5 and len(_transcripts()) >= 2


@pytest.mark.parametrize("code", PYTHON)
def test_python_example_runs(code, monkeypatch):
    if "shared/data" in code and not SHARED.is_dir():
        pytest.skip(f"the example reads {SHARED}, which is absent")
    monkeypatch.chdir(ROOT)                    # the examples' relative paths are the checkout's
    exec(compile(code, "README.md", "exec"), {"__name__": "__readme__"})


@pytest.mark.parametrize("cmd", COMMANDS)
def test_command_line_example_runs(cmd, tmp_path, monkeypatch, capsys):
    if shlex.split(cmd)[1] == "data":          # needs the data on this machine (no network in CI)
        from hunting.datasets import DataError, emps
        try:
            emps(download=False)
        except DataError as e:
            pytest.skip(f"{cmd!r}: {e}")
    (tmp_path / "examples").symlink_to(ROOT / "examples")    # the README's commands run in a checkout
    monkeypatch.chdir(tmp_path)
    assert main(shlex.split(cmd)[1:]) == 0, capsys.readouterr().err


@pytest.mark.parametrize("cmd, shown", _transcripts(), ids=[c[:50] for c, _ in _transcripts()])
def test_transcript_prints_what_the_readme_shows(cmd, shown, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        main(shlex.split(cmd)[1:])
    first = (err.getvalue() or out.getvalue()).splitlines()[0]
    assert first.startswith(shown.split("...")[0].rstrip()), (first, shown)     # "..." elides the rest

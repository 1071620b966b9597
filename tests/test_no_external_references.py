"""The code and docs refer only to what the repository holds: no issue numbers, no commit hashes, no design notes
or folders kept beside it. A reader of a clone has none of those, so a reference to one explains nothing.

The patterns are narrow on purpose, so that legitimate text cannot match: a commit hash counts only where the
text names it as one (after "commit", "revision", "at", "before", "after", "since" or "against", or as a short
hash alone in parentheses or with "'s"), because hex digits also appear as content hashes, case ids and kernel
names."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
SCANNED_FOLDERS = ("cosim", "controllers", "tests", "docs", "examples", ".ci")
SCANNED_FILES = ("README.md", "pyproject.toml")
TEXT_SUFFIXES = {".py", ".md", ".toml", ".txt", ".cfg", ".ini", ".yaml", ".yml", ".sh", ""}

# a hex token with at least one letter and one digit (so that neither a word nor a number matches)
_HEX = r"(?=[0-9a-f]*[a-f])(?=[0-9a-f]*[0-9])"
FORBIDDEN = {
    "an issue number or title": re.compile(r"\bissues? ?(#\s?\d+\b|\d+\b|\")", re.IGNORECASE),
    "a commit hash": re.compile(
        rf"\b(?:commits?|revisions?|at|before|after|since|against) \(?{_HEX}[0-9a-f]{{7,40}}\b"
        rf"|\({_HEX}[0-9a-f]{{7,9}}[,)]"
        rf"|\b{_HEX}[0-9a-f]{{7,9}}'s\b"
    ),
    "the design notes kept outside the repository": re.compile(r"\bDESIGN\.md\b"),
    "a folder beside the repository": re.compile(r"\.\./shared\b"),
}


def scanned_files() -> list[Path]:
    """Every text file of the scanned folders (and the scanned top-level files), this test's own file excepted."""
    files = [ROOT / name for name in SCANNED_FILES]
    for folder in SCANNED_FOLDERS:
        files += [p for p in (ROOT / folder).rglob("*") if p.is_file() and p.suffix in TEXT_SUFFIXES]
    this = Path(__file__).resolve()
    return sorted(p for p in files if p.resolve() != this and "__pycache__" not in p.parts)


def references(text: str) -> list[tuple[int, str, str]]:
    """(line number, what it refers to, the matched text) of every forbidden reference in ``text``."""
    found = []
    for number, line in enumerate(text.splitlines(), start=1):
        for what, pattern in FORBIDDEN.items():
            found += [(number, what, m.group(0)) for m in pattern.finditer(line)]
    return found


@pytest.mark.parametrize("text", [
    "see issue 36", "Acceptance (issue \"Fluid core\")", "as in issue #12", "before 911fb23 a path",
    "the code at ae36d4f", "Before (a22989f):", "a514bfd's run", "(0cc61d5, from a second checkout)",
    "read DESIGN.md", "under ../shared/gpu",
])
def test_each_kind_of_reference_is_caught(text):
    assert references(text), text


@pytest.mark.parametrize("text", [
    "trajectory.csv SHA-256 61404b118e2c", "here (f26bb3b43a99)", "| 4970b094071b | tilt |",
    "forward kernel accumulate_wall_wrench_e10309f4", "assert c.id == \"bdd0ac7cc31f\"", "at 1000000 particles",
    "before the face", "--out /shared/sweeps/my_sweep", "seed = 0", "issues a warning", "tissue 3",
])
def test_legitimate_text_is_not_caught(text):
    assert not references(text), references(text)


def test_the_code_and_docs_refer_to_nothing_outside_the_repository():
    files = scanned_files()
    assert any(p.suffix == ".md" for p in files) and any(p.suffix == ".py" for p in files)
    hits = [f"{p.relative_to(ROOT)}:{n}: {what}: {match!r}"
            for p in files for n, what, match in references(p.read_text(encoding="utf-8", errors="replace"))]
    assert not hits, "\n".join(hits)

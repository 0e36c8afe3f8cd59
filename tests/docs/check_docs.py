#!/usr/bin/python3
"""The docs say what is: no reference doc carries a work-log entry or an issue number.

  check_docs.py ROOT

Scans ROOT/README.md, every README.md below ROOT (hidden folders and build trees left out) and
every ROOT/docs/*.md but docs/HISTORY.md, which is where the project's history lives. Reports
each offending line as `path:line: text` (path relative to ROOT), one per line, and exits 1 when
there is any, 0 when there is none, 2 when ROOT is not a folder.

What counts as a work-log entry or an issue number (case-insensitive):
  - an issue of this project: "issue 27", "issues 13 and 27", "issue #27", a bare "#27" or
    "(#27)"; a reference of another repository, "equidiff#9", "lerobot#3983",
    "huggingface/lerobot#3983", is a citation and passes, as does a Markdown anchor
    "(#1-sanitizers-in-ci)";
  - a numbered session ("session 24", "session-3 prototype", "sessions 21-22") or work period;
  - a round of work: "Third round" ... "Ninth round", "round 3";
  - a superseded measurement or a list of experiments: "Measured before", "Levers tried".
"""
import os
import pathlib
import re
import sys

HISTORY = pathlib.PurePosixPath("docs/HISTORY.md")
# Folders whose README.md files are not the project's docs: hidden ones, build trees
# (build/, build-asan/, ...), virtual environments, caches.
SKIPPED_DIRS = re.compile(r"^(\.|build|venv|__pycache__$|node_modules$)")

ORDINALS = ("first|second|third|fourth|fifth|sixth|seventh|eighth|ninth|tenth|eleventh|"
            "twelfth|thirteenth|fourteenth|fifteenth")
PATTERNS = [
    ("an issue number", re.compile(r"\bissues?\s+#?\d+", re.IGNORECASE)),
    # A number after '#' with no repository name (letters, digits, '_', '.', '-', '/') right
    # before it; a Markdown anchor such as "#1-sanitizers" is not one.
    ("an issue number", re.compile(r"(?<![\w.\-/])#\d+\b(?!-\w)")),
    ("a work-log session", re.compile(r"\bsessions?[\s-]+\d+", re.IGNORECASE)),
    ("a work period", re.compile(r"\bwork(?:ing)?\s+periods?\b", re.IGNORECASE)),
    ("a round of work", re.compile(rf"\b(?:{ORDINALS})\s+rounds?\b", re.IGNORECASE)),
    ("a round of work", re.compile(r"\brounds?\s+\d+\b", re.IGNORECASE)),
    ("a superseded measurement", re.compile(r"\bmeasured before\b", re.IGNORECASE)),
    ("a list of levers tried", re.compile(r"\blevers?\s+tried\b", re.IGNORECASE)),
]


def docs(root: pathlib.Path) -> list[pathlib.Path]:
    """The files to check, sorted: README.md files at any depth and docs/*.md."""
    found = set()
    for folder, subfolders, files in os.walk(root):
        subfolders[:] = [d for d in subfolders if not SKIPPED_DIRS.match(d)]
        if "README.md" in files:
            found.add(pathlib.Path(folder) / "README.md")
    found.update(p for p in (root / "docs").glob("*.md") if p.is_file())
    return sorted(p for p in found
                  if pathlib.PurePosixPath(p.relative_to(root).as_posix()) != HISTORY)


def offences(root: pathlib.Path) -> list[str]:
    lines = []
    for path in docs(root):
        relative = path.relative_to(root).as_posix()
        text = path.read_text(encoding="utf-8", errors="replace")
        for number, line in enumerate(text.splitlines(), 1):
            if any(pattern.search(line) for _, pattern in PATTERNS):
                lines.append(f"{relative}:{number}: {line.strip()}")
    return lines


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    root = pathlib.Path(argv[1])
    if not root.is_dir():
        print(f"check_docs: '{root}' is not a folder", file=sys.stderr)
        return 2
    found = offences(root)
    for line in found:
        print(line)
    if found:
        print(f"check_docs: {len(found)} line(s) with a work-log entry or an issue number; "
              "history goes to docs/HISTORY.md", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

"""check_docs.py on small trees: a clean tree passes, and each kind of work-log line planted in a
doc fails the check with its path and line number. Runs with the standard library and pytest."""
import pathlib
import subprocess
import sys

import pytest

CHECK = pathlib.Path(__file__).resolve().parent / "check_docs.py"

CLEAN = {
    "README.md": "# project\n\nWhat it is.\n\n`bash scripts/test.sh` builds and tests.\n",
    "docs/BENCHMARKS.md": "# Benchmarks\n\nMeasured 2026-12-05 on two idle cores: 1.2 s.\n",
    "docs/HISTORY.md": "# History\n\n- Session 24, issue 27 (#27): the Ninth round.\n",
    "core/README.md": "# core/\n\nGeometry. Three rounds of ConcatEven; round trips.\n",
    "tests/core/README.md": "# tests/core/\n\nOne executable.\n",
    "build/README.md": "# a build tree: not a doc\n\nissue 12\n",
}


def make_tree(root: pathlib.Path, files: dict[str, str]) -> pathlib.Path:
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return root


def run(root: pathlib.Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(CHECK), str(root)], capture_output=True,
                          text=True, check=False)


def test_a_clean_tree_passes(tmp_path):
    result = run(make_tree(tmp_path, CLEAN))
    assert result.returncode == 0, result.stdout + result.stderr
    assert result.stdout == ""


@pytest.mark.parametrize("line", [
    "Measured in session 12 on the shared host.",
    "The sanitizer run (issue 27, item 3) takes 5 minutes.",
    "Both issues 13 and 27 asked for it.",
    "Fixed in the pipe (#27).",
    "The bound of #4 holds.",
    "#### Ninth round (2026-12-05): the slices on both cores",
    "The third round kept the tile.",
    "In round 3 the step got faster.",
    "Work period 7 moved it.",
    "## Measured before the mirror images",
    "**Levers tried on branch img2**",
    "a core computing its half (the session-3 prototype)",
])
def test_a_planted_work_log_line_fails_and_is_named(tmp_path, line):
    files = dict(CLEAN)
    files["docs/BENCHMARKS.md"] += "\n" + line + "\n"  # line 5 of the file
    result = run(make_tree(tmp_path, files))
    assert result.returncode == 1
    assert result.stdout == f"docs/BENCHMARKS.md:5: {line}\n"


@pytest.mark.parametrize("name", ["README.md", "core/README.md", "tests/core/README.md"])
def test_every_readme_is_checked_at_any_depth(tmp_path, name):
    files = dict(CLEAN)
    files[name] = "# folder\n\nAdded in session 9.\n"
    result = run(make_tree(tmp_path, files))
    assert result.returncode == 1
    assert result.stdout == f"{name}:3: Added in session 9.\n"


@pytest.mark.parametrize("line", [
    "Diffusion Policy's sampler (equidiff#9) starts from noise.",
    "LeRobot's relative actions (huggingface/lerobot#3983, lerobot#3983).",
    "openpi#445 keeps the gripper absolute.",
    "See [the first item](#1-sanitizers-in-ci) and docs/RELIABILITY.md#1-sanitizers-in-ci.",
    "Anchored lines: claims.html#L12.",
])
def test_citations_of_other_repositories_and_anchors_pass(tmp_path, line):
    files = dict(CLEAN)
    files["docs/CONVENTIONS.md"] = f"# Conventions\n\n{line}\n"
    result = run(make_tree(tmp_path, files))
    assert result.returncode == 0, result.stdout


def test_the_history_file_and_build_trees_are_not_checked(tmp_path):
    result = run(make_tree(tmp_path, CLEAN))
    assert "HISTORY" not in result.stdout and "build/" not in result.stdout
    assert result.returncode == 0


def test_a_root_that_is_not_a_folder_is_a_usage_error(tmp_path):
    result = run(tmp_path / "missing")
    assert result.returncode == 2
    assert "is not a folder" in result.stderr

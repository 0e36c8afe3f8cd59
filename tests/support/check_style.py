#!/usr/bin/python3
"""The house style, checked: every tracked C++ file formatted as .clang-format says, and no line
over 100 columns in the C++, CMake, shell and Python files.

  check_style.py --root DIR --clang-format PATH [FILE ...]

Without FILEs it checks the files git tracks under DIR; with them, only those (the test of the
check itself). Exit 0 when everything conforms, 1 with one line per offence otherwise, 2 when
the files cannot be listed.
"""
import argparse
import pathlib
import subprocess
import sys

MAX_COLUMNS = 100
CXX = (".cpp", ".hpp", ".h")
TEXT = CXX + (".cmake", ".in", ".sh", ".py")
# Files without one of those suffixes that hold code.
NAMES = ("CMakeLists.txt", "run")


def tracked(root: pathlib.Path) -> list[pathlib.Path]:
    try:
        out = subprocess.run(["git", "-C", str(root), "ls-files"], check=True,
                             capture_output=True, text=True).stdout
    except (OSError, subprocess.CalledProcessError) as e:
        print(f"check_style: cannot list the files git tracks under {root}: {e}", file=sys.stderr)
        sys.exit(2)
    return [root / line for line in out.splitlines() if line]


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--root", required=True, type=pathlib.Path)
    parser.add_argument("--clang-format", required=True)
    parser.add_argument("files", nargs="*", type=pathlib.Path)
    args = parser.parse_args()
    files = [p for p in (args.files or tracked(args.root))
             if (p.suffix in TEXT or p.name in NAMES) and p.is_file()]
    offences = []
    for path in files:
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            if len(line) > MAX_COLUMNS:
                offences.append(f"{path}:{number}: {len(line)} columns (at most {MAX_COLUMNS})")
    cxx = [str(p) for p in files if p.suffix in CXX]
    if cxx:
        # The project's .clang-format, also for files outside the tree (the check's own test).
        style = f"--style=file:{args.root.resolve() / '.clang-format'}"
        try:
            result = subprocess.run([args.clang_format, "--dry-run", "--Werror", style, *cxx],
                                    capture_output=True, text=True, cwd=args.root)
        except OSError as e:
            print(f"check_style: cannot run clang-format '{args.clang_format}': {e}",
                  file=sys.stderr)
            return 2
        offences += [line for line in result.stderr.splitlines() if ": error: " in line]
        if result.returncode != 0 and not any(": error: " in o for o in offences):
            offences.append(f"clang-format failed: {result.stderr.strip()}")
    for offence in offences:
        print(offence)
    print(f"check_style: {len(offences)} offence(s) in {len(files)} file(s)")
    return 1 if offences else 0


if __name__ == "__main__":
    sys.exit(main())

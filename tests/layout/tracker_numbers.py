#!/usr/bin/python3
"""Refuses a tracker number in what the project says to its users.

    tracker_numbers.py [ROOT]

A reader of the code, the docs, a scene, a sweep or a test cannot see the project's tracker, so the
word "issue" followed by a number tells them nothing: the requirement or the reason belongs there
instead. Every text file under ROOT (default: two folders up) outside hidden folders and build trees
is read; each "issue" or "issues" followed by a number (any case, "#" allowed) is reported as
file:line and the exit is 1. An upstream project's tracker written as owner/repo#N is not ours and
passes.
"""
import os
import re
import sys

# "issue"/"issues" and a number, or a bare "#N" after see / fixes / closes.
TRACKER = re.compile(r"\bissues?\s*#?\s*\d+|\b(?:see|fixes|closes)\s+#\d+", re.IGNORECASE)
TEXT_SUFFIXES = (".cpp", ".hpp", ".h", ".md", ".yaml", ".yml", ".txt", ".py", ".sh", ".lcm", ".dbc",
                 ".cmake", ".in", ".json", ".csv")
SKIP_DIRS = ("build", "third_party")


def text_files(root):
    for folder, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs if not d.startswith(".") and not d.startswith(SKIP_DIRS))
        for name in sorted(files):
            path = os.path.join(folder, name)
            if name.endswith(TEXT_SUFFIXES) or name in ("CMakeLists.txt", "README") or _is_script(path):
                yield path


def _is_script(path):
    try:
        with open(path, "rb") as f:
            return f.read(2) == b"#!"
    except OSError:
        return False


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..")
    if not os.path.isdir(root):
        print(f"tracker numbers: {root}: not a folder", file=sys.stderr)
        return 2
    found = 0
    checked = 0
    for path in text_files(root):
        checked += 1
        try:
            lines = open(path, encoding="utf-8").read().splitlines()
        except (OSError, UnicodeDecodeError):
            continue
        for number, line in enumerate(lines, 1):
            for m in TRACKER.finditer(line):
                print(f"{os.path.relpath(path, root)}:{number}: \"{m.group(0)}\": write the requirement or "
                      f"the reason itself, not a tracker number")
                found += 1
    print(f"tracker numbers: {checked} files read, {found} tracker numbers found")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())

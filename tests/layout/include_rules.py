#!/usr/bin/python3
"""Checks every product source's includes against the floor table of docs/architecture.md.

    include_rules.py [ROOT]

ROOT (default: two folders up) is a source tree. The rules are read from the table between the
markers `<!-- include rules: begin -->` and `<!-- include rules: end -->` in ROOT/docs/architecture.md,
so the map and the check cannot disagree. Each row names a folder (`hal/`), a room of a folder
(`firmware/control/laws/`), one tool folder each (`tools/*/`) or a file prefix (`sim_plant/plant_node`),
and what its files may include besides their own: rows (a folder or a file prefix, with what that row
may include in turn) or single files. A row may name only rows above it, so the floors cannot form a
circle.

Every .cpp, .hpp and .h outside tests/, hidden folders and build trees is a product source. Each
#include "..." (and each #include <...> that names one of our folders) is resolved as the compiler
would: beside the including file, from ROOT, from ROOT/firmware (the firmware's include root), as a
generated header (exlcm/ from lcmtypes/, message_fields.hpp from log_export/), or by its file name
through a library's include folder. Exit 1, naming file:line, for an include its row does not allow,
one that cannot be resolved, or a source that no row covers; exit 2 for a missing or bad table.
A source belongs to the longest row that covers it: a room with a row of its own is a floor of its own
(firmware/control/'s rooms are), and its folder's row covers the folder's own files; a folder's rooms
without rows of their own are of its floor and include each other. A file-prefix row's own files are
those of its prefix (`sim_plant/plant_node.hpp` and `.cpp`), not the rest of their folder.
"""
import os
import re
import sys

BEGIN, END = "<!-- include rules: begin -->", "<!-- include rules: end -->"
SOURCE_SUFFIXES = (".cpp", ".hpp", ".h")
# Headers generated into the build tree, and the folder whose build generates them.
GENERATED = (("exlcm/", "lcmtypes/"), ("message_fields.hpp", "log_export/"))
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^">]+)[">]')


def fail_table(message):
    print(f"include rules: docs/architecture.md: {message}", file=sys.stderr)
    sys.exit(2)


def read_rules(root):
    path = os.path.join(root, "docs", "architecture.md")
    try:
        text = open(path, encoding="utf-8").read()
    except OSError as e:
        fail_table(f"cannot read it ({e.strerror})")
    if BEGIN not in text or END not in text:
        fail_table(f"no table between '{BEGIN}' and '{END}'")
    block = text.split(BEGIN, 1)[1].split(END, 1)[0]
    rows = []  # (key, [entries]) in table order, bottom floor first
    for number, line in enumerate(block.splitlines(), 1):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) < 2 or not cells[0].startswith("`"):
            continue  # header, separator or prose
        key = cells[0].strip("`")
        entries = re.findall(r"`([^`]+)`", cells[1])
        known = [k for k, _ in rows]
        for entry in entries:
            if entry not in known and not any(entry.startswith(k) for k in known if k.endswith("/")):
                fail_table(f"row `{key}` may include `{entry}`, which is no row above it "
                           "(a row names only floors below it)")
        rows.append((key, entries))
    if not rows:
        fail_table("the include-rules table has no rows")
    return rows


def allowed_targets(rows, key):
    """The row's entries, and for each entry that is a row what that row allows, recursively."""
    table = dict(rows)
    result, stack = set(), list(table[key])
    while stack:
        entry = stack.pop()
        if entry in result:
            continue
        result.add(entry)
        if entry in table:
            stack.extend(table[entry])
    return result


def is_allowed(rows, allowed, target):
    """A single file entry allows that file; a row (a folder or a file prefix) what it covers."""
    keys = {k for k, _ in rows}
    return any(target == a or (target.startswith(a) and (a.endswith("/") or a in keys)) for a in allowed)


def row_of(rows, path):
    """The row covering a source path: the longest matching key; `tools/*/` covers each tool folder."""
    best = None
    for key, _ in rows:
        if key.endswith("*/"):
            prefix = key[:-2]
            match = path.startswith(prefix) and path[len(prefix):].count("/") == 1
        else:
            match = path.startswith(key)
        if match and (best is None or len(key) > len(best)):
            best = key
    return best


def product_sources(root):
    sources = []
    for folder, subfolders, names in os.walk(root):
        rel = os.path.relpath(folder, root)
        subfolders[:] = sorted(
            d for d in subfolders
            if not d.startswith(".") and not (rel == "." and d == "tests")
            and not os.path.exists(os.path.join(folder, d, "CMakeCache.txt")))
        for name in sorted(names):
            if name.endswith(SOURCE_SUFFIXES):
                sources.append(os.path.normpath(os.path.join(rel, name)))
    return sources


def resolve(root, source, name, by_file_name, angle):
    here = os.path.dirname(source)
    candidates = [name, os.path.join("firmware", name)]
    if not angle:
        candidates.insert(0, os.path.join(here, name))
    for candidate in candidates:
        if os.path.isfile(os.path.join(root, candidate)):
            return os.path.normpath(candidate)
    if angle:
        return None  # a system or third-party header
    for prefix, folder in GENERATED:
        if name.startswith(prefix):
            return folder + name
    found = by_file_name.get(name, []) if "/" not in name else []
    return found[0] if len(found) == 1 else ""


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else
                           os.path.join(os.path.dirname(__file__), "..", ".."))
    rows = read_rules(root)
    sources = product_sources(root)
    by_file_name = {}
    for s in sources:
        by_file_name.setdefault(os.path.basename(s), []).append(s)
    problems, includes = [], 0
    for source in sources:
        key = row_of(rows, source)
        if key is None:
            problems.append(f"{source}:1: not on the map: no row of docs/architecture.md's include "
                            "rules covers its folder (add one, in floor order)")
            continue
        allowed = allowed_targets(rows, key)
        # A folder's row covers its files and the rooms that have no row of their own (a room with a
        # row is matched by it, the longer key); a tool folder's row, that tool's folder; a
        # file-prefix row, the files of its prefix.
        if key.endswith("*/"):
            own = os.path.dirname(source) + "/"
        else:
            own = key
        with open(os.path.join(root, source), encoding="utf-8", errors="replace") as f:
            for number, line in enumerate(f, 1):
                m = INCLUDE.match(line)
                if not m:
                    continue
                angle, name = m.group(1) == "<", m.group(2)
                target = resolve(root, source, name, by_file_name, angle)
                if target is None:
                    continue
                includes += 1
                if target == "":
                    problems.append(f'{source}:{number}: #include "{name}" names no file of ours '
                                    "(nor a unique file name, nor a generated header)")
                    continue
                if target.startswith(own) and (own == key or "/" not in target[len(own):]):
                    continue
                if is_allowed(rows, allowed, target):
                    continue
                problems.append(f'{source}:{number}: #include "{name}" ({target}) is not allowed: '
                                f"`{key}` may include {', '.join(sorted(allowed)) or 'nothing of ours'} "
                                "(docs/architecture.md, include rules)")
    for p in problems:
        print(p)
    print(f"include rules: {len(sources)} product sources, {includes} includes of ours checked against "
          f"{len(rows)} rows: {len(problems)} not allowed")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/python3
"""Holds docs/architecture.md's map to the tree: its floors and rooms, its programs, its arrows.

    architecture_map.py [ROOT]

ROOT (default: two folders up) is a source tree. What is checked is read from ROOT/docs/architecture.md,
so that moving a folder needs only the doc updated:

- the floors block, between `<!-- floors: begin -->` and `<!-- floors: end -->`: a line that begins
  with a name ending in `/` names a floor (a folder of ROOT); a name ending in `/` followed by two
  spaces at the head of a line's second column (after the floor's name, or after spaces) names a room
  of the floor above it (`control/laws/` under `firmware/` is `firmware/control/laws/`). Every floor
  and room named must exist; every folder that holds product sources (outside tests/, hidden folders
  and build trees) must be a floor, a room or a program's folder of the table of programs.
- the table of programs, between `<!-- programs: begin -->` and `<!-- programs: end -->`: rows
  `| `name` | `tools/folder/` | ... |`. Each must be a program of that folder, and every program of
  tools/ must be a row. A program is each add_executable of a tools/*/CMakeLists.txt, and each
  executable script (a file with its execute bit and a `#!` line) in tools/ or a folder of it, under
  the name an install(PROGRAMS ... RENAME name) gives it.
- the include rules' table (read as include_rules.py reads it): every folder row is a floor, a room
  or a program's folder of the map.
- the table of namespaces, between `<!-- namespaces: begin -->` and `<!-- namespaces: end -->`: rows
  `| `folder/` | `exc::name`, ... |`. Every C++ source of ROOT (outside tests/ and build trees) that
  opens a `namespace exc...` block holding more than forward declarations lies under a row (the
  longest that holds it), and every such block is one of that row's namespaces; every row's folder
  exists and opens each of its namespaces somewhere.
- every path the doc names in backquotes (`sim_plant/plant.cpp`; the firmware's from firmware/,
  `control/laws/pid.hpp`; a file prefix, `sim_plant/plant_node`), the include rules' arrows among them,
  names a file or folder of ROOT.

Exit 1 naming each claim that is false (the doc's line, or the folder or file off the map); exit 2 for
a missing or unreadable block.
"""
import os
import re
import stat
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import include_rules  # noqa: E402  (the include-rules table's reader, beside this file)

DOC = "docs/architecture.md"
FLOORS = ("<!-- floors: begin -->", "<!-- floors: end -->")
PROGRAMS = ("<!-- programs: begin -->", "<!-- programs: end -->")
NAMESPACES = ("<!-- namespaces: begin -->", "<!-- namespaces: end -->")
CPP_SUFFIXES = (".cpp", ".hpp", ".h", ".cpp.in", ".hpp.in")
NAMESPACE_OPEN = re.compile(r"^namespace (exc(?:::[a-z_]+)*) \{\s*$")
FORWARD_DECLARATION = re.compile(r"^(class|struct) [A-Za-z_][A-Za-z0-9_]*;$")
# Files that make a folder one of product sources: code, assembly, linker scripts, LCM types, Python,
# a build file; executable scripts are found by their mode.
SOURCE_SUFFIXES = (".cpp", ".hpp", ".h", ".c", ".S", ".ld", ".lcm", ".py")
FLOOR_LINE = re.compile(r"^([A-Za-z0-9_.-]+/)(?=\s)")
ROOM_AFTER = re.compile(r"^\s+((?:[A-Za-z0-9_.-]+/)+) {2,}\S")
ADD_EXECUTABLE = re.compile(r"^\s*add_executable\(\s*([A-Za-z0-9_.+-]+)", re.M)
INSTALL_PROGRAMS = re.compile(r"install\(\s*PROGRAMS\s+([^)]*)\)", re.S)
BACKQUOTED = re.compile(r"`([^`\s]+)`")
PATH_LIKE = re.compile(r'^"?([A-Za-z0-9_.-]+/)+([A-Za-z0-9_.*-]+)?"?$')


def fail_doc(message):
    print(f"architecture map: {DOC}: {message}", file=sys.stderr)
    sys.exit(2)


def block(text, markers, what):
    begin, end = markers
    if begin not in text or end not in text:
        fail_doc(f"no {what} between '{begin}' and '{end}'")
    start = text.index(begin)
    first_line = text.count("\n", 0, start) + 1
    return first_line, text[start:].split(end, 1)[0].splitlines()


def read_floors(text):
    """{floor: line}, {room (floor + name): line} from the floors block."""
    first, lines = block(text, FLOORS, "floors block")
    floors, rooms, floor = {}, {}, None
    for offset, line in enumerate(lines):
        number = first + offset
        m = FLOOR_LINE.match(line)
        rest = line
        if m:
            floor = m.group(1)
            floors[floor] = number
            rest = line[len(floor):]
        room = ROOM_AFTER.match(rest)
        if room and floor is not None:
            rooms[floor + room.group(1)] = number
    if not floors:
        fail_doc("the floors block names no floor")
    return floors, rooms


def table_rows(text, markers, what):
    """[(line, cells)] of a table's rows between markers whose first cell is backquoted."""
    first, lines = block(text, markers, what)
    rows = []
    for offset, line in enumerate(lines):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) >= 2 and cells[0].startswith("`"):  # not the header, the separator or prose
            rows.append((first + offset, cells))
    if not rows:
        fail_doc(f"the {what} has no rows")
    return rows


def read_programs(text):
    """{(name, folder): line} from the table of programs."""
    programs = {}
    for number, cells in table_rows(text, PROGRAMS, "table of programs"):
        folder = cells[1].strip("`")
        if not folder.endswith("/"):
            folder += "/"
        programs[(cells[0].strip("`"), folder)] = number
    return programs


def read_namespaces(text):
    """{folder/: (line, [namespace, ...])} from the table of namespaces."""
    return {cells[0].strip("`"): (number, re.findall(r"`(exc(?:::[a-z_]+)*)`", cells[1]))
            for number, cells in table_rows(text, NAMESPACES, "table of namespaces")}


def namespace_blocks(path):
    """[(line, namespace)] of each `namespace exc...` block of a source that holds more than forward
    declarations (a block ends at the first `}` in column 0 after it)."""
    found = []
    lines = open(path, encoding="utf-8", errors="replace").read().splitlines()
    i = 0
    while i < len(lines):
        m = NAMESPACE_OPEN.match(lines[i])
        if not m:
            i += 1
            continue
        start, body = i, []
        i += 1
        while i < len(lines) and not lines[i].startswith("}"):
            code = lines[i].split("//", 1)[0].strip()
            if code:
                body.append(code)
            i += 1
        if not all(FORWARD_DECLARATION.match(b) for b in body):
            found.append((start + 1, m.group(1)))
    return found


def cpp_sources(root):
    """Every C++ source of ROOT outside tests/, hidden folders and build trees, relative."""
    for folder, subfolders, names in os.walk(root):
        rel = os.path.relpath(folder, root)
        subfolders[:] = sorted(d for d in subfolders
                               if not d.startswith(".") and not (rel == "." and d == "tests")
                               and not is_build_tree(os.path.join(folder, d)))
        for name in sorted(names):
            if name.endswith(CPP_SUFFIXES):
                yield os.path.relpath(os.path.join(folder, name), root).replace(os.sep, "/")


def is_build_tree(path):
    return os.path.exists(os.path.join(path, "CMakeCache.txt"))


def is_script(path):
    try:
        mode = os.stat(path).st_mode
        if not stat.S_ISREG(mode) or not mode & stat.S_IXUSR:
            return False
        with open(path, "rb") as f:
            return f.read(2) == b"#!"
    except OSError:
        return False


def source_folders(root):
    """{folder/: a product source in it} for every folder of ROOT but ROOT, tests/ and hidden ones."""
    found = {}
    for folder, subfolders, names in os.walk(root):
        rel = os.path.relpath(folder, root)
        subfolders[:] = sorted(d for d in subfolders
                               if not d.startswith(".") and not (rel == "." and d == "tests")
                               and not is_build_tree(os.path.join(folder, d)))
        if rel == ".":
            continue
        for name in sorted(names):
            if name.endswith(SOURCE_SUFFIXES) or name == "CMakeLists.txt" or is_script(os.path.join(folder, name)):
                found[rel.replace(os.sep, "/") + "/"] = name
                break
    return found


def tool_programs(root):
    """{(name, folder): the file that makes it} for tools/ and each folder of it."""
    programs = {}
    tools = os.path.join(root, "tools")
    if not os.path.isdir(tools):
        return programs
    folders = ["tools/"] + sorted(f"tools/{d}/" for d in os.listdir(tools)
                                  if os.path.isdir(os.path.join(tools, d)) and not d.startswith("."))
    for folder in folders:
        path = os.path.join(root, folder)
        renamed = {}
        cmake = os.path.join(path, "CMakeLists.txt")
        if os.path.isfile(cmake):
            text = re.sub(r"#[^\n]*", "", open(cmake, encoding="utf-8", errors="replace").read())
            for name in ADD_EXECUTABLE.findall(text):
                programs[(name, folder)] = folder + "CMakeLists.txt"
            for args in INSTALL_PROGRAMS.findall(text):
                words = args.split()
                if "RENAME" in words and words.index("RENAME") + 1 < len(words) and words:
                    renamed[words[0]] = words[words.index("RENAME") + 1]
        for name in sorted(os.listdir(path)):
            if is_script(os.path.join(path, name)):
                programs[(renamed.get(name, name), folder)] = folder + name
    return programs


def exists(root, relative):
    """A folder, a file or a file prefix (`sim_plant/plant_node`, `sim_plant/plant_node.*`) of ROOT."""
    relative = relative.rstrip("*").rstrip(".") if relative.endswith("*") else relative
    if os.path.exists(os.path.join(root, relative)):
        return True
    folder, prefix = os.path.split(relative)
    if not prefix or not os.path.isdir(os.path.join(root, folder)):
        return False
    return any(n.startswith(prefix) for n in os.listdir(os.path.join(root, folder)))


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else
                           os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    try:
        text = open(os.path.join(root, DOC), encoding="utf-8").read()
    except OSError as e:
        fail_doc(f"cannot read it ({e.strerror})")
    floors, rooms = read_floors(text)
    programs = read_programs(text)
    problems = []

    # Floors and rooms: each named one exists.
    for floor, line in floors.items():
        if not os.path.isdir(os.path.join(root, floor)):
            problems.append(f"{DOC}:{line}: floor `{floor}` is on the map but no such folder exists")
    for room, line in rooms.items():
        if not os.path.isdir(os.path.join(root, room)):
            problems.append(f"{DOC}:{line}: room `{room}` is on the map but no such folder exists")

    # Every folder with product sources is on the map.
    program_folders = {folder for _, folder in programs}
    sources = source_folders(root)
    for folder, example in sources.items():
        if folder in program_folders or folder in floors or folder in rooms:
            continue
        top = folder.split("/", 1)[0] + "/"
        where = (f"no floor `{top}`" if top not in floors else
                 f"floor `{top}` lists no room `{folder[len(top):]}`")
        problems.append(f"{folder}{example}: folder `{folder}` holds product sources but is not on the map "
                        f"({where} in {DOC}'s floors block, and no program of the table lives there)")

    # Programs: the table and tools/ agree both ways.
    made = tool_programs(root)
    for (name, folder), line in programs.items():
        if (name, folder) not in made:
            elsewhere = sorted(f for n, f in made if n == name)
            hint = f" (it is in {', '.join(elsewhere)})" if elsewhere else ""
            problems.append(f"{DOC}:{line}: program `{name}` ({folder}) is on the map but {folder} makes no "
                            f"such program (no add_executable, no executable script){hint}")
    for (name, folder), source in sorted(made.items()):
        if (name, folder) not in programs:
            problems.append(f"{source}: program `{name}` ({folder}) is not on the map (no row of {DOC}'s "
                            "table of programs)")

    # The include rules' rows are on the map (what their arrows name exists: the paths below).
    for key, _ in include_rules.read_rules(root):
        if key.endswith("/") and key != "tools/*/" and key not in floors and key not in rooms \
                and key not in program_folders:
            problems.append(f"{DOC}: include rules: row `{key}` is no floor, room or program's folder of the map")

    # Namespaces: each source's defining blocks are its folder's, and each row is used.
    namespace_rows = read_namespaces(text)
    opened = {}
    for source in cpp_sources(root):
        blocks = namespace_blocks(os.path.join(root, source))
        if not blocks:
            continue
        row = max((f for f in namespace_rows if source.startswith(f)), key=len, default=None)
        if row is None:
            problems.append(f"{source}:{blocks[0][0]}: opens `{blocks[0][1]}` but its folder has no row in {DOC}'s "
                            "table of namespaces")
            continue
        line, allowed = namespace_rows[row]
        for number, name in blocks:
            opened.setdefault(row, set()).add(name)
            if name not in allowed:
                problems.append(f"{source}:{number}: opens `{name}`; {DOC}:{line} gives `{row}` "
                                f"{', '.join('`' + a + '`' for a in allowed)}")
    for row, (line, allowed) in namespace_rows.items():
        if not os.path.isdir(os.path.join(root, row)):
            problems.append(f"{DOC}:{line}: namespace row `{row}` names no folder of the tree")
            continue
        for name in allowed:
            if name not in opened.get(row, set()):
                problems.append(f"{DOC}:{line}: `{row}` is given `{name}`, which none of its sources opens")

    # Every path named in backquotes exists (the firmware's from firmware/).
    paths = 0
    for number, line in enumerate(text.splitlines(), 1):
        for quoted in BACKQUOTED.findall(line):
            if not PATH_LIKE.match(quoted) or "*/" in quoted:
                continue
            name = quoted.strip('"')
            paths += 1
            if not (exists(root, name) or exists(root, "firmware/" + name)):
                problems.append(f"{DOC}:{number}: `{name}` names no file or folder of the tree")

    for p in problems:
        print(p)
    print(f"architecture map: {len(floors)} floors, {len(rooms)} rooms, {len(sources)} folders with sources, "
          f"{len(programs)} programs on the map against {len(made)} in tools/, {len(namespace_rows)} namespace rows, "
          f"{paths} paths named: "
          f"{len(problems)} false")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())

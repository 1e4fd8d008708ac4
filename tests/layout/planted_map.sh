#!/bin/bash
# planted_map.sh CHECKER SOURCE WORK: the architecture-map check can fail. A scratch copy of SOURCE
# (its folders but hidden ones and build trees, with docs/architecture.md) passes (the
# control); then a room on the map that does not exist, a program of tools/ missing from the map (an
# executable target and a script), a program on the map that tools/ does not make, a folder of sources
# off the map, a path the doc names that does not exist, an include rule for a folder that is
# neither in the tree nor on the map, a source defining in another floor's namespace (the plant's node
# in the firmware's app), a source whose folder has no namespace row and a namespace row none of its
# folder's sources opens must each fail the check, named.
set -u
checker=$1 source=$2 work=$3
rm -rf "$work" && mkdir -p "$work" || exit 1
# The copy: every folder but hidden ones and build trees (modes kept: scripts are found by their
# execute bit; tests/ too, for the paths the doc names there).
/usr/bin/python3 - "$source" "$work" <<'EOF' || exit 1
import os, shutil, sys
def skip(folder, names):
    return [n for n in names if n.startswith(".") or os.path.exists(os.path.join(folder, n, "CMakeCache.txt"))]
shutil.copytree(sys.argv[1], sys.argv[2], ignore=skip, dirs_exist_ok=True)
EOF

out=$(/usr/bin/python3 "$checker" "$work" 2>&1); rc=$?
printf 'clean copy (rc %d):\n%s\n' "$rc" "$out"
[ "$rc" -eq 0 ] || { echo "FAIL: the clean scratch copy did not pass"; exit 1; }

doc=$work/docs/architecture.md
# A room that does not exist, under the firmware's floor; a path the doc names that does not exist;
# an include rule for a folder that neither exists nor is on the map.
/usr/bin/python3 - "$doc" <<'EOF' || exit 1
import sys
path = sys.argv[1]
text = open(path, encoding="utf-8").read()
lines = text.split("\n")
at = next(i for i, l in enumerate(lines) if l.startswith("firmware/ "))
lines.insert(at + 1, "               no_such_room/  a room planted on the map that the tree does not have")
text = "\n".join(lines) + "\nThe planted path `firmware/control/no_such_law.hpp`.\n"
end = "<!-- include rules: end -->"
text = text.replace(end, "| `firmware/estimation/` | `firmware/model/` |\n" + end)
end = "<!-- namespaces: end -->"
text = text.replace(end, "| `lcmtypes/` | `exc::lcm` |\n" + end)
open(path, "w", encoding="utf-8").write(text)
EOF
# Programs missing from the map: an executable target and an executable script.
printf 'add_executable(excavator-planted planted_main.cpp)\n' >> "$work/tools/excavator_sim/CMakeLists.txt"
printf '#!/bin/sh\necho planted\n' > "$work/tools/sweep/planted-sweep" && chmod +x "$work/tools/sweep/planted-sweep"
# A program on the map that tools/ no longer makes.
rm "$work/tools/report_memory_bench/report-memory-bench"
# A folder of sources off the map.
mkdir -p "$work/firmware/off_the_map" && printf '#pragma once\nnamespace exc::off {\nint thing();\n}\n' > "$work/firmware/off_the_map/thing.hpp"
# The plant's node in the firmware's namespace, as it once was (a forward declaration beside it is not counted).
printf 'namespace exc::app {\nclass Ahead;\n}\nnamespace exc::app {\nstruct PlantNodePlanted {};\n}\n' > "$work/sim_plant/planted_node.hpp"

out=$(/usr/bin/python3 "$checker" "$work" 2>&1); rc=$?
printf 'planted copy (rc %d):\n%s\n' "$rc" "$out"
[ "$rc" -eq 1 ] || { echo "FAIL: the planted copy exited $rc, not 1"; exit 1; }
status=0
for expected in 'room `firmware/no_such_room/` is on the map but no such folder exists' \
                'tools/excavator_sim/CMakeLists.txt: program `excavator-planted` (tools/excavator_sim/) is not on the map' \
                'tools/sweep/planted-sweep: program `planted-sweep` (tools/sweep/) is not on the map' \
                'program `report-memory-bench` (tools/report_memory_bench/) is on the map but tools/report_memory_bench/ makes no such program' \
                'firmware/off_the_map/thing.hpp: folder `firmware/off_the_map/` holds product sources but is not on the map' \
                '`firmware/control/no_such_law.hpp` names no file or folder of the tree' \
                '`firmware/estimation/` names no file or folder of the tree' \
                'include rules: row `firmware/estimation/` is no floor, room or program' \
                'firmware/off_the_map/thing.hpp:2: opens `exc::off` but its folder has no row' \
                'sim_plant/planted_node.hpp:4: opens `exc::app`; docs/architecture.md' \
                '`lcmtypes/` is given `exc::lcm`, which none of its sources opens' \
                ': 11 false'; do
  grep -qF -- "$expected" <<< "$out" || { echo "FAIL: the report does not name: $expected"; status=1; }
done
exit $status

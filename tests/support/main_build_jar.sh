#!/usr/bin/env bash
# The README's main command and its lcm-spy line agree: the build folder the main command configures
# (cmake -S . -B DIR) is where the lcm-spy line's CLASSPATH and run line look; in such a tree the
# main command's one target (excavator-sim) depends on the jar (the generated make rules say so),
# and the jar's own target, exlcm-jar, builds DIR/lcmtypes/exlcm.jar alone (seconds: lcm-gen, javac).
#   main_build_jar.sh SOURCE WORK
set -euo pipefail
src=$1 work=$2
fail() { echo "FAIL: $*" >&2; exit 1; }
readme=$src/README.md
main=$(grep -m1 'tools/install-deps main &&' "$readme") || fail "no main command in the README"
dir=$(sed -E 's/.*cmake -S \. -B ([^ ]+) .*/\1/' <<< "$main")
[ -n "$dir" ] && [ "$dir" != "$main" ] || fail "no build folder in the main command: $main"
grep -q "CLASSPATH=$dir/lcmtypes/exlcm.jar" "$readme" || fail "the README's lcm-spy line does not name $dir/lcmtypes/exlcm.jar (the main command's build folder)"
grep -q "^ *$dir/tools/excavator_sim/excavator-sim run .*--lcm 'udpm" "$readme" || fail "the README's live run is not the main command's $dir/tools/excavator_sim/excavator-sim"
rm -rf "$work"
cmake -S "$src" -B "$work" > "$work.configure.txt" 2>&1 || { cat "$work.configure.txt"; fail "configure failed"; }
grep -q "excavator-sim.dir/all: .*exc_lcmtypes_java.dir/all" "$work/CMakeFiles/Makefile2" ||
  fail "building excavator-sim does not make lcmtypes/exlcm.jar"
cmake --build "$work" --target exlcm-jar > "$work.jar.txt" 2>&1 || { cat "$work.jar.txt"; fail "the exlcm-jar target failed"; }
[ -s "$work/lcmtypes/exlcm.jar" ] || fail "no $work/lcmtypes/exlcm.jar after the exlcm-jar target"
echo "main_build_jar.sh: the README's main command ($dir) builds exlcm.jar with excavator-sim; its lcm-spy line names it"

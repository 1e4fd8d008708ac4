#!/usr/bin/env bash
# tools/sanitizer-tests leaves out, under the address and the thread sanitizer, every test that runs a
# program under valgrind (its --split bench, the hold's callgrind counts): valgrind cannot run a
# binary with either runtime. Checked against this build's test list, so a new valgrind test that
# the list misses fails here rather than in a sanitizer run.
#   sanitizer_left_out.sh SOURCE BUILD
set -euo pipefail
src=$1 build=$2
fail() { echo "FAIL: $*" >&2; exit 1; }
count() { ctest --test-dir "$build" -N "$@" | sed -n 's/^Total Tests: //p'; }
valgrind_tests='callgrind|valgrind|^tools/excavator-loop-bench --split'
[ "$(count -R "$valgrind_tests")" -gt 0 ] || fail "no test runs valgrind here: the names changed?"
for sanitizer in address thread; do
  regex=$("$src/tools/sanitizer-tests" "$sanitizer" --left-out)
  missed=$(count -R "$valgrind_tests" -E "$regex|^tools/sanitizer-tests")
  [ "$missed" -eq 0 ] || { ctest --test-dir "$build" -N -R "$valgrind_tests" -E "$regex|^tools/sanitizer-tests"; fail "$missed valgrind test(s) not left out under $sanitizer"; }
done
echo "sanitizer_left_out.sh: every valgrind test is left out under address and thread, with the reason in tools/sanitizer-tests"

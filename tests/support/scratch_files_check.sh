#!/usr/bin/env bash
# The tests' main on the probe's scratch case (see CMakeLists.txt): PROBE WORK_DIR.
set -u
probe=$1 work=$2
rm -rf "$work" && mkdir -p "$work" || exit 1
fail() { echo "FAILED: $*"; exit 1; }

EXC_PROBE_SCRATCH="$work/pass/dir" "$probe" --test-case=probe/scratch > "$work/pass.out" 2>&1 || fail "the passing run exited non-zero: $(cat "$work/pass.out")"
[ -d "$work/pass" ] || fail "the passing run's parent directory is gone too"
[ ! -e "$work/pass/dir" ] || fail "a passing run kept its scratch directory"
[ ! -e "$work/pass/scratch_file.txt" ] || fail "a passing run kept its scratch file"

EXC_PROBE_SCRATCH="$work/fail/dir" EXC_PROBE_FAIL=1 "$probe" --test-case=probe/scratch > "$work/fail.out" 2>&1 && fail "the failing run exited 0"
[ -f "$work/fail/dir/written.txt" ] || fail "a failing run removed its scratch directory"
[ -f "$work/fail/scratch_file.txt" ] || fail "a failing run removed its scratch file"
grep -q "kept for inspection: $work/fail/dir" "$work/fail.out" || fail "a failing run did not name what it kept: $(cat "$work/fail.out")"

EXC_KEEP_TEST_FILES=1 EXC_PROBE_SCRATCH="$work/keep/dir" "$probe" --test-case=probe/scratch > "$work/keep.out" 2>&1 || fail "the kept run exited non-zero"
[ -f "$work/keep/dir/written.txt" ] || fail "EXC_KEEP_TEST_FILES=1 did not keep the scratch directory"

# A second passing run into the failed run's directory empties it first, then removes it.
EXC_PROBE_SCRATCH="$work/fail/dir" "$probe" --test-case=probe/scratch > "$work/again.out" 2>&1 || fail "the rerun exited non-zero"
[ ! -e "$work/fail/dir" ] || fail "a passing rerun kept the directory"
rm -rf "$work"
echo "scratch files: removed after a pass, kept and named after a failure, kept on request"

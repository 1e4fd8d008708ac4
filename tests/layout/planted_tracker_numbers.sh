#!/bin/bash
# planted_tracker_numbers.sh CHECKER WORK: the tracker-number check can fail. A scratch tree with a
# doc, a scene and a source that speak of requirements passes (the control); then a tracker number
# planted in each of the three ways a text slips one in must fail the check, named by file:line.
set -u
checker=$1 work=$2
rm -rf "$work" && mkdir -p "$work/docs" "$work/scenes" "$work/firmware" || exit 1
printf '# Stopping\n\nA stuck spool is found within 100 ms (R1).\n' > "$work/docs/safety.md"
printf '# Ground the firmware was not tuned for\nduration: 10\n' > "$work/scenes/clay.yaml"
printf '// upstream: lcm-proj/lcm#331 is their tracker, not ours\nint x;\n' > "$work/firmware/law.cpp"
# The planted words are put together here so that this file does not fail the real tree's check.
w=issue s=see
out=$(/usr/bin/python3 "$checker" "$work" 2>&1); rc=$?
printf 'clean tree (rc %d):\n%s\n' "$rc" "$out"
[ "$rc" -eq 0 ] || { echo "FAIL: the clean scratch tree did not pass"; exit 1; }

printf "# Stopping\n\nA stuck spool is found within 100 ms (${w^} 46, R1).\n" > "$work/docs/safety.md"
printf "# Ground the firmware was not tuned for (${w}s #31 and 32)\nduration: 10\n" > "$work/scenes/clay.yaml"
printf "// $s #17 for the goal\nint x;\n" > "$work/firmware/law.cpp"
out=$(/usr/bin/python3 "$checker" "$work" 2>&1); rc=$?
printf 'planted tree (rc %d):\n%s\n' "$rc" "$out"
[ "$rc" -eq 1 ] || { echo "FAIL: the planted tree exited $rc, not 1"; exit 1; }
status=0
for expected in "docs/safety.md:3: \"${w^} 46\"" "scenes/clay.yaml:1: \"${w}s #31\"" "firmware/law.cpp:1: \"$s #17\"" \
                '3 tracker numbers found'; do
  grep -qF -- "$expected" <<< "$out" || { echo "FAIL: the report does not name: $expected"; status=1; }
done
exit $status

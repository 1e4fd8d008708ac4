#!/usr/bin/env bash
# The generalisation sweep in small: the shipped spec cut to 4 cases (12 runs of the
# dig, every law on its defaults), through tools/sweep/parallel-sweep in 2 shards, merged, and
# tools/sweep/plot_generalisation.py's table and charts. Checks the merged table's columns and drawn
# values against the spec's ranges, the criterion's count against the table recomputed here, and that
# bad knob values (out of a knob's range, a path too fast for the actuators) are refused at load.
#   generalisation_sweep.sh EXC_SIM SPEC SCENE WORK
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/sweep_test.sh"
sim=$1 spec=$2 scene=$3 work=$4
rm -rf "$work"; mkdir -p "$work"
sed -e 's/cases: 1000/cases: 4/' -e "s|../scenes/dig.yaml|$scene|" "$spec" > "$work/spec.yaml"
grep -q "cases: 4" "$work/spec.yaml" || fail "the shipped spec no longer says cases: 1000"
EXC_SIM=$sim "$here/../../tools/sweep/parallel-sweep" "$work/spec.yaml" 2 "$work/out" -j2 \
  || fail "parallel-sweep of the small generalisation sweep exited $?"
/usr/bin/python3 "$here/../../tools/sweep/plot_generalisation.py" "$work/out" --figures "$work/figures" > "$work/table.md" \
  || fail "plot_generalisation.py exited $?"
/usr/bin/python3 - "$work/out/sweep.csv" "$work/table.md" "$work/figures" <<'PY' || fail "the merged table or the generalisation table is wrong"
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert [int(r["case"]) for r in rows] == [0, 1, 2, 3], [r["case"] for r in rows]
ranges = {"soil_blend": (0, 1), "terrain_slope": (-15, 15), "position_noise": (0, 3e-4), "delay_cycles": (0, 3),
          "path_speed": (0.7, 1.3), "model_mass": (-0.2, 0.2)}
for r in rows:
    for k, (lo, hi) in ranges.items():
        assert lo <= float(r[k]) <= hi, (k, r[k])
    assert float(r["delay_cycles"]) == round(float(r["delay_cycles"])), r["delay_cycles"]
    for law in ("pid", "adaptive", "flow"):
        assert r[law + "_ok"] == "1", (law, r[law + "_failure"])
        for j in ("boom", "arm", "bucket"):
            e = float(r["%s_rms_%s" % (law, j)])
            assert 0 < e < 0.05, (law, j, e)  # tracked: errors of mm, not of the path's metres
# The draws differ between cases (seeded per case), so the knobs were drawn, not left nominal.
assert len({r["terrain_slope"] for r in rows}) == 4 and len({r["soil_blend"] for r in rows}) == 4
good = sum(1 for r in rows if all(float(r["adaptive_rms_" + j]) <= 0.5 * float(r["pid_rms_" + j]) for j in ("arm", "bucket")))
table = open(sys.argv[2]).read()
assert "| pid | 0 of 4 |" in table and "| adaptive | 0 of 4 |" in table and "| flow | 0 of 4 |" in table, table
assert ("pid on arm and bucket RMS: %d of 4 cases" % good) in table, (good, table)
for png in ("generalisation.png", "generalisation_regions.png"):
    assert open(sys.argv[3] + "/" + png, "rb").read(8) == b"\x89PNG\r\n\x1a\n", png
PY
# A table case without its run line: the script says so and exits 1.
mkdir -p "$work/torn" && cp "$work/out/sweep.csv" "$work/torn/" && grep -v '"case":2,' "$work/out/shard-0.jsonl" > "$work/torn/shard-0.jsonl" || true
cp "$work/out/shard-1.jsonl" "$work/torn/"
set +e
/usr/bin/python3 "$here/../../tools/sweep/plot_generalisation.py" "$work/torn" --figures "$work/torn" > /dev/null 2> "$work/torn.err"
status=$?
set -e
[ "$status" -eq 1 ] && grep -q "have no run line" "$work/torn.err" || fail "a case without its run line: exit $status, $(cat "$work/torn.err")"
# Bad knob values are refused at load, exit 2, at the value's line, before any case runs.
refused() {  # refused FROM TO MESSAGE: the spec with FROM replaced by TO must be refused with MESSAGE
  sed -e "s|$1|$2|" "$work/spec.yaml" > "$work/bad.yaml"
  ! cmp -s "$work/bad.yaml" "$work/spec.yaml" || fail "the spec has no '$1'"
  set +e
  "$sim" sweep "$work/bad.yaml" --quiet --out "$work/bad.jsonl" 2> "$work/bad.err"
  local status=$?
  set -e
  [ "$status" -eq 2 ] || fail "$2: exit $status (want 2)"
  grep -q -- "$3" "$work/bad.err" || fail "$2: the error does not say '$3': $(cat "$work/bad.err")"
  [ ! -e "$work/bad.jsonl" ] || fail "$2: a case ran"
}
refused "terrain_slope: \[-15, 15\]" "terrain_slope: [-15, 60]" "bad.yaml:[0-9]*:[0-9]*: sweep.perturbations.terrain_slope\[1\]: is 60; allowed: a number in \[-45, 45\] deg"
refused "soil_blend: \[0, 1\]" "soil_blend: [-0.5, 1]" "sweep.perturbations.soil_blend\[0\]: is -0.5; allowed: a number in \[0, 1\]"
refused "path_speed: \[0.7, 1.3\]" "path_speed: [0.7, 5]" "sweep.perturbations.path_speed\[1\]: is 5, refused by the scene: .*task.path"
refused "delay_cycles: \[0, 3\]" "delay_cycles: [0, 64]" "sweep.perturbations.delay_cycles\[1\]: is 64; allowed: a whole number in \[0, 63\]"
refused "position_noise: \[0, 3.0e-4\]" "position_noise: [0, 0.5]" "sweep.perturbations.position_noise\[1\]: is 0.5; allowed: a number in \[0, 0.1\]"
echo "generalisation_sweep.sh: 4 cases x 3 laws merged and tabled ($(grep -c . "$work/out/sweep.csv") lines), bad knob values refused"

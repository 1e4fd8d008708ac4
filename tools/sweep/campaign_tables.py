#!/usr/bin/python3
"""The safety campaign's two tables in Markdown, from a merged sweep (docs/safety.md, the README).

usage: campaign_tables.py DIR [--requirements]
  --requirements  a column with each safety function's reaction-time requirement (docs/safety.md), and a
                  third table: the stop requirement R1-R4 per safety function
  reads DIR/sweep.json (excavator-sim sweep-merge's "safety_functions" and "campaign") and prints
  per safety function (the fault that took the stop) and per fault kind: runs, worst detection,
  worst time to rest, runs stopped but never at rest, emergency stops; PID and adaptive side by side.
  Exit 2 when the file is missing or holds no campaign (a sweep without faults).
"""
import json
import os
import sys

LAWS = ("pid", "adaptive")
# The hazard each safety function serves (docs/safety.md), in the concept's order.
# With --requirements, each function's reaction-time requirement (docs/safety.md's hazard table).
FUNCTIONS = (
    ("spool disagreement", "H1 spool monitor", "100 ms of the onset (R1)"),
    ("velocity implausible", "H1 flow plausibility", "100 ms of the onset (R1)"),
    ("tracking error", "H2 tracking-error limit", "one cycle past the limit (H2)"),
    ("sensor timeout", "H3 sensor watchdog", "20 ms watchdog (H3)"),
    ("pressure implausible", "H4 pressure plausibility", "3 sets range/step, 500 moving sets frozen (H4)"),
    ("plant fault", "H6 the machine's own fault", "the cycle the frame arrives (H6)"),
    ("plant emergency", "H6 the machine's emergency", "the cycle the frame arrives (H6)"),
    ("plant holding", "H6 the machine holding", "5 sensor sets (H6)"),
    ("deadline overrun", "H7 missed deadlines", "the cycle after the last miss (H7)"),
    ("operator stop", "H9 operator stop", "the cycle the frame arrives (H9)"),
    ("operator link lost", "H10 operator link", "supervisor_timeout, 0.5 s (H10)"),
    ("none", "no stop (tracked, or neither)", "-"),
)


def seconds(x):
    if x is None:
        return "-"
    return "%.0f ms" % (x * 1e3) if x < 1 else "%.2f s" % x


def pair(rows, key, fmt=str):
    return " / ".join(fmt(r.get(key)) if r else "-" for r in rows)


def kinds(rows):
    """Each fault kind behind a function with its runs per law ("rock 10 / 3"; one number when equal)."""
    names = sorted({k for r in rows for k in (r or {}).get("kinds", {})},
                   key=lambda k: -max((r or {}).get("kinds", {}).get(k, 0) for r in rows))
    cells = []
    for k in names:
        counts = [(r or {}).get("kinds", {}).get(k, 0) for r in rows]
        cells.append("%s %s" % (k, counts[0] if len(set(counts)) == 1 else " / ".join(map(str, counts))))
    return ", ".join(cells)


def main(argv):
    args = [a for a in argv[1:] if a != "--requirements"]
    requirements = len(args) < len(argv) - 1
    if len(args) != 1 or args[0] in ("-h", "--help") or args[0].startswith("-"):
        print(__doc__.strip())
        return 0 if args in (["-h"], ["--help"]) else 2
    path = os.path.join(args[0], "sweep.json")
    try:
        with open(path) as f:
            merged = json.load(f)
    except (OSError, ValueError) as e:
        print("campaign_tables.py: %s: %s" % (path, e), file=sys.stderr)
        return 2
    functions, campaign = merged.get("safety_functions"), merged.get("campaign")
    if not functions or not campaign:
        print("campaign_tables.py: %s holds no campaign (a sweep with faults has 'safety_functions' and 'campaign')"
              % path, file=sys.stderr)
        return 2
    laws = [law for law in LAWS if law in functions]
    print("| safety function (the fault that took the stop) |%s runs %s | fault kinds behind it | worst detection "
          "| worst time to rest | never at rest | estop |" % (" requirement |" if requirements else "", " / ".join(laws)))
    print("|---|---|---|---|---|---|---|" + ("---|" if requirements else ""))
    known = {name for name, _, _ in FUNCTIONS}
    names = list(FUNCTIONS) + [(n, n, "-") for law in laws for n in functions[law] if n not in known]
    seen = set()
    for name, label, requirement in names:
        rows = [functions[law].get(name) for law in laws]
        if name in seen or not any(rows):
            continue
        seen.add(name)
        print("| %s |%s %s | %s | %s | %s | %s | %s |" % (
            label, (" %s |" % requirement) if requirements else "", pair(rows, "runs"), kinds(rows),
            pair(rows, "worst_detection", seconds), pair(rows, "worst_time_to_rest", seconds),
            pair(rows, "never_at_rest"), pair(rows, "estop")))
    print()
    print("| fault | runs per law | %s | worst detection | worst time to rest | estop %s |"
          % (" | ".join("%s tracked / safe / neither" % law for law in laws), " / ".join(laws)))
    print("|---|---|%s---|---|---|" % ("---|" * len(laws)))
    for kind in sorted(campaign[laws[0]]):
        rows = [campaign[law].get(kind, {}) for law in laws]
        cells = " | ".join("%d / %d / %d" % (r.get("tracked", 0), r.get("safe_state", 0), r.get("neither", 0)) for r in rows)
        detection = max((r.get("worst_detection") for r in rows if r.get("worst_detection") is not None), default=None)
        rest = max((r.get("worst_time_to_rest") for r in rows if r.get("worst_time_to_rest") is not None), default=None)
        print("| %s | %d | %s | %s | %s | %s |" % (kind, rows[0].get("runs", 0), cells, seconds(detection), seconds(rest),
                                                pair(rows, "estop")))
    if requirements:
        print_stop_requirement(functions, campaign, laws)
    return 0


def mm(x):
    return "-" if x is None else "%.2f" % (x * 1e3)


def print_stop_requirement(functions, campaign, laws):
    """R1-R4 (docs/safety.md, "The stop requirement"), per safety function and law."""
    print()
    print("| safety function | stops %s | R2 met | R3 met | R3 missed | exempt (gravity) | worst drift, mm/s | "
          "worst ring tau, s | worst exempt travel, mm |" % " / ".join(laws))
    print("|---|---|---|---|---|---|---|---|---|")
    for name, label, _ in FUNCTIONS:
        rows = [functions[law].get(name) for law in laws]
        if name == "none" or not any(rows):
            continue
        stops = [sum((r or {}).get(k, 0) for k in ("r3_met", "r3_missed")) for r in rows]
        if not any(stops):
            continue
        tau = max(((r or {}).get("worst_ring_tau") or 0 for r in rows), default=0)
        print("| %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            label, " / ".join(map(str, stops)), pair(rows, "r2_met", lambda v: str(v or 0)),
            pair(rows, "r3_met", lambda v: str(v or 0)), pair(rows, "r3_missed", lambda v: str(v or 0)),
            pair(rows, "exempt", lambda v: str(v or 0)), pair(rows, "worst_drift", mm), "%.2f" % tau,
            pair(rows, "worst_exempt_travel", mm)))
    def r1_count(key):
        return [sum((functions[law].get(n) or {}).get(key, 0) for n in functions[law]) for law in laws]
    r1, r1_late, r1_before = (r1_count("r1_within_100ms_of_onset"), r1_count("r1_later_than_100ms_of_onset"),
                              r1_count("r1_found_before_disagreement"))
    neither = [sum(r.get("neither", 0) for r in campaign[law].values()) for law in laws]
    runs = [sum(r.get("runs", 0) for r in campaign[law].values()) for law in laws]
    print()
    print("R1, stuck spools (spool_stuck, actuator_jam) found within 100 ms of the onset of disagreement (%s): %s; "
          "later: %s; found before their spool disagreed past the spool monitor's limits: %s. R4, runs that neither "
          "track nor meet R3: %s of %s." % (" / ".join(laws), " / ".join(map(str, r1)), " / ".join(map(str, r1_late)),
                                            " / ".join(map(str, r1_before)), " / ".join(map(str, neither)),
                                            " / ".join(map(str, runs))))


if __name__ == "__main__":
    sys.exit(main(sys.argv))

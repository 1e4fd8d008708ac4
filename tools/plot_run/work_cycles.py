"""Work cycles in the report (plot-run): a task that repeats has a record per cycle and controller in
excavator-sim's summary (cycle start and end, RMS and worst error per joint, peak soil force, the
soil estimates at the cycle's end). Here: those records, their table, and what they show in words,
generated from the numbers."""
CYCLE_JOINTS = ("swing", "boom", "arm", "bucket")
THETA_NAMES = ("M_x", "B_x", "K_x", "M_z", "B_z", "K_z")
STEADY = 0.02  # a change under 2 % between cycles is "the same"


def work_cycles(summary):
    """{controller: [cycle, ...]} from an excavator-sim summary whose task repeats (else {})."""
    if not isinstance(summary, dict):
        return {}
    found = {k: v["cycles"] for k, v in summary.items()
             if isinstance(v, dict) and isinstance(v.get("cycles"), list) and len(v["cycles"]) > 1}
    order = {"pid": 0, "adaptive": 1}
    return dict(sorted(found.items(), key=lambda kv: (order.get(kv[0], 2), kv[0])))


def milli(value):
    return 1e3 * value


def has_estimates(rows):
    return any(r["theta_hat"][k] != 0.0 for r in rows for k in THETA_NAMES)


def cycle_table(summary):
    """Markdown: one row per work cycle and controller."""
    cycles = work_cycles(summary)
    if not cycles:
        return []
    lines = ["## Per work cycle", "",
             "| cycle | controller | cycle time (s) | RMS error swing (mrad) / boom / arm / bucket (mm) |"
             " worst error swing (mrad) / boom / arm / bucket (mm) | peak soil force (kN) |"
             " soil estimates at the end (M_x B_x K_x M_z B_z K_z) |",
             "|---|---|---|---|---|---|---|"]
    for c in range(max(len(v) for v in cycles.values())):
        for controller, rows in cycles.items():
            if c >= len(rows):
                continue
            r = rows[c]
            theta = " ".join("%.3g" % r["theta_hat"][k] for k in THETA_NAMES) if has_estimates(rows) else \
                "(no estimator)"
            lines.append("| %d | %s | %.2f | %s | %s | %.1f | %s |" % (
                c + 1, controller, r["end"] - r["start"],
                " / ".join("%.3g" % milli(r["rms_error"][j]) for j in CYCLE_JOINTS),
                " / ".join("%.3g" % milli(r["max_error"][j]) for j in CYCLE_JOINTS),
                1e-3 * r["peak_soil_force"], theta))
    return lines + [""] + cycle_findings(cycles, summary) + [""]


def ranges(numbers):
    """[1, 2, 3, 5] -> "1-3, 5"."""
    parts, start = [], None
    for i, n in enumerate(numbers):
        if start is None:
            start = n
        if i + 1 == len(numbers) or numbers[i + 1] != n + 1:
            parts.append(str(start) if start == n else "%d-%d" % (start, n))
            start = None
    return ", ".join(parts)


def cycles_phrase(numbers, total):
    """"every cycle" (of `total`), else "cycle 3" or "cycles 2-4, 6"."""
    if len(numbers) == total and total > 1:
        return "every cycle" if numbers[0] == 1 else "every later cycle"
    return ("cycle " if len(numbers) == 1 else "cycles ") + ranges(numbers)


def unit(joint):
    return "mrad" if joint == "swing" else "mm"


def lower_in(cycles, joint, key):
    """Per controller, the cycles in which its `key` error on `joint` is the lowest (ties: none)."""
    best = {}
    for c in range(max(len(rows) for rows in cycles.values())):
        values = sorted((rows[c][key][joint], k) for k, rows in cycles.items() if c < len(rows))
        if len(values) > 1 and values[0][0] < values[1][0]:
            best.setdefault(values[0][1], []).append(c + 1)
    return best


def comparison(cycles, joint):
    """Which controller has the lower RMS and worst error on a joint, in which cycles."""
    total = max(len(rows) for rows in cycles.values())
    means = {k: sum(r["rms_error"][joint] for r in rows) / len(rows) for k, rows in cycles.items()}
    parts = []
    for key, what in (("rms_error", "RMS"), ("max_error", "worst")):
        best = sorted(lower_in(cycles, joint, key).items(), key=lambda kv: kv[1][0])
        if best:
            parts.append("the lower %s error: %s" % (what, ", ".join(
                "%s in %s" % (k, cycles_phrase(n, total)) for k, n in best)))
    if not parts:
        return "- %s: the same error for every controller in every cycle (%s)." % (
            joint, ", ".join("%.3g %s" % (milli(m), unit(joint)) for m in set(means.values())))
    return "- %s: %s (mean RMS %s)." % (joint, "; ".join(parts), ", ".join(
        "%s %.3g %s" % (k, milli(m), unit(joint)) for k, m in means.items()))


def learning(controller, rows):
    """Whether a controller's RMS error changes after its first cycle: joint by joint, the later
    cycles lower or higher than the first by more than STEADY, and the verdict of most of them."""
    later = len(rows) - 1
    if later < 1:
        return []
    details, verdicts = [], {"improves": [], "is worse": [], "stays the same": [], "goes both ways": []}
    for joint in CYCLE_JOINTS:
        first = rows[0]["rms_error"][joint]
        if not first > 0:
            continue
        values = {c: r["rms_error"][joint] for c, r in enumerate(rows[1:], start=2)}
        lower = [c for c, v in values.items() if v < first * (1 - STEADY)]
        higher = [c for c, v in values.items() if v > first * (1 + STEADY)]
        moves = ["lower in %s (down to %.3g)" % (cycles_phrase(lower, later), milli(min(values[c] for c in lower)))]\
            if lower else []
        if higher:
            moves.append("higher in %s (up to %.3g)" % (cycles_phrase(higher, later),
                                                        milli(max(values[c] for c in higher))))
        details.append("%s %.3g %s in cycle 1, %s" % (joint, milli(first), unit(joint), ", ".join(moves) or
                                                      "within %d %% in every later cycle" % (100 * STEADY)))
        verdicts["improves" if 2 * len(lower) > later else "is worse" if 2 * len(higher) > later else
                 "stays the same" if not lower and not higher else "goes both ways"].append(joint)
    summary = ["it %s after its first cycle on %s" % (v, ", ".join(joints))
               for v, joints in verdicts.items() if joints]
    return ["- %s, RMS error after its first cycle: %s%s." % (
        controller, "; ".join(details), (": " + "; ".join(summary)) if summary else "")]


def estimates(controller, rows, truth):
    """How a controller's soil estimates move from cycle to cycle (if it has an estimator)."""
    if not has_estimates(rows):
        return []
    parts = []
    for k in ("K_x", "K_z"):
        values = ", ".join("%.3g" % r["theta_hat"][k] for r in rows)
        true = truth.get(k) if isinstance(truth, dict) else None
        parts.append("%s %s%s" % (k, values, " (true %.3g)" % true if isinstance(true, (int, float)) else ""))
    return ["- %s carries its soil estimates from one cycle to the next; at the end of each cycle: %s." % (
        controller, "; ".join(parts))]


def cycle_findings(cycles, summary):
    """What the per-cycle numbers show, in words."""
    lines = ["What the numbers show:", ""]
    if len(cycles) > 1:
        lines += [comparison(cycles, joint) for joint in CYCLE_JOINTS]
    for controller, rows in cycles.items():
        lines += learning(controller, rows)
        lines += estimates(controller, rows, summary.get(controller, {}).get("theta_true"))
    return lines

"""Work cycles in the report (plot-run): a task that repeats has a record per cycle and controller in
excavator-sim's summary; here those records and their table."""


def work_cycles(summary):
    """{controller: [cycle, ...]} from an excavator-sim summary whose task repeats (else {})."""
    if not isinstance(summary, dict):
        return {}
    found = {k: v["cycles"] for k, v in summary.items()
             if isinstance(v, dict) and isinstance(v.get("cycles"), list) and len(v["cycles"]) > 1}
    order = {"pid": 0, "adaptive": 1}
    return dict(sorted(found.items(), key=lambda kv: (order.get(kv[0], 2), kv[0])))


def cycle_table(summary):
    """Markdown rows per work cycle and controller (tasks that repeat)."""
    cycles = work_cycles(summary)
    if not cycles:
        return []
    lines = ["## Per work cycle", "",
             "| cycle | controller | cycle time (s) | RMS boom / arm / bucket (mm) | worst bucket (mm) |"
             " peak soil force (kN) | soil estimates at the end (M_x B_x K_x M_z B_z K_z) |",
             "|---|---|---|---|---|---|---|"]
    for c in range(max(len(v) for v in cycles.values())):
        for controller, rows in cycles.items():
            if c >= len(rows):
                continue
            r = rows[c]
            theta = " ".join("%.3g" % r["theta_hat"][k] for k in ("M_x", "B_x", "K_x", "M_z", "B_z", "K_z"))
            lines.append("| %d | %s | %.2f | %.3g / %.3g / %.3g | %.3g | %.1f | %s |" % (
                c + 1, controller, r["end"] - r["start"], 1e3 * r["rms_error"]["boom"],
                1e3 * r["rms_error"]["arm"], 1e3 * r["rms_error"]["bucket"], 1e3 * r["max_error"]["bucket"],
                1e-3 * r["peak_soil_force"], theta))
    return lines + [""]

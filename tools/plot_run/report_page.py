"""The report page of a run (plot-run): report.md with the summary table and the figures."""
import math
import os

from run_figures import JOINTS, work_cycles

def rms(values):
    finite = [v for v in values if isinstance(v, float) and not math.isnan(v)]
    return math.sqrt(sum(v * v for v in finite) / len(finite)) if finite else float("nan")


def format_value(value):
    if isinstance(value, float):
        return "%.6g" % value
    if isinstance(value, (list, tuple)):
        return ", ".join(format_value(v) for v in value)
    if isinstance(value, dict):
        return "; ".join("%s: %s" % (k, format_value(v)) for k, v in value.items())
    return str(value)


SIM_JOINTS = (("swing", "mrad"), ("boom", "mm"), ("arm", "mm"), ("bucket", "mm"))


def sim_runs(summary):
    """The per-controller runs of an excavator-sim summary (objects with an rms_error per joint)."""
    if not isinstance(summary, dict):
        return {}
    runs = {k: v for k, v in summary.items() if isinstance(v, dict) and isinstance(v.get("rms_error"), dict)}
    order = ["pid", "adaptive", "slotine_li"]  # the baseline first, as in the paper's figures
    return dict(sorted(runs.items(), key=lambda kv: (order.index(kv[0]) if kv[0] in order else len(order), kv[0])))


def sim_table(runs):
    """excavator-sim's summary as engineers read it: one row per figure, one column per controller."""
    names = list(runs)
    lines = ["| quantity | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]

    def row(label, get):
        cells = []
        for r in runs.values():
            try:
                cells.append(get(r))
            except (KeyError, TypeError, ValueError):
                cells.append("n/a")
        lines.append("| %s | " % label + " | ".join(cells) + " |")

    for key, what in (("rms_error", "RMS error"), ("max_error", "max error")):
        for joint, unit in SIM_JOINTS:
            row("%s %s (%s)" % (what, joint, unit), lambda r, k=key, j=joint: "%.4g" % (1e3 * r[k][j]))
    row("peak soil force (kN)", lambda r: "%.1f" % (1e-3 * r["peak_soil_force"]))
    row("shear re-anchorings", lambda r: "%d" % r["reanchor_count"])
    for q in ("median", "p99", "max"):
        row("control step %s (us)" % q, lambda r, q=q: "%.1f" % r["control_step_us"][q])
    row("heap allocations in the loop", lambda r: "%d" % r["heap_allocations_in_loop"])
    row("telemetry messages (dropped)", lambda r: "%d (%d)" % (r["telemetry"]["published"], r["telemetry"]["dropped"]))
    row("simulated (s)", lambda r: "%.3g" % r["simulated_seconds"])
    row("task finished at (s)", lambda r: "%.3f" % r["task_finish_time"] if r["task_finished"] else
        "not finished (run ended at %.3g s)" % r["simulated_seconds"])
    for name in ("M_x", "B_x", "K_x", "M_z", "B_z", "K_z"):
        row("soil estimate %s (true)" % name,
            lambda r, n=name: "%.4g (%.4g)" % (r["theta_hat"][n], r["theta_true"][n]))
    row("status", lambda r: "ok" if r.get("ok", True) else "FAILED: %s" % r.get("failure", ""))
    return lines


def summary_table(summary):
    """Markdown for any JSON: a table of runs x keys if every value is an object, else key/value."""
    lines = []
    if isinstance(summary, dict) and summary and all(isinstance(v, dict) for v in summary.values()):
        keys = []
        for v in summary.values():
            keys += [k for k in v if k not in keys]
        lines.append("| quantity | " + " | ".join(summary) + " |")
        lines.append("|---|" + "---|" * len(summary))
        for k in keys:
            lines.append("| %s | " % k + " | ".join(format_value(v.get(k, "")) for v in summary.values())
                         + " |")
    elif isinstance(summary, dict):
        lines.append("| quantity | value |")
        lines.append("|---|---|")
        for k, v in summary.items():
            lines.append("| %s | %s |" % (k, format_value(v)))
    else:
        lines.append(format_value(summary))
    return lines


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


def write_report(runs, summary, title, out_dir, written):
    lines = ["# %s" % title, ""]
    if summary is not None:
        runs_in_summary = sim_runs(summary)
        table = sim_table(runs_in_summary) if runs_in_summary else summary_table(summary)
        lines += ["## Summary", ""]
        if isinstance(summary, dict) and isinstance(summary.get("setup"), str):
            lines += ["Scene `%s`: %s." % (summary.get("scene", "?"), summary["setup"]), ""]
        lines += table + [""]
    # From the log: the controller's own error e (estimated state against q_d) over every logged
    # cycle, hold included; the summary's figures are the plant's true state while tracking.
    lines += ["## RMS of the controller's error e over the whole log (telemetry)", ""]
    lines.append("| joint | " + " | ".join(runs) + " |")
    lines.append("|---|" + "---|" * len(runs))
    for j, (joint, unit) in enumerate(JOINTS):
        cells = []
        for channels in runs.values():
            ctrl = channels.get("EXC_CONTROLLER", {})
            exact = ctrl.get("__rms__", {}).get("error_%d" % j) if ctrl else None
            cells.append("%.4g" % (exact if exact is not None else rms(ctrl["error_%d" % j])) if ctrl else "n/a")
        lines.append("| %s (%s) | " % (joint, unit.split("[")[-1].rstrip("]")) + " | ".join(cells)
                     + " |")
    lines.append("")
    lines += cycle_table(summary)
    captions = {
        "work_cycles.png": "Work cycles: RMS error per joint and peak soil force, per cycle and controller",
        "tracking_error.png": "Tracking error of each active joint",
        "soil_force.png": "Soil force at the tip (the zig-zag of the paper's Fig. 8)",
        "soil_estimates.png": "Soil parameter estimates against the true values",
        "loop_timing.png": "Control loop timing histogram",
    }
    lines += ["## Figures", ""]
    for name in written:
        caption = captions.get(name, "Tracking of the %s, desired against actual" %
                               name[len("tracking_"):-4])
        lines += ["### %s" % caption, "", "![%s](%s)" % (caption, name), ""]
    path = os.path.join(out_dir, "report.md")
    with open(path, "w") as f:
        f.write("\n".join(lines))
    return path

"""The report page of a run (plot-run): report.md with the summary table and the figures."""
import os

from figure_base import JOINTS
from run_data import ZOOM_HALF_WIDTH, is_long
from work_cycles import cycle_table


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
    """The per-controller runs of an excavator-sim summary (objects with an rms_error per joint, or null
    for a run that never tracked: its figures are then n/a)."""
    if not isinstance(summary, dict):
        return {}
    runs = {k: v for k, v in summary.items()
            if isinstance(v, dict) and "rms_error" in v and (v["rms_error"] is None or isinstance(v["rms_error"], dict))}
    order = ["pid", "adaptive", "slotine_li"]  # the baseline first, as in the paper's figures
    return dict(sorted(runs.items(), key=lambda kv: (order.index(kv[0]) if kv[0] in order else len(order), kv[0])))


PHASE_NOTE = ("Which phase each figure covers (the plant's true positions against the pose the firmware "
              "asks for): *tracking* the path running, a stop along the path included; *settle* each hold's "
              "start, until every function has stayed inside half the holding tolerance for the settle dwell "
              "(at most the settle limit): the path's last error dying out; *hold* the firmware holding a pose "
              "from then on, judged against the holding tolerance; *stop* the safe state after a fault (the "
              "centred valves' creep). The telemetry's table below is the firmware's own error over every "
              "logged cycle, all phases together.")


def phase_cell(run, phase, text):
    """A phase's figure, "n/a" when the run never was in it or never tracked."""
    phases = run.get("phases") or {}
    figures = phases.get(phase)
    if not figures or run.get("rms_error") is None:
        return "n/a"
    return text(figures)


def hold_verdict(run):
    """The hold against the holding tolerance, as the run's verdict judges it."""
    hold = (run.get("phases") or {}).get("hold")
    if not hold or run.get("rms_error") is None:
        return "n/a (no hold)"
    tolerance = run.get("holding_tolerance", {})
    worst = max(("boom", "arm", "bucket"), key=lambda j: hold["max_error"][j] / tolerance.get(j, 2.5e-3))
    within = run.get("hold_ok", all(hold["max_error"][j] <= tolerance.get(j, 2.5e-3) for j in tolerance))
    return "%s: worst %s %.3g mm against %.3g mm" % ("met" if within else "NOT met", worst,
                                                    1e3 * hold["max_error"][worst], 1e3 * tolerance.get(worst, 2.5e-3))


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
            row("tracking: %s %s (%s)" % (what, joint, unit), lambda r, k=key, j=joint: "%.4g" % (1e3 * r[k][j]))
    # The other phases (PHASE_NOTE says what each covers), from the summary's "phases".
    for phase, label in (("settle", "settle"), ("hold", "hold"), ("stop", "stop")):
        if not any(isinstance(r.get("phases"), dict) and r["phases"].get(phase) for r in runs.values()):
            continue
        row("%s: time in it (s)" % label, lambda r, p=phase: phase_cell(r, p, lambda f: "%.1f" % f["seconds"]))
        for key, what in (("rms_error", "RMS error"), ("max_error", "max error")):
            for joint, unit in SIM_JOINTS:
                row("%s: %s %s (%s)" % (label, what, joint, unit),
                    lambda r, p=phase, k=key, j=joint: phase_cell(r, p, lambda f: "%.4g" % (1e3 * f[k][j])))
        if phase == "hold":
            row("hold: excursions past the tolerance (boom / arm / bucket)",
                lambda r: phase_cell(r, "hold", lambda f: " / ".join("%d" % f["excursions"][j]
                                                                      for j in ("boom", "arm", "bucket"))))
            row("hold: verdict (holding tolerance)", hold_verdict)
    row("peak soil force (kN)", lambda r: "%.1f" % (1e-3 * r["peak_soil_force"]))
    row("shear re-anchorings", lambda r: "%d" % r["reanchor_count"])
    for q in ("median", "p99", "max"):
        row("control step %s (us)" % q, lambda r, q=q: "%.1f" % r["control_step_us"][q])
    row("heap allocations in the loop", lambda r: "%d" % r["heap_allocations_in_loop"])
    row("telemetry messages (dropped)", lambda r: "%d (%d)" % (r["telemetry"]["published"], r["telemetry"]["dropped"]))
    row("per-cycle channels logged", lambda r: "every cycle" if r["telemetry"].get("per_cycle_every", 1) == 1
        else "every %d cycles" % r["telemetry"]["per_cycle_every"])
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


def long_run_note(runs):
    """How a long run's figures and CSVs were made (nothing for a short run)."""
    channels = [c for run in runs.values() for c in run.values() if c]
    if not any(is_long(c) for c in channels):
        return []
    note = ("A long run: the time-series figures show each signal's envelope (its minimum and maximum "
            "per time bucket) over the whole run, and the tracking figures a zoom on the %g s either side "
            "of the moment the summary names as each controller's worst error on that joint in each phase "
            "(tracking, hold, stop: the plant's true error, the table's max error), its figure and time in "
            "the zoom's title; the curves are the telemetry (the machine as the firmware sensed it), and "
            "the legend gives the logged error there (the firmware's estimate). Without a summary the zoom "
            "is on the largest logged error, hold and track together, and its title says so."
            % ZOOM_HALF_WIDTH)
    if any(c.buckets is not None for c in channels):
        note += (" The long channels' CSVs (csv/, a header that starts with `bucket`) are their bucketed "
                 "view (per time bucket: first, last, min, max and sums of every column), with every "
                 "message of the zoom windows (around the summary's worst moments and the log's largest "
                 "errors) and of the run's last second in csv/detail/; the RMS "
                 "figures above are over every message.")
    return [note, ""]


def thinned_log_note(summary):
    """What a log recorded at a lower rate (excavator-sim --log-every) holds (nothing for a whole log)."""
    every = sorted({r.get("telemetry", {}).get("per_cycle_every", 1) for r in sim_runs(summary).values()})
    if every in ([], [1]):
        return []
    rates = " or ".join(str(e) for e in every)
    return ["The log holds EXC_STATE, EXC_COMMAND and EXC_CONTROLLER of one control cycle in %s only "
            "(`--log-every %s`): the RMS above, the CSVs and the figures are over those cycles; the summary's "
            "figures are over every cycle. The other channels are whole." % (rates, rates), ""]


def write_report(runs, summary, title, out_dir, written):
    lines = ["# %s" % title, ""]
    if summary is not None:
        runs_in_summary = sim_runs(summary)
        table = sim_table(runs_in_summary) if runs_in_summary else summary_table(summary)
        lines += ["## Summary", ""]
        if isinstance(summary, dict) and isinstance(summary.get("setup"), str):
            lines += ["Scene `%s`: %s." % (summary.get("scene", "?"), summary["setup"]), ""]
        lines += table + [""]
        if runs_in_summary:
            lines += [PHASE_NOTE, ""]
    # From the log: the controller's own error e (estimated state against q_d) over every logged
    # cycle, hold included; the summary's figures are the plant's true state while tracking.
    lines += ["## RMS of the controller's error e over the whole log (telemetry)", ""]
    lines.append("| joint | " + " | ".join(runs) + " |")
    lines.append("|---|" + "---|" * len(runs))
    for j, (joint, unit) in enumerate(JOINTS):
        cells = []
        for channels in runs.values():
            ctrl = channels.get("EXC_CONTROLLER", {})
            cells.append("%.4g" % ctrl.rms["error_%d" % j] if ctrl else "n/a")
        lines.append("| %s (%s) | " % (joint, unit.split("[")[-1].rstrip("]")) + " | ".join(cells)
                     + " |")
    lines.append("")
    lines += thinned_log_note(summary)
    note = long_run_note(runs)
    lines += note
    lines += cycle_table(summary)
    captions = {
        "work_cycles.png": "Work cycles: RMS and worst error per joint, cycle time, peak soil force and the "
                           "soil estimates, per cycle and controller",
        "cycle_errors.png": "Each work cycle's tracking error over the cycle's time, per controller and joint",
        "tracking_error.png": "Tracking error of each active joint",
        "soil_force.png": "Soil force at the tip (the zig-zag of the paper's Fig. 8)",
        "soil_estimates.png": "Soil parameter estimates against the true values",
        "loop_timing.png": "Control loop timing histogram",
    }
    lines += ["## Figures", ""]
    for name in written:
        caption = captions.get(name, "Tracking of the %s, desired against actual%s" % (
            name[len("tracking_"):-4], ": the envelope over the run, and each controller's worst window per "
            "phase" if note else ""))
        lines += ["### %s" % caption, "", "![%s](%s)" % (caption, name), ""]
    path = os.path.join(out_dir, "report.md")
    with open(path, "w") as f:
        f.write("\n".join(lines))
    return path

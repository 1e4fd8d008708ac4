"""Which moment each worst window of the tracking figures shows, and the figure its title quotes: per
phase (tracking, hold, stop) the worst error of a joint that the run's summary names (excavator-sim's,
passed with --summary), the plant's true error against the pose asked for, and when it happened, so
that the report's zoom and the summary's table give one number. Without a summary for a run, the
largest of the firmware's own logged error (its estimate, hold and track together), said so in the
title. The log holds no plant truth: a zoom's curves are what the firmware logged around that moment
(excavator-log keeps those rows when it is given the summary)."""
import collections

import numpy as np

from run_data import worst_window

ZOOM_PHASES = ("tracking", "hold", "stop")  # the phases the summary's verdicts are about
JOINT_NAMES = ("swing", "boom", "arm", "bucket")
PHASE_COLOURS = {"tracking": "tab:red", "hold": "tab:green", "stop": "tab:purple", None: "tab:red"}

# phase: the summary's phase (None: the telemetry's own worst); time (s) and error (m, rad for the
# swing) of the worst, None where there is none; source: "plant" (the summary) or "firmware" (the
# log's estimate); missing: why there is no figure or no time, None when there is both.
Zoom = collections.namedtuple("Zoom", "phase time error source missing")


def summary_run(summary, label):
    """The summary's run of that controller (an object with per-phase figures), or None."""
    run = summary.get(label) if isinstance(summary, dict) else None
    return run if isinstance(run, dict) and isinstance(run.get("phases"), dict) else None


def zoom_phases(runs, summary):
    """The phases to zoom on, in ZOOM_PHASES' order: those any run's summary has samples in (tracking
    at least); [None] (one zoom on the telemetry's own worst) when no run has a summary."""
    found = [summary_run(summary, label) for label in runs]
    if not any(found):
        return [None]
    present = [p for p in ZOOM_PHASES if any(r and r["phases"].get(p) for r in found)]
    return present if "tracking" in present else ["tracking"] + present


def zoom(ctrl, summary, label, phase, j):
    """The Zoom of controller `label`'s joint j in `phase` (None: the telemetry's own worst)."""
    run = summary_run(summary, label)
    if run is None:
        if phase not in (None, "tracking"):
            return Zoom(phase, None, None, None, "no summary for this run")
        worst = worst_window(ctrl, j)
        if worst is None:
            return Zoom(None, None, None, None, "no tracking logged")
        return Zoom(None, worst[0], worst[1], "firmware", None)
    figures = run["phases"].get(phase)
    if run.get("rms_error", {}) is None:
        return Zoom(phase, None, None, None, "never tracked")
    if not isinstance(figures, dict):
        return Zoom(phase, None, None, None, "no %s phase in this run" % phase)
    joint = JOINT_NAMES[j]
    error = (figures.get("max_error") or {}).get(joint)
    t = (figures.get("worst_time") or {}).get(joint)
    if not isinstance(error, (int, float)):
        return Zoom(phase, None, None, None, "the summary gives no worst %s error" % joint)
    if not isinstance(t, (int, float)) or t < 0:
        return Zoom(phase, None, error, "plant", "the summary gives no time for it")
    return Zoom(phase, float(t), float(error), "plant", None)


def logged_error_at(ctrl, t, j):
    """|e| of joint j in the logged row nearest t (the firmware's estimate), and that row's time; None
    without a row within 10 ms."""
    if not ctrl or "error_%d" % j not in ctrl or not len(ctrl.get("utime", [])):
        return None
    times = np.asarray(ctrl["utime"]) * 1e-6
    k = int(np.argmin(np.abs(times - t)))
    if abs(times[k] - t) > 0.01:
        return None
    return abs(float(ctrl["error_%d" % j][k])), float(times[k])

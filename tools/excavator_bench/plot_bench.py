#!/usr/bin/python3
"""Plots the CSV files of excavator-bench (matplotlib, Agg): one PNG per chart.

usage: plot_bench.py OUT_DIR     (reads OUT_DIR/*.csv, writes OUT_DIR/*.png)
"""
import csv
import math
import os
import sys
import textwrap

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def num(x):
    try:
        v = float(x)
    except (TypeError, ValueError):
        return math.nan
    return v


def decorate(ax, xlabel, ylabel, title=None, legend=None):
    """A panel's axis labels, title, a grid on major and minor ticks and (a font size) its legend."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    if legend:
        ax.legend(fontsize=legend)


def save(fig, out, name):
    fig.tight_layout()
    fig.savefig(os.path.join(out, name), dpi=110)
    plt.close(fig)


def work_precision(out):
    data = rows(os.path.join(out, "work_precision.csv"))
    scenes = sorted({r["scene"] for r in data})
    metrics = [("tip_rms_m", "tip position RMS (m)"), ("constraint_residual_m", "constraint residual max (m)"),
               ("energy_drift_J", "energy drift max (J)")]
    fig, axes = plt.subplots(len(scenes), len(metrics), figsize=(6 * len(metrics), 4.8 * len(scenes)), squeeze=False)
    for i, scene in enumerate(scenes):
        for j, (key, name) in enumerate(metrics):
            ax = axes[i][j]
            for method in sorted({r["method"] for r in data if r["scene"] == scene}):
                pts = [(num(r["cpu_s_per_sim_s"]), num(r[key])) for r in data
                       if r["scene"] == scene and r["method"] == method and r["ok"] == "1"]
                pts = [(x, max(y, 1e-16)) for x, y in pts if x > 0 and not math.isnan(y)]
                if pts:
                    ax.loglog(*zip(*pts), marker="o", ms=3, label=method)
            front = sorted((num(r["cpu_s_per_sim_s"]), num(r[key])) for r in data
                           if r["scene"] == scene and r["pareto"] == "1" and key == "tip_rms_m")
            if front:
                ax.loglog(*zip(*front), "k--", lw=1.5, label="Pareto front")
            decorate(ax, "CPU time per simulated second (s)", name, f"{scene}: {name}")
        axes[i][0].legend(fontsize=6)
    save(fig, out, "work_precision.png")


def fidelity(out):
    """Per scene, what a reader compares: each model variant's tip path, cylinder force and tracking
    difference from the reference (the most complete model) against the tolerances, and its CPU time
    as a share of the reference's. Linear axes: the reference is the zero of every difference, not a
    point of its own."""
    data = rows(os.path.join(out, "fidelity.csv"))
    scenes = list(dict.fromkeys(r["scene"] for r in data))
    panels = [("tip_rms_m", 1e3, "tip path vs the reference, mm RMS", 10.0),
              ("force_rel", 100.0, "cylinder forces vs the reference, % RMS", 5.0),
              ("tracking_diff", 1e3, "change of the worst tracking RMS, mm", 2.0),
              ("cost_ratio", 100.0, "CPU time, % of the reference's", None)]
    n = max(len([r for r in data if r["scene"] == scene]) for scene in scenes) if scenes else 1
    fig, axes = plt.subplots(max(1, len(scenes)), len(panels), figsize=(20, 1.0 + (0.5 * n + 1.2) * max(1, len(scenes))),
                             squeeze=False, sharey="row")
    for i, scene in enumerate(scenes):
        sel = [r for r in data if r["scene"] == scene]
        labels = [textwrap.fill(r["fidelity"] + (" [reference]" if r.get("reference") == "1" else "") +
                                (" [recommended]" if r["recommended"] == "1" else ""), 34) for r in sel]
        y = list(range(len(sel)))[::-1]
        for j, (key, scale, name, tolerance) in enumerate(panels):
            ax = axes[i][j]
            values = [num(r[key]) * scale if r["ok"] == "1" else math.nan for r in sel]
            colours = ["grey" if r.get("reference") == "1" else ("tab:green" if r["within_tolerance"] == "1" else "tab:red")
                       for r in sel]
            finite = [v for v in values if not math.isnan(v)]
            top = max(finite + ([tolerance] if tolerance else []) + [1e-9])
            ax.barh(y, [0 if math.isnan(v) else v for v in values], color=colours, height=0.6)
            for yy, v, r in zip(y, values, sel):
                if r["ok"] != "1":
                    ax.text(0, yy, " failed: " + r["failure"][:40], va="center", fontsize=7, color="tab:red")
                elif r.get("reference") == "1" and key != "cost_ratio":
                    ax.text(0, yy, " 0: the reference", va="center", fontsize=7)
                else:
                    ax.text(v, yy, f" {v:.3g}", va="center", fontsize=7)
            if tolerance:
                ax.axvline(tolerance, color="black", ls="--", lw=1)
                name += f" (dashed: tolerance {tolerance:g})"
            else:
                ax.axvline(100.0, color="black", ls=":", lw=1)
            ax.set_xlim(0, 1.2 * top)
            ax.set_yticks(y)
            ax.set_yticklabels(labels, fontsize=8)
            ax.set_xlabel(name, fontsize=8)
            ax.grid(True, axis="x", alpha=0.3)
            if j == 0:
                ax.set_title(f"{scene} (closed loop, adaptive law): green within every tolerance, red outside one",
                             loc="left", fontsize=9)
    save(fig, out, "fidelity.png")


def stability(out):
    data = rows(os.path.join(out, "stability_step.csv"))
    axes_names = [("soil_stiffness_N_per_m", "soil stiffness K_t (N/m)"), ("joint_speed_factor", "joint speed factor")]
    fig, axes = plt.subplots(1, 2, figsize=(14, 5))
    for ax, (axis, name) in zip(axes, axes_names):
        for method in sorted({r["method"] for r in data}):
            pts = [(num(r["value"]), num(r["largest_stable_step_s"])) for r in data
                   if r["method"] == method and r["axis"] == axis]
            pts = [(x, y if not math.isnan(y) else 1e-6) for x, y in pts]
            if pts:
                ax.semilogy(*zip(*pts), marker="o", ms=4, label=method)
        if axis == "soil_stiffness_N_per_m":
            ax.set_xscale("log")
        decorate(ax, name, "largest stable step (s); 1e-6 = none", f"largest stable step against {name}")
    axes[0].legend(fontsize=6)
    save(fig, out, "stability_step.png")

    data = rows(os.path.join(out, "stability_control.csv"))
    axis_list = sorted({r["axis"] for r in data})
    fig, axes = plt.subplots(1, len(axis_list), figsize=(4.5 * len(axis_list), 4.5), squeeze=False)
    # One colour per controller in every panel (PID has no adaptation-rate panel).
    controllers = sorted({r["controller"] for r in data})
    colour = {c: "C%d" % i for i, c in enumerate(controllers)}
    for ax, axis in zip(axes[0], axis_list):
        for ctrl in controllers:
            pts = [(num(r["value"]), num(r["tracking_rms_worst"]), r["ok"] == "1") for r in data
                   if r["controller"] == ctrl and r["axis"] == axis]
            if not pts:
                continue
            line, = ax.plot([p[0] for p in pts], [max(p[1], 1e-7) for p in pts], marker="o", ms=4, label=ctrl,
                            color=colour[ctrl])
            bad = [p for p in pts if not p[2]]
            if bad:
                ax.plot([p[0] for p in bad], [max(p[1], 1e-7) for p in bad], "x", color=line.get_color(), ms=12, mew=2)
        ax.set_yscale("log")
        if axis in ("gain_scale", "adaptation_scale"):
            ax.set_xscale("log")
        decorate(ax, axis, "worst joint tracking RMS (m / rad); x = failed", legend=7)
    save(fig, out, "stability_control.png")


def step_text(h):
    return f"{h * 1e3:g} ms" if h >= 1e-3 else f"{h * 1e6:g} us"


def pressure_integration(out):
    """Tip path and chamber-pressure error against CPU time, per input and pressure method; the runs
    the plant's checks stopped are named in the legend."""
    data = rows(os.path.join(out, "pressure_integration.csv"))
    inputs = list(dict.fromkeys(r["input"] for r in data))
    metrics = [("tip_rms_m", 1.0, "tip path RMS against the reference (m)"),
               ("pressure_rms_Pa", 1e-6, "chamber pressure RMS against the reference (MPa)")]
    fig, axes = plt.subplots(len(inputs), 2, figsize=(13, 4.8 * len(inputs)), squeeze=False)
    for i, name in enumerate(inputs):
        for j, (key, scale, label) in enumerate(metrics):
            ax = axes[i][j]
            for method in sorted({r["method"] for r in data if r["input"] == name}):
                sel = sorted((r for r in data if r["input"] == name and r["method"] == method),
                             key=lambda r: -num(r["step_s"]))
                ok = [(num(r["cpu_s_per_sim_s"]), max(num(r[key]) * scale, 1e-12), num(r["step_s"]))
                      for r in sel if r["ok"] == "1"]
                stopped = [step_text(num(r["step_s"])) for r in sel if r["ok"] != "1"]
                text = method + (f" (stopped by the plant's checks at {', '.join(stopped)})" if stopped else "")
                if ok:
                    ax.loglog([p[0] for p in ok], [p[1] for p in ok], marker="o", ms=4, label=text)
                    for x, y, h in ok:
                        ax.annotate(step_text(h), (x, y), fontsize=6, xytext=(3, 3), textcoords="offset points")
                else:
                    ax.plot([], [], "x", label=text)
            decorate(ax, "CPU time per simulated second (s)", label, f"{name}: {label}", legend=7)
    save(fig, out, "pressure_integration.png")


def peer(out):
    data = rows(os.path.join(out, "peer_tip.csv"))
    scenes = sorted({r["scene"] for r in data})
    fig, axes = plt.subplots(1, max(1, len(scenes)), figsize=(7 * max(1, len(scenes)), 5), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        sel = [r for r in data if r["scene"] == scene]
        for key, name, style in (("reference", "fine-step reference", "k-"), ("plant", "plant, Euler 1 ms", "b--"),
                                 ("mujoco", "MuJoCo, Euler 1 ms", "r:")):
            xs = [num(r[key + "_x"]) for r in sel]
            zs = [num(r[key + "_z"]) for r in sel]
            if any(not math.isnan(v) for v in xs):
                ax.plot(xs, zs, style, label=name)
        ax.axis("equal")
        decorate(ax, "tip radius from the swing axis (m)", "tip height (m)", f"tip path, same efforts: {scene}",
                 legend=8)
    save(fig, out, "peer.png")


def main():
    if len(sys.argv) != 2 or sys.argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(sys.argv) == 2 else 2
    out = sys.argv[1]
    for chart in (work_precision, pressure_integration, fidelity, stability, peer):
        chart(out)
    print(f"plots: {', '.join(n for n in sorted(os.listdir(out)) if n.endswith('.png'))} in {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

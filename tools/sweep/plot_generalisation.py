#!/usr/bin/python3
"""The generalisation sweep's table and charts, from a merged sweep's directory.

usage: plot_generalisation.py DIR [--figures FIGDIR] [--baseline pid] [--law adaptive]
  reads DIR/sweep.csv (the merge's table: the cases, their draws, each law's ok and RMS per joint)
  and DIR/shard-*.jsonl (each run's worst error per joint; only the cases the table has, once each)
  writes DIR/generalisation.md: per law, the failed runs and the RMS and worst error of boom, arm and
    bucket (median, 90th percentile, largest, mm), and the fraction of cases where LAW's RMS on arm
    and bucket is at most half BASELINE's (the criterion for ground the laws were not tuned for)
  FIGDIR/generalisation.png: each law's worst error per case (the largest of boom, arm and bucket),
    the cases sorted per law, failed runs marked
  FIGDIR/generalisation_regions.png: LAW's RMS over BASELINE's (the worse of arm and bucket) against
    each drawn knob, the criterion's line at 0.5, failed runs marked
exit 1 when a case of the table has no run line or a law's run has no errors; 2 on bad arguments
"""
import csv
import glob
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

JOINTS = ("boom", "arm", "bucket")
INDEX = {"swing": 0, "boom": 1, "arm": 2, "bucket": 3}


def fail(msg, code=1):
    print("plot_generalisation: " + msg, file=sys.stderr)
    sys.exit(code)


def args(argv):
    if not argv or argv[0] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0 if argv else 2)
    opts = {"dir": argv[0], "figures": argv[0], "baseline": "pid", "law": "adaptive"}
    rest = argv[1:]
    while rest:
        if rest[0] not in ("--figures", "--baseline", "--law") or len(rest) < 2:
            fail("unknown or incomplete option '%s' (see --help)" % rest[0], 2)
        opts[rest[0][2:]] = rest[1]
        rest = rest[2:]
    return opts


def per_joint(run, key):
    v = run.get(key)
    if isinstance(v, dict):
        return {j: v.get(j) for j in JOINTS}
    if isinstance(v, list):
        return {j: v[INDEX[j]] for j in JOINTS}
    return None


def percentile(xs, p):
    xs = sorted(x for x in xs if not math.isnan(x))
    if not xs:
        return math.nan
    k = (len(xs) - 1) * p
    lo, hi = int(math.floor(k)), int(math.ceil(k))
    return xs[lo] + (xs[hi] - xs[lo]) * (k - lo)


def main(argv):
    o = args(argv)
    table = os.path.join(o["dir"], "sweep.csv")
    if not os.path.isfile(table):
        fail("%s is not there: run excavator-sim sweep-merge first" % table, 2)
    with open(table) as f:
        rows = list(csv.DictReader(f))
    if not rows:
        fail("%s has no cases" % table)
    laws = [c[:-3] for c in rows[0].keys() if c.endswith("_ok")]
    for law in (o["baseline"], o["law"]):
        if law not in laws:
            fail("law '%s' is not in %s (laws: %s)" % (law, table, ", ".join(laws)), 2)
    knobs = []
    for c in rows[0].keys():
        if c == "case" or any(c.startswith(l + "_") for l in laws):
            continue
        knobs.append(c)
    wanted = {int(r["case"]) for r in rows}
    runs = {}
    for path in sorted(glob.glob(os.path.join(o["dir"], "shard-*.jsonl"))):
        with open(path) as f:
            for line in f:
                try:
                    j = json.loads(line)
                except ValueError:
                    continue
                if j.get("case") in wanted:
                    runs.setdefault(j["case"], j)
    missing = sorted(wanted - set(runs))
    if missing:
        fail("%d case(s) of the table have no run line in %s/shard-*.jsonl, e.g. %s" % (len(missing), o["dir"], missing[:5]))

    cases = sorted(wanted)
    stats = {}
    for law in laws:
        s = {"failed": [], "rms": {j: [] for j in JOINTS}, "max": {j: [] for j in JOINTS}, "worst": []}
        for c in cases:
            run = runs[c].get(law, {})
            rms, mx = per_joint(run, "rms_error"), per_joint(run, "max_error")
            if rms is None or mx is None:
                fail("case %d: the %s run has no errors per joint" % (c, law))
            if not run.get("ok", False):
                s["failed"].append((c, run.get("failure", "")))
            for j in JOINTS:
                s["rms"][j].append(1e3 * float(rms[j]))
                s["max"][j].append(1e3 * float(mx[j]))
            s["worst"].append(1e3 * max(float(mx[j]) for j in JOINTS))
        stats[law] = s

    base, law = stats[o["baseline"]], stats[o["law"]]
    ratio = [max(law["rms"]["arm"][i] / base["rms"]["arm"][i], law["rms"]["bucket"][i] / base["rms"]["bucket"][i])
             for i in range(len(cases))]
    good = sum(1 for r in ratio if r <= 0.5)
    md = ["| law | failed runs | RMS boom / arm / bucket, mm: median (90th pct.) | worst error boom / arm / bucket, mm: median (largest) |",
          "|---|---|---|---|"]
    for l in laws:
        s = stats[l]
        rms = " / ".join("%.2f (%.2f)" % (percentile(s["rms"][j], 0.5), percentile(s["rms"][j], 0.9)) for j in JOINTS)
        mx = " / ".join("%.1f (%.1f)" % (percentile(s["max"][j], 0.5), max(s["max"][j])) for j in JOINTS)
        md.append("| %s | %d of %d | %s | %s |" % (l, len(s["failed"]), len(cases), rms, mx))
    md.append("")
    md.append("%s at least 2x better than %s on arm and bucket RMS: %d of %d cases (%.1f %%); ratio (worse of arm and bucket): median %.2f, 90th percentile %.2f, largest %.2f"
              % (o["law"], o["baseline"], good, len(cases), 100.0 * good / len(cases), percentile(ratio, 0.5),
                 percentile(ratio, 0.9), max(ratio)))
    for l in laws:
        for c, why in stats[l]["failed"][:5]:
            md.append("- %s failed in case %d: %s" % (l, c, why))
    text = "\n".join(md) + "\n"
    with open(os.path.join(o["dir"], "generalisation.md"), "w") as f:
        f.write(text)
    print(text, end="")

    os.makedirs(o["figures"], exist_ok=True)
    colours = {"pid": "tab:blue", "adaptive": "tab:red", "flow": "tab:green"}
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for l in laws:
        s = stats[l]
        order = sorted(range(len(cases)), key=lambda i: s["worst"][i])
        ys = [s["worst"][i] for i in order]
        ax.plot(range(len(ys)), ys, color=colours.get(l), label="%s (%d failed)" % (l, len(s["failed"])))
        bad = [(k, ys[k]) for k, i in enumerate(order) if not runs[cases[i]][l].get("ok", False)]
        if bad:
            ax.plot([b[0] for b in bad], [b[1] for b in bad], "x", color=colours.get(l))
    ax.set_yscale("log")
    ax.set_xlabel("case, sorted per law (%d cases)" % len(cases))
    ax.set_ylabel("worst error of boom, arm, bucket (mm)")
    ax.set_title("Generalisation sweep: each law's worst tracking error per case")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(o["figures"], "generalisation.png"), dpi=110)
    plt.close(fig)

    n = len(knobs)
    cols = 3
    fig, axes = plt.subplots((n + cols - 1) // cols, cols, figsize=(11, 3.2 * ((n + cols - 1) // cols)), squeeze=False)
    for k, knob in enumerate(knobs):
        ax = axes[k // cols][k % cols]
        xs = [float(r[knob]) for r in sorted(rows, key=lambda r: int(r["case"]))]
        ok = [runs[c][o["law"]].get("ok", False) and runs[c][o["baseline"]].get("ok", False) for c in cases]
        ax.scatter([x for x, g in zip(xs, ok) if g], [r for r, g in zip(ratio, ok) if g], s=6, alpha=0.5, color="tab:red")
        ax.scatter([x for x, g in zip(xs, ok) if not g], [r for r, g in zip(ratio, ok) if not g], s=30, marker="x", color="k")
        ax.axhline(0.5, color="k", linestyle="--", linewidth=1)
        ax.set_yscale("log")
        ax.set_xlabel(knob)
        ax.set_ylabel("%s / %s RMS" % (o["law"], o["baseline"]))
        ax.grid(True, which="both", alpha=0.3)
    for k in range(n, axes.size):
        axes[k // cols][k % cols].axis("off")
    fig.suptitle("%s RMS over %s's (worse of arm and bucket) per drawn knob; below the dashed line: 2x better"
                 % (o["law"], o["baseline"]))
    fig.tight_layout()
    fig.savefig(os.path.join(o["figures"], "generalisation_regions.png"), dpi=80)
    plt.close(fig)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

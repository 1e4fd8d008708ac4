"""A run's telemetry as plot-run reads it, from `excavator-log export`'s CSVs, in memory that does not
grow with the run: only the columns the figures and tables use, as arrays of doubles. A long channel
(more than excavator-log's --bucket-rows messages) is read from its bucketed view (buckets/ or, beyond
--full-rows, the CSV itself; per time bucket: first, last, min, max and the sums of every column)
and its detail rows (detail/: every message around each controller's largest error per joint and at
the run's end), never row by row; its RMS figures are exact over every message all the same."""
import array
import csv
import math
import os
import re

import numpy as np

from plot_failure import fail

# The columns the figures and tables read; the others are not kept.
USED = re.compile(r"(utime|log_utime|mode|stage|bin_width_us|p99_us|max_us|"
                  r"(q_desired|q_active|error|soil_force|theta_hat|theta_true|bins)_\d+)$")
ERROR = re.compile(r"error_\d+$")
STATS = ("first", "last", "min", "max", "sum", "sumsq", "n")

ZOOM_HALF_WIDTH = 2.0  # s either side of a controller's largest error (excavator-log's detail rows)
COMMANDED_MODES = (2.0, 3.0)  # hold, track: the firmware's modes in which q_desired exists


class Columns(dict):
    """One channel: {column: array of floats} of every message, or of the detail rows when the
    channel was exported as its bucketed view; then `buckets` is {column: {stat: numpy array}} with
    "rows" and "utime" spans per bucket. `rms` is {error column: RMS over every message}."""

    def __init__(self, columns=(), buckets=None, rms=None):
        super().__init__(columns)
        self.buckets = buckets
        self.rms = rms or {}


def read_table(path, last_per=None):
    """(header, {used column: array('d')}) of a CSV; a bucketed view's columns are c_stat. last_per:
    keep only the last row of each value of that column (counters that hold the run so far)."""
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader, None)
        if header is None:
            return [], {}
        bucketed = header[0] == "bucket"
        keep = [(i, name) for i, name in enumerate(header)
                if USED.match(name.rsplit("_", 1)[0] if bucketed and "_" in name else name)
                or name in ("bucket", "rows")]
        table = {name: array.array("d") for _, name in keep}
        last = {}
        key = header.index(last_per) if last_per in header else None
        for line_no, row in enumerate(reader, start=2):
            if len(row) != len(header):
                fail("%s line %d: %d fields, header has %d" % (path, line_no, len(row), len(header)))
            if key is not None:
                last.pop(row[key], None)
                last[row[key]] = row  # in the order of each value's last row
                continue
            for i, name in keep:
                table[name].append(number(row[i]))
        for row in last.values():
            for i, name in keep:
                table[name].append(number(row[i]))
    return header, table


def number(text):
    try:
        return float(text)
    except ValueError:
        return float("nan")


def exact_rms(values):
    """RMS over the finite values, summed in row order (NaN without any)."""
    sum_sq, counted = 0.0, 0
    for v in values:
        if not math.isnan(v):
            sum_sq += v * v
            counted += 1
    return math.sqrt(sum_sq / counted) if counted else float("nan")


def read_channel(directory, name, last_per=None):
    """The Columns of directory/name: every row, or its bucketed view and its detail rows."""
    view = os.path.join(directory, "buckets", name)
    header, table = read_table(view if os.path.exists(view) else os.path.join(directory, name), last_per)
    if not header or header[0] != "bucket":
        return Columns(table, rms={c: exact_rms(v) for c, v in table.items() if ERROR.match(c)})
    buckets = {"rows": np.asarray(table.pop("rows"))}
    for column, values in table.items():
        base, _, stat = column.rpartition("_")
        if stat in STATS:
            buckets.setdefault(base, {})[stat] = np.asarray(values)
    rms = {}
    for c, b in buckets.items():
        if ERROR.match(c):
            n = b["n"].sum()
            rms[c] = math.sqrt(b["sumsq"].sum() / n) if n else float("nan")
    detail = os.path.join(directory, "detail", name)
    rows = read_table(detail, last_per)[1] if os.path.exists(detail) else {}
    return Columns(rows, buckets=buckets, rms=rms)


def seconds(columns):
    return [u * 1e-6 for u in columns.get("utime", [])]


def commanded(ctrl, column):
    """The column where the firmware commands the machine (hold or track); NaN before, so that the
    desired trajectory is not drawn at 0 while the firmware starts up."""
    modes = ctrl.get("mode", [])
    return [v if i < len(modes) and modes[i] in COMMANDED_MODES else float("nan")
            for i, v in enumerate(ctrl[column])]


def is_long(columns):
    """Drawn as an envelope: the channel has a bucketed view."""
    return bool(columns) and columns.buckets is not None


def bucket_times(columns):
    """The middle of each bucket of the bucketed view, s."""
    return 0.5e-6 * (columns.buckets["utime"]["min"] + columns.buckets["utime"]["max"])


def envelope(columns, column, only_commanded=False):
    """(t, lo, hi) in s: min and max of a column per time bucket of the bucketed view, NaN where it has
    no value (a gap). only_commanded: NaN in a bucket with a message outside hold or track."""
    b = columns.buckets
    lo, hi = b[column]["min"].copy(), b[column]["max"].copy()
    if only_commanded:
        outside = (b["mode"]["min"] < min(COMMANDED_MODES)) | (b["mode"]["max"] > max(COMMANDED_MODES))
        lo[outside] = hi[outside] = float("nan")
    return bucket_times(columns), lo, hi


def worst_window(ctrl, j):
    """(t_worst, |e| there) of the largest error of joint j in hold or track (every row or the
    detail rows, which hold it), or None."""
    if not ctrl or "error_%d" % j not in ctrl:
        return None
    e = np.abs(np.asarray(commanded(ctrl, "error_%d" % j)))
    if not len(e) or np.all(np.isnan(e)):
        return None
    k = int(np.nanargmax(e))
    return ctrl["utime"][k] * 1e-6, float(e[k])


def within(columns, t0, t1, column, only_commanded=False):
    """(t, values) of the rows with t0 <= t <= t1 (only_commanded: NaN outside hold and track)."""
    t = np.asarray(columns.get("utime", [])) * 1e-6
    keep = (t >= t0) & (t <= t1)
    values = np.asarray(columns[column])[keep]
    if only_commanded:
        values = np.where(np.isin(np.asarray(columns["mode"])[keep], COMMANDED_MODES), values, np.nan)
    return t[keep], values


def discover_runs(csv_dirs):
    """{run label: {channel base name: Columns}} from the CSV directories."""
    runs = {}
    for directory in csv_dirs:
        if not os.path.isdir(directory):
            fail("%s: not a directory (expected the output of excavator-log export)" % directory)
        names = sorted(n for n in os.listdir(directory) if n.endswith(".csv"))
        if not any(n.startswith("EXC_STATE") for n in names):
            fail("%s: no EXC_STATE*.csv (is this an excavator-log export directory?)" % directory)
        for name in names:
            stem = name[:-4]
            base, _, suffix = stem.partition("__")
            label = suffix if suffix else os.path.basename(os.path.normpath(directory))
            # Timing counters hold the run so far: the last message of each stage is the run's.
            last_per = "stage" if base == "EXC_TIMING" else None
            runs.setdefault(label, {})[base] = read_channel(directory, name, last_per)
    # The baseline first, the adaptive law second, as in the paper's side-by-side figures.
    order = {"pid": 0, "adaptive": 1}
    return dict(sorted(runs.items(), key=lambda kv: (order.get(kv[0], 2), kv[0])))

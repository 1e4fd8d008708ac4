#!/usr/bin/python3
"""Checks in a candump -L capture, decoded with canmatrix (Debian's python3-canmatrix, an independent
DBC reader), that each of the firmware's emergency stops held until an operator's acknowledge:

For each SUPERVISOR frame with Command = acknowledge, the stop before it begins at the first
FW_EMERGENCY with EmergencyStop = 1 after the previous acknowledge. From there to the acknowledge:
every FW_EMERGENCY carries EmergencyStop = 1 (no release), every command frame is CMD_VALVE with all
four valves centred (no CMD_PILOT, no CMD_EFFORT), and at least --min-cycles SYNC frames pass (the
firmware stayed stopped, not just for a moment). After the acknowledge the firmware releases the
machine (FW_EMERGENCY EmergencyStop = 0, FaultCode 0) within --release-cycles SYNCs. The stops'
FaultCodes must be --expect-codes in order (e.g. 16,1: spool disagreement, a stuck spool; then
sensor timeout). With --controlled the stops are controlled ones (EmergencyStop = 0, FaultCode not 0:
an operator's stop, a lost operator link): each begins at the first FW_EMERGENCY with a FaultCode
after the previous acknowledge and holds that code with EmergencyStop = 0.

Exit 0 when every check holds, 1 otherwise, 2 for bad arguments or a missing canmatrix.
"""
import argparse
import re
import sys

LINE = re.compile(r"^\((\d+)\.(\d+)\) (\S+) ([0-9A-Fa-f]{3})(##?)(.*)$")
ACKNOWLEDGE = 3


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--dbc", required=True, help="the DBC file (hal/excavator.dbc)")
    parser.add_argument("--expect-codes", required=True, help="the stops' FaultCodes in order, comma-separated")
    parser.add_argument("--min-cycles", type=int, default=50, help="SYNCs each stop must last at least")
    parser.add_argument("--release-cycles", type=int, default=5, help="SYNCs after an acknowledge to the release")
    parser.add_argument("--controlled", action="store_true", help="the stops are controlled (EmergencyStop = 0)")
    parser.add_argument("capture", help="a candump -L log")
    args = parser.parse_args()
    try:
        expected = [int(c) for c in args.expect_codes.split(",")]
    except ValueError:
        print(f"ack_capture_check: --expect-codes '{args.expect_codes}': not comma-separated whole numbers", file=sys.stderr)
        return 2
    try:
        import logging
        logging.disable(logging.WARNING)
        import warnings
        warnings.simplefilter("ignore")
        import canmatrix.formats
    except ImportError as e:
        print(f"ack_capture_check: cannot import canmatrix ({e}): install python3-canmatrix, run with /usr/bin/python3",
              file=sys.stderr)
        return 2
    db = canmatrix.formats.loadp_flat(args.dbc)
    frames = []  # (line, name, values)
    with open(args.capture) as f:
        for number, text in enumerate(f, 1):
            m = LINE.match(text.strip())
            if not m:
                continue
            rest = m.group(6)[1:] if m.group(5) == "##" else m.group(6)
            frame = db.frame_by_id(canmatrix.ArbitrationId(int(m.group(4), 16), extended=False))
            if frame is None:
                continue
            values = {n: float(s.phys_value) for n, s in frame.decode(bytearray(bytes.fromhex(rest))).items()}
            frames.append((number, frame.name, values))
    errors, stops = [], []
    onset = None  # index of the current stop's first EmergencyStop = 1 frame
    for i, (line, name, v) in enumerate(frames):
        stop_bit = 0 if args.controlled else 1
        if name == "FW_EMERGENCY" and v["EmergencyStop"] == stop_bit and (stop_bit == 1 or v["FaultCode"] != 0) and onset is None:
            onset = i
        if name == "SUPERVISOR" and v["Command"] == ACKNOWLEDGE and onset is not None:
            stops.append((onset, i))
            onset = None
    for n, (start, ack) in enumerate(stops, 1):
        code = int(frames[start][2]["FaultCode"])
        where = f"stop {n} (FaultCode {code}, lines {frames[start][0]}..{frames[ack][0]})"
        syncs = 0
        for line, name, v in frames[start:ack]:
            syncs += name == "SYNC"
            if name == "FW_EMERGENCY" and (v["EmergencyStop"] != (0 if args.controlled else 1) or int(v["FaultCode"]) != code):
                errors.append(f"{where}: line {line}: FW_EMERGENCY {v} before the acknowledge")
            elif name in ("CMD_PILOT", "CMD_EFFORT"):
                errors.append(f"{where}: line {line}: {name} (a motion command) before the acknowledge")
            elif name == "CMD_VALVE" and any(v[s] != 0 for s in ("SwingValve", "BoomValve", "ArmValve", "BucketValve")):
                errors.append(f"{where}: line {line}: CMD_VALVE {v} (valves not centred) before the acknowledge")
        if syncs < args.min_cycles:
            errors.append(f"{where}: stopped for only {syncs} cycles, fewer than {args.min_cycles}")
        released, after = None, 0
        for line, name, v in frames[ack + 1:]:
            after += name == "SYNC"
            if after > args.release_cycles:
                break
            if name == "FW_EMERGENCY" and v["EmergencyStop"] == 0 and v["FaultCode"] == 0:
                released = after
                break
        if released is None:
            errors.append(f"{where}: no release (FW_EMERGENCY EmergencyStop=0) within {args.release_cycles} cycles "
                          "of the acknowledge")
        print(f"{args.capture}: {where}: EmergencyStop={0 if args.controlled else 1} held for {syncs} cycles, valves centred and no motion "
              f"command until the acknowledge, released {released} cycles after it")
    codes = [int(frames[s][2]["FaultCode"]) for s, _ in stops]
    if codes != expected:
        errors.append(f"the stops' FaultCodes are {codes}, expected {expected}")
    for e in errors[:20]:
        print(f"{args.capture}: {e}")
    print(f"{args.capture}: {len(stops)} stops held until an acknowledge, {len(errors)} errors")
    return 0 if not errors else 1


if __name__ == "__main__":
    sys.exit(main())

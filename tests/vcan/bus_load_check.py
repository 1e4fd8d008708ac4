#!/usr/bin/python3
"""Checks EXC_CAN_STATS.bus_load in a firmware's LCM log against a candump -L capture of the same run.

The firmware end sees every frame of the two-node bus (it sends its own and receives the plant's), and
publishes on EXC_CAN_STATS (node 0) the fraction of bus time its frames took since its previous
message, from each frame's exact on-wire length (hal/can_bus_load.cpp). Summed over the messages
(bus_load x the window since the previous message's utime) this is the run's whole bus time. Here the
same figure is computed another way: the frames from the kernel's capture, each frame's length built
bit by bit from ISO 11898-1:2015 in this file (SOF, identifier, control bits, DLC, data, the dynamic
stuff bits after five equal bits, the fixed-stuffed stuff count and CRC field, CRC delimiter, ACK, EOF
and intermission; the bits from ESI to the end of the CRC field at the data rate when BRS is set), and
the bus's rates from the command line (the DBC's 1 Mbit/s and 5 Mbit/s). The log is read as LCM's
event log format and can_stats_t from its .lcm field order, without LCM's code.

Prints both figures, the frames per identifier and the DBC's bounds (the same frames without stuff
bits and with the worst-case stuffing); exit 0 when the two figures agree to within --tolerance-us
(default 10 us, less than a fifth of the shortest frame) and the load is not zero, 1 otherwise, 2 for
bad input.
"""
import argparse
import re
import struct
import sys

LINE = re.compile(r"^\((\d+)\.(\d+)\) (\S+) ([0-9A-Fa-f]{3})(##?)(.*)$")
LOG_SYNC = 0xEDA1DA01
FD_LENGTHS = (0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64)


def lcm_events(path):
    """(channel, data) of every event of an LCM log file."""
    with open(path, "rb") as f:
        blob = f.read()
    at = 0
    while at + 28 <= len(blob):
        sync, _number, _timestamp, channel_len, data_len = struct.unpack_from(">IqqII", blob, at)
        if sync != LOG_SYNC:
            raise ValueError(f"{path}: no event sync word at byte {at}")
        at += 28
        channel = blob[at:at + channel_len].decode()
        at += channel_len
        yield channel, blob[at:at + data_len]
        at += data_len


def can_stats(data):
    """can_stats_t (lcmtypes/can_stats_t.lcm): fingerprint, utime, seq, node, 8 counters, bus_load."""
    fields = struct.unpack_from(">8sqqb8qd", data, 0)
    return {"utime": fields[1], "seq": fields[2], "node": fields[3], "tx": fields[4], "rx_ok": fields[5],
            "bus_load": fields[12]}


def stuffed(bits):
    """The bits as sent, as (index of the original bit it is or follows, is a stuff bit): a stuff bit
    (the complement) after every five equal bits, stuff bits counting towards the next run."""
    out, last, run = [], None, 0
    for i, b in enumerate(bits):
        out.append((i, False))
        run = run + 1 if b == last else 1
        last = b
        if run == 5:
            out.append((i, True))
            last, run = 1 - b, 1
    return out


def bits_of(value, width):
    return [(value >> i) & 1 for i in range(width - 1, -1, -1)]


def frame_bits(ident, data, fd, brs):
    """(nominal bits, data-phase bits) of one standard data frame on the wire, intermission included."""
    tail = 1 + 1 + 1 + 7 + 3  # CRC delimiter, ACK slot, ACK delimiter, EOF, intermission: nominal rate
    if not fd:
        head = [0] + bits_of(ident, 11) + [0, 0, 0] + bits_of(len(data), 4)  # SOF, ID, RTR, IDE, r0, DLC
        body = head + [b for byte in data for b in bits_of(byte, 8)]
        crc = 0
        for b in body:
            nxt = ((crc >> 14) & 1) != b
            crc = (crc << 1) & 0x7FFF
            if nxt:
                crc ^= 0x4599
        return len(stuffed(body + bits_of(crc, 15))) + tail, 0
    # SOF, ID, RRS, IDE, FDF, res, BRS | ESI, DLC, data: dynamically stuffed from SOF to the data's end.
    arbitration = [0] + bits_of(ident, 11) + [0, 0, 1, 0, 1 if brs else 0]
    rest = [0] + bits_of(FD_LENGTHS.index(len(data)), 4) + [b for byte in data for b in bits_of(byte, 8)]
    sent = stuffed(arbitration + rest)
    # The rate switches at BRS's sample point: BRS and every bit before it (stuff bits among them) go
    # at the nominal rate, a stuff bit after BRS and everything after it at the data rate.
    brs_index = len(arbitration) - 1
    slow = sum(1 for i, stuff in sent if i < brs_index or (i == brs_index and not stuff))
    # Stuff count (3-bit Gray code + parity) and CRC (17 bits up to 16 data bytes, 21 above), with a
    # fixed stuff bit before the stuff count and after every 4 bits.
    crc_bits = 4 + (17 if len(data) <= 16 else 21)
    crc_field = crc_bits + 1 + crc_bits // 4
    fast = len(sent) - slow + crc_field
    if not brs:
        return slow + fast + tail, 0
    return slow + tail, fast


def worst_bits(n, fd=True):
    """The kernel's can_frame_bits() worst case of an FD frame of n bytes (every stuff bit it can have)."""
    stuffable = 22 + 8 * n
    crc_field = 27 if n <= 16 else 32
    return 22 + 8 * n + (stuffable - 1) // 4 + crc_field + 13


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--log", required=True, help="the firmware's LCM log (excavator-firmware --lcm file://...)")
    parser.add_argument("--channel", default="EXC_CAN_STATS")
    parser.add_argument("--nominal", type=int, default=1000000, help="arbitration bit rate (the DBC's Baudrate)")
    parser.add_argument("--data", type=int, default=5000000, help="data-phase bit rate (the DBC's BaudrateCANFD)")
    parser.add_argument("--tolerance-us", type=float, default=10.0)
    parser.add_argument("capture", help="a candump -L capture of the same run")
    args = parser.parse_args()
    nominal_ns, data_ns = 1e9 / args.nominal, 1e9 / args.data

    try:
        stats = [can_stats(d) for c, d in lcm_events(args.log) if c == args.channel]
    except (OSError, ValueError, struct.error) as e:
        print(f"bus_load_check: {e}", file=sys.stderr)
        return 2
    stats = [s for s in stats if s["node"] == 0]
    if not stats:
        print(f"bus_load_check: {args.log}: no {args.channel} message of the firmware end (node 0)", file=sys.stderr)
        return 2
    logged_ns, last_utime = 0.0, 0
    for s in stats:
        logged_ns += s["bus_load"] * (s["utime"] - last_utime) * 1e3
        last_utime = s["utime"]

    frames, counted_ns, unstuffed_ns, worst_ns, per_id = 0, 0.0, 0.0, 0.0, {}
    with open(args.capture) as f:
        for number, text in enumerate(f, 1):
            m = LINE.match(text.rstrip("\n"))
            if not m:
                print(f"bus_load_check: {args.capture} line {number}: not a standard candump -L frame", file=sys.stderr)
                return 2
            ident, fd, rest = int(m.group(4), 16), m.group(5) == "##", m.group(6)
            brs = fd and int(rest[0], 16) & 1 == 1
            data = bytes.fromhex(rest[1:] if fd else rest)
            nominal, fast = frame_bits(ident, data, fd, brs)
            counted_ns += nominal * nominal_ns + fast * data_ns
            # The DBC's bounds for the same frame (BRS): no stuff bit at all, and every one it can have.
            plain_fast = 5 + 8 * len(data) + (27 if len(data) <= 16 else 32)
            unstuffed_ns += 30 * nominal_ns + plain_fast * data_ns
            worst_ns += 34 * nominal_ns + (worst_bits(len(data)) - 34) * data_ns
            per_id[ident] = per_id.get(ident, 0) + 1
            frames += 1
    seconds = last_utime * 1e-6
    print(f"{args.log}: {len(stats)} {args.channel} messages of the firmware end over {seconds:.3f} s: "
          f"bus time {logged_ns * 1e-3:.1f} us from bus_load ({logged_ns * 1e-9 / seconds * 100 if seconds else 0:.2f} %)")
    print(f"{args.capture}: {frames} frames, exact on-wire time {counted_ns * 1e-3:.1f} us "
          f"({counted_ns * 1e-9 / seconds * 100 if seconds else 0:.2f} %); without stuff bits {unstuffed_ns * 1e-3:.1f} us, "
          f"worst-case stuffing {worst_ns * 1e-3:.1f} us")
    print("  frames per identifier: " + ", ".join(f"0x{i:03X} {n}" for i, n in sorted(per_id.items())))
    difference_us = (logged_ns - counted_ns) * 1e-3
    print(f"difference {difference_us:+.3f} us (tolerance {args.tolerance_us} us)")
    errors = []
    if logged_ns <= 0:
        errors.append("bus_load is zero in every message")
    if abs(difference_us) > args.tolerance_us:
        errors.append(f"the log's bus time differs from the capture's by {difference_us:+.1f} us")
    if not unstuffed_ns < counted_ns < worst_ns:
        errors.append("the capture's bus time is outside the DBC's bounds")
    for e in errors:
        print(f"bus_load_check: FAIL: {e}")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())

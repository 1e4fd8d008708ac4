#!/usr/bin/python3
"""Decodes a candump -L capture of the excavator bus with canmatrix, an independent DBC reader
(Debian's python3-canmatrix), so the project's codec is not the only judge of its own frames.

Run it with Debian's /usr/bin/python3 (canmatrix is a Debian package, not a pip one).

For every line: the DBC's frame for the identifier, the frame format canmatrix reads from the DBC
(VFrameFormat StandardCAN_FD, CANFD_BRS) against the line's ("##" and the flags digit), the length,
the CRC-8 SAE J1850 of the last byte (written here from its definition), then every signal decoded
by canmatrix. With --expect, a JSON-lines file of what the sender put in each frame (one object a
frame, in capture order: {"line": N, "message": NAME, "signals": {SIGNAL: physical value}}), each
decoded value must equal the sent one within half the signal's factor.

Prints a summary line, frames per message and the first errors; exit 0 when the capture decodes
clean (and matches), 1 otherwise, 2 for bad arguments or a missing canmatrix.
"""
import argparse
import json
import re
import sys

LINE = re.compile(r"^\((\d+)\.(\d+)\) (\S+) ([0-9A-Fa-f]{3}|[0-9A-Fa-f]{8})(##?)(.*)$")


def crc8_sae_j1850(data):
    crc = 0xFF
    for byte in data:
        crc ^= byte
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1D) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc ^ 0xFF


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--dbc", required=True, help="the DBC file (hal/excavator.dbc)")
    parser.add_argument("--expect", help="JSON lines of the values sent, one object per frame")
    parser.add_argument("--nominal", type=int, default=1000000, help="the arbitration rate the DBC must state")
    parser.add_argument("--data", type=int, default=5000000, help="the data-phase rate the DBC must state")
    parser.add_argument("capture", help="a candump -L log")
    args = parser.parse_args()
    try:
        import logging
        logging.disable(logging.WARNING)  # canmatrix warns about optional formats it cannot load
        import warnings
        warnings.simplefilter("ignore")
        import canmatrix.formats
    except ImportError as e:
        print(f"canmatrix_decode: cannot import canmatrix ({e}): install the Debian package python3-canmatrix "
              "(tools/install-deps test) and run with /usr/bin/python3", file=sys.stderr)
        return 2
    db = canmatrix.formats.loadp_flat(args.dbc)
    errors = []
    # The bus as the DBC states it, read by canmatrix.
    rates = (int(db.attributes.get("Baudrate", 0)), int(db.attributes.get("BaudrateCANFD", 0)))
    if rates != (args.nominal, args.data):
        errors.append(f"{args.dbc}: Baudrate/BaudrateCANFD {rates}, expected {(args.nominal, args.data)}")
    expected = []
    if args.expect:
        with open(args.expect) as f:
            expected = [json.loads(line) for line in f if line.strip()]
    frames = 0
    per_message = {}
    decoded_frames = []
    with open(args.capture) as f:
        for number, text in enumerate(f, 1):
            text = text.rstrip("\n")
            if not text.strip():
                continue
            frames += 1
            where = f"line {number}: "
            m = LINE.match(text)
            if not m:
                errors.append(where + "not a candump -L line")
                continue
            ident, hashes, rest = int(m.group(4), 16), m.group(5), m.group(6)
            fd = hashes == "##"
            brs = False
            if fd:
                if not rest or rest[0] not in "0123456789ABCDEFabcdef":
                    errors.append(where + "no CAN FD flags digit")
                    continue
                brs = int(rest[0], 16) & 1 == 1
                rest = rest[1:]
            try:
                data = bytes.fromhex(rest)
            except ValueError:
                errors.append(where + "data are not hex bytes")
                continue
            frame = db.frame_by_id(canmatrix.ArbitrationId(ident, extended=len(m.group(4)) == 8))
            if frame is None:
                errors.append(where + f"identifier 0x{ident:03X} is not in the DBC")
                continue
            dbc_brs = str(frame.attributes.get("CANFD_BRS", "0")).strip('"') == "1"
            if fd != frame.is_fd or brs != dbc_brs:
                errors.append(where + f"{frame.name}: fd {fd} brs {brs}, the DBC (canmatrix) says fd {frame.is_fd} "
                              f"brs {dbc_brs}")
                continue
            if len(data) != frame.size:
                errors.append(where + f"{frame.name}: {len(data)} bytes, the DBC says {frame.size}")
                continue
            id_bytes = bytes([ident & 0xFF, (ident >> 8) & 0xFF])
            if crc8_sae_j1850(id_bytes + data[:-1]) != data[-1]:
                errors.append(where + f"{frame.name}: CRC-8 0x{data[-1]:02X}, computed "
                              f"0x{crc8_sae_j1850(id_bytes + data[:-1]):02X}")
                continue
            values = {name: float(signal.phys_value) for name, signal in frame.decode(bytearray(data)).items()}
            per_message[frame.name] = per_message.get(frame.name, 0) + 1
            decoded_frames.append((number, frame, values))
    if frames == 0:
        errors.append("the capture has no frames")
    if args.expect:
        if len(expected) != len(decoded_frames):
            errors.append(f"{len(decoded_frames)} frames decoded, {len(expected)} expected")
        checked = mismatched = 0
        for (number, frame, values), want in zip(decoded_frames, expected):
            where = f"line {number}: "
            if want["message"] != frame.name:
                errors.append(where + f"{frame.name}, the sender sent {want['message']}")
                continue
            for name, sent in want["signals"].items():
                signal = frame.signal_by_name(name)
                if signal is None:
                    errors.append(where + f"{frame.name} has no signal {name}")
                    continue
                tolerance = 0.5 * float(signal.factor) * (1 + 1e-9) + 1e-12 * abs(sent)
                if abs(values[name] - sent) > tolerance:
                    errors.append(where + f"{frame.name}.{name} decoded {values[name]!r}, sent {sent!r}")
                    mismatched += 1
                checked += 1
        print(f"{args.capture}: {checked - mismatched} of {checked} signal values equal to what was sent "
              "(within half a step of the DBC's factor)")
    print(f"{args.capture}: {frames} frames decoded by canmatrix against {args.dbc} "
          f"(CAN FD, {rates[0]} / {rates[1]} bit/s), {len(errors)} errors")
    for name in sorted(per_message):
        print(f"  {name}: {per_message[name]}")
    for e in errors[:30]:
        print(f"{args.capture}: {e}")
    if len(errors) > 30:
        print(f"({len(errors) - 30} more errors)")
    return 0 if not errors else 1


if __name__ == "__main__":
    sys.exit(main())

"""Drives pyptzcontroller (PyPI, PELCO-D) over a serial port: the
simulator's PELCO PTY (`cargo xtask sim --pelco-pty PATH`), through
pyserial, as it would drive a PTZ head on an RS-485 adapter.

Arguments: the port's path and the dialect, `D` (the library's own
PELCO-D protocol table) or `P` (PELCO-P, given to the library as a
protocol table of its format: `A0 addr cmd1 cmd2 data1 data2 AF xor`,
device 1 = address byte 0). The session: absolute position home, pan and
tilt moves at several speeds each ended by a stop, absolute positions
with position queries, preset set / call / clear. Prints one JSON line:
the positions the library decoded from the board's query replies, in
order. The library's progress messages go to stderr; timing is the
host's (the test measures in the simulator's time, from its record of
the port's traffic).
"""

import contextlib
import functools
import json
import operator
import sys
import time

from ptz_control_lib import PtzControl
from ptz_control_lib.protocols import PELCO_D_PROTOCOL

#: (direction, speed byte, seconds) of the timed moves; pan first, then
#: tilt. Each stays inside the board (±24° pan, ±17° tilt at OQ 25 cm).
MOVES = [
    ("right", 0x20, 0.9),
    ("left", 0x10, 1.2),
    ("left", 0x08, 1.2),
    ("up", 0x20, 0.8),
    ("down", 0x10, 1.2),
    ("down", 0x08, 1.2),
]
#: Rest after a stop or an absolute move, s.
SETTLE_S = 1.0


def pelco_p_protocol():
    """The library's PELCO-D table in PELCO-P's frame."""
    protocol = dict(PELCO_D_PROTOCOL)
    meta = dict(protocol["__meta__"])
    meta["name"] = "Pelco-P"
    meta["format"] = [
        "0xA0", "{address}", "{cmd1}", "{cmd2}", "{data1}", "{data2}", "0xAF", "{checksum}",
    ]
    meta["checksum_calculator"] = lambda data: functools.reduce(operator.xor, data, 0)
    protocol["__meta__"] = meta
    return protocol


def main():
    port, dialect = sys.argv[1], sys.argv[2]
    positions = []
    with contextlib.redirect_stdout(sys.stderr):
        if dialect == "P":
            ptz = PtzControl(port, address=0, protocol=pelco_p_protocol())
        else:
            ptz = PtzControl(port, address=1)
        if not ptz.connect():
            sys.exit("cannot open " + port)
        ptz.move_to_pan_tilt(pan_angle=0.0, tilt_angle=0.0)
        time.sleep(SETTLE_S)
        for direction, speed, seconds in MOVES:
            ptz.move(direction, speed)
            time.sleep(seconds)
            ptz.stop()
            time.sleep(SETTLE_S)
        # Absolute positions (the library counts pan 0-360), each queried.
        for pan, tilt in [(8.0, -6.0), (351.5, 4.25)]:
            ptz.move_to_pan_tilt(pan_angle=pan, tilt_angle=tilt)
            time.sleep(SETTLE_S)
            positions.append(ptz.get_position())
        # Preset 7 at (-8.5, 4.25); away; back to it; cleared: no move.
        ptz.set_preset(7)
        ptz.move_to_pan_tilt(pan_angle=5.0, tilt_angle=5.0)
        time.sleep(SETTLE_S)
        ptz.go_to_preset(7)
        time.sleep(SETTLE_S)
        positions.append(ptz.get_position())
        ptz._send_command(ptz._create_command("clear_preset", preset_id=7))
        ptz.move_to_pan_tilt(pan_angle=0.0, tilt_angle=0.0)
        time.sleep(SETTLE_S)
        ptz.go_to_preset(7)
        time.sleep(SETTLE_S)
        positions.append(ptz.get_position())
        ptz.disconnect()
    print(json.dumps({"positions": positions}))


main()

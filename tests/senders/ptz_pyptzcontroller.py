"""Drives pyptzcontroller (PyPI, PELCO-D) through a scripted session and
prints, as one JSON line, the frames it wrote and the position it decoded.

The library talks to a pyserial port; this driver hands it a port object
that records what is written and replies with the bytes given in hex as
the first argument (the firmware's replies to the two position queries,
from tests/tests/pelco_client.rs), so the bytes on the wire are the
library's own. The library's progress messages go to stderr.
"""

import contextlib
import json
import sys

from ptz_control_lib import PtzControl


class RecordingPort:
    """The serial port as the library uses it."""

    def __init__(self, replies):
        self.is_open = True
        self.written = []
        self.replies = bytearray(replies)

    def reset_input_buffer(self):
        pass

    def write(self, data):
        self.written.append(bytes(data).hex())

    def read(self, n):
        out = bytes(self.replies[:n])
        del self.replies[:n]
        return out

    def close(self):
        self.is_open = False


def main():
    replies = bytes.fromhex(sys.argv[1]) if len(sys.argv) > 1 else b""
    with contextlib.redirect_stdout(sys.stderr):
        ptz = PtzControl("recorded", address=1)
        port = RecordingPort(replies)
        ptz.serial_port = port
        ptz.move("right", 0x20)
        ptz.move("left", 0x3F)
        ptz.move("up", 0x10)
        ptz.move("down", 0x08)
        ptz.stop()
        ptz.set_preset(5)
        ptz.go_to_preset(5)
        ptz._send_command(ptz._create_command("clear_preset", preset_id=5))
        ptz._send_command(ptz._create_command("aux_on", switch_id=1))
        ptz._send_command(ptz._create_command("aux_off", switch_id=1))
        ptz.move_to_pan_tilt(pan_angle=25.5, tilt_angle=-10.0)
        ptz.move_to_pan_tilt(pan_angle=12.25, tilt_angle=7.5)
        position = ptz.get_position()
    print(json.dumps({"written": port.written, "position": position}))


main()

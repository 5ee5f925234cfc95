"""Streams a G-code file to a grbl controller with pygrbl-streamer (PyPI,
character counting against a 128-byte RX buffer) while polling `?` at
5 Hz, optionally holding the feed (its pause(): `!`) HOLD_AT s after the
start and resuming (`~`) HOLD_FOR s later; prints a JSON summary.
Usage: stream_pygrbl.py PORT FILE [HOLD_AT HOLD_FOR]."""
import json
import sys
import threading
import time

from pygrbl_streamer import GrblStreamer

port, path = sys.argv[1], sys.argv[2]
hold = (float(sys.argv[3]), float(sys.argv[4])) if len(sys.argv) > 4 else None
summary = {"sender": "pygrbl-streamer", "errors": [], "alarms": [], "statuses": 0, "polls": 0}
lock = threading.Lock()
g = GrblStreamer(port=port, baudrate=115200, auto_unlock=False)


def received(line):
    if line.startswith("<"):
        with lock:
            summary["statuses"] += 1


g.receive_callback = received
g.error_callback = lambda line: summary["errors"].append(line)
g.alarm_callback = lambda line: summary["alarms"].append(line)
g.connect()
original_realtime = g.realtime


def counting_realtime(char):
    # Every `?` written (ours and the library's own), from here on.
    if char == b"?":
        with lock:
            summary["polls"] += 1
    original_realtime(char)


with lock:
    summary["statuses"] = 0
g.realtime = counting_realtime
stop = threading.Event()


def poll():
    while not stop.is_set():
        g.realtime(b"?")
        time.sleep(0.2)


def hold_and_resume():
    if stop.wait(hold[0]):
        return
    g.pause()
    summary["held"] = g.state.name
    time.sleep(hold[1])
    g.resume()


poller = threading.Thread(target=poll)
holder = threading.Thread(target=hold_and_resume) if hold else None
start = time.monotonic()
poller.start()
if holder:
    holder.start()
summary["completed"] = g.send_file(path, completion_timeout=300)
summary["seconds"] = time.monotonic() - start
stop.set()
poller.join()
if holder:
    holder.join()
time.sleep(0.5)  # the last poll's report
g.disconnect()
print(json.dumps(summary))

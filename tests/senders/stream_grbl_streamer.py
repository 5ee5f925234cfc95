"""Streams a G-code file to a grbl controller with grbl-streamer (PyPI,
the gerbil interface: character counting, `?` polled every 0.2 s);
optionally holds the feed (its hold(): `!`) HOLD_AT s after the start and
resumes (its resume(): `~`) HOLD_FOR s later; prints a JSON summary.
Usage: stream_grbl_streamer.py PORT FILE [HOLD_AT HOLD_FOR]."""
import json
import sys
import threading
import time

from grbl_streamer import GrblStreamer

port, path = sys.argv[1], sys.argv[2]
hold = (float(sys.argv[3]), float(sys.argv[4])) if len(sys.argv) > 4 else None
summary = {"sender": "grbl-streamer", "errors": [], "alarms": [], "statuses": 0, "polls": 0}
booted = threading.Event()
done = threading.Event()
last_state = {"state": None}


def on_event(event, *data):
    if event == "on_boot":
        booted.set()
    elif event == "on_error":
        summary["errors"].append(str(data))
    elif event == "on_alarm":
        summary["alarms"].append(str(data))
    elif event == "on_job_completed":
        done.set()


g = GrblStreamer(on_event)
# grbl-streamer 2.0.2 streams from two threads (job_run() in the caller's,
# every `ok` in its reader's) without a lock: when an `ok` arrives while
# the caller's thread still fills the RX buffer, both advance the line
# pointer and a line is skipped (seen: 103 of 104 lines written). Its
# character counting is kept; only its streaming step is serialised.
stream_lock = threading.Lock()
original_stream = g._stream


def locked_stream():
    with stream_lock:
        original_stream()


g._stream = locked_stream
g.cnect(port, 115200)
if not booted.wait(10):
    print(json.dumps({**summary, "completed": False, "why": "no banner"}))
    sys.exit(1)
time.sleep(0.5)
g.incremental_streaming = False  # character counting
summary["statuses"] = 0
original_write = g._iface.write


written = []


def counting_write(data):
    if data == "?":
        summary["polls"] += 1
    elif data not in ("!", "~"):  # realtime bytes are not lines
        written.append(data)
    return original_write(data)


g._iface.write = counting_write
original_update = g._update_state


def counting_update(line):
    summary["statuses"] += 1
    original_update(line)
    last_state["state"] = g.cmode


g._update_state = counting_update
g.poll_start()
start = time.monotonic()
with open(path) as f:
    g.write(f.read())
g.job_run()
if hold:
    time.sleep(max(0.0, start + hold[0] - time.monotonic()))
    g.hold()
    time.sleep(hold[1])
    g.resume()
finished = done.wait(300)
# The job is sent; wait for the motion to end.
deadline = time.monotonic() + 300
while time.monotonic() < deadline and last_state["state"] != "Idle":
    time.sleep(0.1)
summary["seconds"] = time.monotonic() - start
g.poll_stop()
time.sleep(0.5)
summary["completed"] = finished and last_state["state"] == "Idle"
g.disconnect()
summary["written"] = [w.strip() for w in written]
print(json.dumps(summary))

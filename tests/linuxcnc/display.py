#!/usr/bin/python3
"""The headless DISPLAY program of the simulator check: LinuxCNC starts it with `-ini FILE`.

It records every servo cycle with `halsampler` (joint positions and the beam output) into
$KERF_SAMPLES, switches the machine on, homes it, runs $KERF_PROGRAM in auto mode, waits for the
end, and writes $KERF_RESULT (JSON: errors from LinuxCNC's error channel, the final state). Then
it exits, which shuts LinuxCNC down.
"""
import json
import os
import subprocess
import sys
import time

import linuxcnc

program = os.environ["KERF_PROGRAM"]
samples = os.environ["KERF_SAMPLES"]
result_path = os.environ["KERF_RESULT"]
deadline = time.time() + float(os.environ.get("KERF_TIMEOUT", "240"))

s = linuxcnc.stat()
c = linuxcnc.command()
e = linuxcnc.error_channel()
errors = []


def poll_errors():
    while True:
        m = e.poll()
        if not m:
            return
        kind, text = m
        if kind in (linuxcnc.NML_ERROR, linuxcnc.OPERATOR_ERROR):
            errors.append(text)
        else:
            print("linuxcnc:", text, file=sys.stderr)


def wait(cond, what, limit=30.0):
    end = min(deadline, time.time() + limit)
    while time.time() < end:
        s.poll()
        poll_errors()
        if cond():
            return True
        time.sleep(0.01)
    errors.append(f"timeout waiting for {what}")
    return False


def finish(code):
    poll_errors()
    with open(result_path, "w") as f:
        json.dump({"errors": errors, "code": code}, f)
    sys.exit(0)


wait(lambda: s.task_state != 0, "task", 30)
c.state(linuxcnc.STATE_ESTOP_RESET)
wait(lambda: s.task_state == linuxcnc.STATE_ESTOP_RESET, "estop reset")
c.state(linuxcnc.STATE_ON)
wait(lambda: s.task_state == linuxcnc.STATE_ON, "machine on")
c.mode(linuxcnc.MODE_MANUAL)
c.wait_complete()
c.teleop_enable(False)
c.wait_complete()
c.home(-1)
if not wait(lambda: all(s.joint[j]["homed"] for j in range(s.joints)), "homing"):
    finish("homing")
c.mode(linuxcnc.MODE_AUTO)
c.wait_complete()
sampler = subprocess.Popen(["halsampler", "-t", "-c", "0"], stdout=open(samples, "w"))
time.sleep(0.3)
c.program_open(program)
c.wait_complete()
c.auto(linuxcnc.AUTO_RUN, 0)
wait(lambda: s.interp_state != linuxcnc.INTERP_IDLE, "program start", 10)
ok = wait(lambda: s.interp_state == linuxcnc.INTERP_IDLE, "program end", deadline - time.time())
time.sleep(0.3)
sampler.terminate()
sampler.wait(10)
s.poll()
if s.task_state != linuxcnc.STATE_ON:
    errors.append(f"machine left the on state (task_state {s.task_state})")
finish("done" if ok else "timeout")

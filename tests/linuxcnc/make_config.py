#!/usr/bin/env python3
"""Writes a headless LinuxCNC simulator configuration for a kerf.machine/1 file.

    make_config.py MACHINE.json OUTDIR [--display PROGRAM] [--tcp]

OUTDIR gets kerf.ini and kerf.hal: trivkins with the machine's axis letters (one joint per
axis, in file order X Y Z tilt C), every joint's limits, velocity (the file's per-minute values
divided by 60) and acceleration, immediate homing at 0 (or the travel's end nearest 0), a 1 ms servo thread, the joints' command
positions looped back as feedback, the laser power that follows the tip's speed (docs/process.md
"Power that follows the speed": the tip speed v = |XYZ' + (E2, E3, E4) tilt' + (E5, E6, E7) C'|
from `ddt` of the five joints' commanded positions, `mult2`, `sum2` and `hypot`, and
power = clamp(E0 v, E1, 100) with `mult2` and `limit1`, E<n> being motion.analog-out-<n>),
the beam: motion.digital-out-00 delayed by two servo periods (`timedelay`, `BEAM_DELAY_S`: the
joints' lag behind the trajectory in LinuxCNC's cubic interpolator), and a HAL `sampler`
recording the five joint positions, the beam and the power every servo cycle. Only numbers from the machine file reach the
INI; the machine's name is not written (it is free text).

With --tcp (programs of kerf's `linuxcnc-tcp` dialect) the kinematics are LinuxCNC's own
tool-tip module for the machine instead of trivkins (`tcp_kinematics` below: a table-table with
conventional false and tool_offset 0 is `xyzac-trt-kins`, a B fork head with tilt_sign -1 and
its pivot L above the joints' point is `5axiskins` with one more joint for its W coordinate,
left at 0; HAL pins set from the machine file), its TCP kinematics active (switchkins type 0); the [AXIS_*] sections then bound the
world (tool-tip, workpiece-frame) coordinates, the [JOINT_*] sections the machine axes as
before. The power's HAL is the same (the joints are the machine's either way; the program
writes the same coefficients). `motion.current-vel` was tried for the tip speed and measured
wrong: it is the planner's scalar path speed, which stays at the feed through a blend while the
tip slows (power/speed 13 % off on the dome), and it runs ahead of the joints.
"""
import json
import math
import sys
from pathlib import Path

SERVO_NS = 1_000_000
# LinuxCNC switches motion.digital-out-NN (M62-M65) on the trajectory's time, and its cubic
# interpolator runs the joints two servo periods behind the trajectory: the laser's enable is
# the output delayed by that much (timedelay), so that the beam switches where the axes are.
# Measured without it: micro-joint switches 2.0-3.0 servo cycles ahead of their places.
BEAM_DELAY_S = 2 * SERVO_NS * 1e-9
# Unlimited (continuous) rotary axes get a travel LinuxCNC accepts but no program reaches.
UNLIMITED = 1.0e6
# The tool tip's range in the workpiece frame under tool-tip kinematics (mm): no program of the
# shipped machines reaches it; the joints' own limits are what binds.
WORLD_RANGE = 1.0e4


def tcp_kinematics(kin):
    """The LinuxCNC module, its extra coordinates and the HAL pins that compute a kerf machine's
    kinematics, or exit naming why none does (the same rule as kerf's `linuxcnc_kinematics`,
    docs/linuxcnc.md)."""
    if kin["type"] == "fork-head":
        l = float(kin["L"])
        if (kin.get("tilt") != "B" or kin.get("tilt_sign") != -1 or [float(v) for v in kin["d"]] != [0.0, 0.0, l]
                or any(float(v) != 0.0 for v in kin["tool_lateral"]) or not math.isfinite(l)):
            sys.exit("--tcp: a fork-head for 5axiskins needs tilt B, tilt_sign -1, d [0, 0, L], tool_lateral [0, 0]")
        # 5axiskins needs a W coordinate (the tool's own axis): one more joint, left at 0.
        return "5axiskins", "W", {"pivot-length": l}
    if kin["type"] != "table-table":
        sys.exit(f"--tcp: kinematics.type {kin['type']}: only table-table (xyzac-trt-kins) and fork-head (5axiskins)")
    if kin.get("conventional"):
        sys.exit("--tcp: kinematics.conventional must be false for LinuxCNC 2.9's xyzac-trt-kins")
    if float(kin.get("tool_offset", 0.0)) != 0.0:
        sys.exit("--tcp: kinematics.tool_offset must be 0 for xyzac-trt-kins")
    rot = [float(v) for v in kin["rot_point"]]
    pins = {"x-rot-point": rot[0], "y-rot-point": rot[1], "z-rot-point": rot[2], "x-offset": 0.0,
            "y-offset": float(kin["y_offset"]), "z-offset": float(kin["z_offset"]), "tool-offset": 0.0}
    for k, v in pins.items():
        if not math.isfinite(v):
            sys.exit(f"--tcp: {k} must be finite")
    return "xyzac-trt-kins", "", pins


def main():
    args = sys.argv[1:]
    tcp = "--tcp" in args
    if tcp:
        args.remove("--tcp")
    display = "true"
    if "--display" in args:
        i = args.index("--display")
        display = args[i + 1]
        del args[i : i + 2]
    if len(args) != 2:
        sys.exit(__doc__)
    machine = json.loads(Path(args[0]).read_text())
    out = Path(args[1])
    out.mkdir(parents=True, exist_ok=True)
    kin = machine["kinematics"]
    tilt = "B" if kin.get("tilt") == "B" or kin["type"] == "head-table" else "A"
    letters = ["X", "Y", "Z", tilt, "C"]
    coords = "".join(letters)
    for name in letters:
        for key in ("max_velocity", "max_acceleration"):
            v = float(machine[key][name])
            if not (math.isfinite(v) and v > 0):
                sys.exit(f"{key}.{name}: must be finite and > 0")
    module, more, pins = tcp_kinematics(kin) if tcp else (None, "", {})
    if more:
        coords += more
    kins = f"{module} coordinates={coords}" if tcp else f"trivkins coordinates={coords} kinstype=both"
    vmax = max(float(machine["max_velocity"][n]) for n in letters[:3]) / 60.0
    rmax = max(float(machine["max_velocity"][n]) for n in letters[3:]) / 60.0
    ini = [
        "# Generated by tests/linuxcnc/make_config.py from a kerf.machine/1 file.",
        "[EMC]",
        "VERSION = 1.1",
        "MACHINE = kerf-sim",
        "DEBUG = 0",
        "[DISPLAY]",
        f"DISPLAY = {display}",
        "[TASK]",
        "TASK = milltask",
        "CYCLE_TIME = 0.001",
        "[RS274NGC]",
        "PARAMETER_FILE = sim.var",
        "[EMCMOT]",
        "EMCMOT = motmod",
        "COMM_TIMEOUT = 1.0",
        f"SERVO_PERIOD = {SERVO_NS}",
        "[EMCIO]",
        "EMCIO = io",
        "CYCLE_TIME = 0.100",
        "TOOL_TABLE = tool.tbl",
        "[HAL]",
        "HALFILE = kerf.hal",
        "[KINS]",
        f"KINEMATICS = {kins}",
        f"JOINTS = {len(coords)}",
        "[TRAJ]",
        f"COORDINATES = {coords}",
        "LINEAR_UNITS = mm",
        "ANGULAR_UNITS = degree",
        f"DEFAULT_LINEAR_VELOCITY = {vmax:.6f}",
        f"MAX_LINEAR_VELOCITY = {vmax:.6f}",
        f"DEFAULT_ANGULAR_VELOCITY = {rmax:.6f}",
        f"MAX_ANGULAR_VELOCITY = {rmax:.6f}",
        "POSITION_FILE = position.txt",
        "NO_FORCE_HOMING = 0",
    ]
    for j, name in enumerate(letters):
        lim = machine["limits"][name]
        lo, hi = (-UNLIMITED, UNLIMITED) if lim is None else (float(lim[0]), float(lim[1]))
        if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
            sys.exit(f"limits.{name}: [min, max] must be finite with min <= max")
        home = min(max(0.0, lo), hi)
        v = float(machine["max_velocity"][name]) / 60.0
        a = float(machine["max_acceleration"][name])
        common = [
            f"MAX_VELOCITY = {v:.6f}",
            f"MAX_ACCELERATION = {a:.6f}",
            f"MIN_LIMIT = {lo:.6f}",
            f"MAX_LIMIT = {hi:.6f}",
        ]
        # Under tool-tip kinematics the axes are the tip in the workpiece frame: given a wide
        # range (WORLD_RANGE), so that the joints' own limits are what binds.
        world = [f"MIN_LIMIT = {-WORLD_RANGE:.6f}", f"MAX_LIMIT = {WORLD_RANGE:.6f}"] if tcp and j < 3 else common[2:]
        ini += [f"[AXIS_{name}]"] + common[:2] + world
        ini += [f"[JOINT_{j}]", f"TYPE = {'LINEAR' if j < 3 else 'ANGULAR'}"] + common + [
            "FERROR = 1.0",
            "MIN_FERROR = 1.0",
            f"HOME = {home:.6f}",
            "HOME_OFFSET = 0.0",
            "HOME_SEARCH_VEL = 0.0",
            "HOME_LATCH_VEL = 0.0",
            "HOME_SEQUENCE = 0",
        ]
    if more == "W":
        # The W joint (5axiskins' tool axis coordinate): programs never move it.
        zv, za = float(machine["max_velocity"]["Z"]) / 60.0, float(machine["max_acceleration"]["Z"])
        w = [f"MAX_VELOCITY = {zv:.6f}", f"MAX_ACCELERATION = {za:.6f}", "MIN_LIMIT = -10.0", "MAX_LIMIT = 10.0"]
        ini += ["[AXIS_W]"] + w + ["[JOINT_5]", "TYPE = LINEAR"] + w + [
            "FERROR = 1.0", "MIN_FERROR = 1.0", "HOME = 0.0", "HOME_OFFSET = 0.0",
            "HOME_SEARCH_VEL = 0.0", "HOME_LATCH_VEL = 0.0", "HOME_SEQUENCE = 0"]
    (out / "kerf.ini").write_text("\n".join(ini) + "\n")
    hal = [
        "# Generated by tests/linuxcnc/make_config.py.",
        "loadrt [KINS]KINEMATICS",
        *[f"setp {module}.{k} {v!r}" for k, v in pins.items()],
        "loadrt [EMCMOT]EMCMOT servo_period_nsec=[EMCMOT]SERVO_PERIOD num_joints=[KINS]JOINTS num_dio=4 num_aio=8",
        "loadrt sampler depth=50000 cfg=fffffbf",
        "loadrt ddt count=5",
        "loadrt mult2 count=7",
        "loadrt sum2 count=6",
        "loadrt hypot count=1",
        "loadrt limit1 count=1",
        "loadrt timedelay count=1",
        "addf motion-command-handler servo-thread",
        "addf motion-controller servo-thread",
        *[f"addf ddt.{j} servo-thread" for j in range(5)],
        *[f"addf mult2.{j} servo-thread" for j in range(6)],
        *[f"addf sum2.{j} servo-thread" for j in range(6)],
        "addf hypot.0 servo-thread",
        "addf mult2.6 servo-thread",
        "addf limit1.0 servo-thread",
        "addf timedelay.0 servo-thread",
        "addf sampler.0 servo-thread",
    ]
    for j in range(5):
        hal.append(f"net j{j}pos joint.{j}.motor-pos-cmd => joint.{j}.motor-pos-fb sampler.0.pin.{j} ddt.{j}.in")
    if more == "W":
        hal.append("net j5pos joint.5.motor-pos-cmd => joint.5.motor-pos-fb")
    hal += [
        # The tip's speed: component i of XYZ' + (E2..E4) tilt' + (E5..E7) C' is
        # sum2.(3+i) = X_i' + sum2.i, sum2.i = mult2.i + mult2.(3+i), mult2.i = E(2+i) tilt',
        # mult2.(3+i) = E(5+i) C'; then the power: E0 x |that| (mult2.6), at least E1 (the
        # floor, or the pierce power while the head stands), at most 100.
        "net v3 ddt.3.out => " + " ".join(f"mult2.{i}.in1" for i in range(3)),
        "net v4 ddt.4.out => " + " ".join(f"mult2.{3 + i}.in1" for i in range(3)),
        *[f"net coef{i} motion.analog-out-{i + 2:02d} => mult2.{i}.in0" for i in range(6)],
        *[f"net rt{i} mult2.{i}.out => sum2.{i}.in0" for i in range(3)],
        *[f"net rc{i} mult2.{3 + i}.out => sum2.{i}.in1" for i in range(3)],
        *[f"net lin{i} ddt.{i}.out => sum2.{3 + i}.in0" for i in range(3)],
        *[f"net rot{i} sum2.{i}.out => sum2.{3 + i}.in1" for i in range(3)],
        *[f"net tip{i} sum2.{3 + i}.out => hypot.0.in{i}" for i in range(3)],
        "net tip-speed hypot.0.out => mult2.6.in1",
        "net power-scale motion.analog-out-00 => mult2.6.in0",
        "net power-raw mult2.6.out => limit1.0.in",
        "net power-floor motion.analog-out-01 => limit1.0.min",
        "setp limit1.0.max 100",
        "net power limit1.0.out => sampler.0.pin.6",
        "net beam-cmd motion.digital-out-00 => timedelay.0.in",
        f"setp timedelay.0.on-delay {BEAM_DELAY_S}",
        f"setp timedelay.0.off-delay {BEAM_DELAY_S}",
        "net beam timedelay.0.out => sampler.0.pin.5",
        "net estop-loop iocontrol.0.user-enable-out iocontrol.0.emc-enable-in",
        "net tool-prep-loop iocontrol.0.tool-prepare iocontrol.0.tool-prepared",
        "net tool-change-loop iocontrol.0.tool-change iocontrol.0.tool-changed",
    ]
    (out / "kerf.hal").write_text("\n".join(hal) + "\n")
    (out / "tool.tbl").write_text("T1 P1 ;laser\n")
    (out / "sim.var").write_text("")


if __name__ == "__main__":
    main()

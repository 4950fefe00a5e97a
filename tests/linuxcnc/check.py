#!/usr/bin/python3
"""kerf's programs on a real controller: LinuxCNC's interpreter and simulator.

    /usr/bin/python3 tests/linuxcnc/check.py [--out DIR] [--no-sim] [--sim NAME ...]

1. Every shipped fixture on every machine file whose travel holds it (`kerf run` succeeds):
   the `linuxcnc` program (and the `generic` one on the first such machine) through LinuxCNC's standalone interpreter
   `rs274` with an INI made from that machine; any message on its error stream (errors and
   warnings alike) fails the check.
2. The simulator runs (`SIMS` below: a flat part and a tilted-head part, and `simulate_kerf`: the
   flat part with LinuxCNC's own kerf compensation against kerf's; `simulate_head`: the head
   model swept along the executed samples of a part cut beside a wall, and its negative
   control; `simulate_tcp`: tool-tip
   programs on LinuxCNC's own `xyzac-trt-kins` and `5axiskins` beside their joint-space twins,
   and a negative control per module that must fail): a headless LinuxCNC
   (configuration from `make_config.py`, DISPLAY = `display.py`, run by an unprivileged user)
   executes the program while `halsampler` records the joints and the beam output every servo
   cycle; `lcnc_measure` (Rust, kerf's forward kinematics) measures the samples; the asserts are
   below. Figures go to DIR/summary.json.

Exit status 0 when every assertion holds, 1 otherwise (also when LinuxCNC is not installed).
Python only drives LinuxCNC and compares numbers; the tip comes from kerf's kinematics.
"""
import json
import os
import pwd
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
MACHINES = ["ac_head", "gantry_ac", "fork_head", "table_table", "head_table", "xyzac_trt",
            "bc_head_5axiskins"]
# Issue 30: the machines whose tool-tip programs (`linuxcnc-tcp`) LinuxCNC runs with its own
# kinematics module (docs/linuxcnc.md, "Tool-tip programs").
TCP_MACHINES = ["xyzac_trt", "bc_head_5axiskins"]
# (fixture, machine, flat, more `kerf run` arguments, cuts to run or None for all): the flat
# part must run within 10 % of kerf's predicted time. The real propeller (placed by `--place
# auto`, blade edges at up to 112 degrees of tilt) runs its first cuts only: all 47 take LinuxCNC
# about 4 minutes.
# The flat part and the saddle cut with a technology (issue 29: power that follows the tip's
# speed; on the flat part its 10 mm holes fall under the small-hole rule of the 3 mm entry).
TECH_FLAT = ("--technology", "@TECH", "--material", "mild steel", "--thickness", "3")
TECH_TILTED = ("--technology", "@TECH", "--material", "stainless", "--thickness", "2")
# Micro-joints (issue 29): the beam off over each, every switch within MAX_JOINT_SWITCH_MM of
# its planned place along the path.
JOINTS = ("--micro-joints", "0.5,40")
MAX_JOINT_SWITCH_MM = 0.1

SIMS = [
    ("sheet_metal_holes", "gantry_ac", True, (*TECH_FLAT, *JOINTS), None),
    ("tube_saddle", "ac_head", False, (*TECH_TILTED, *JOINTS), None),
    # The head check off: the blade edges by the hub meet the head (refused by default).
    ("realdata/occt_propeller", "gantry_ac", False, ("--place", "auto", "--cut-clearance", "off"), 12),
    # Issue 26's domed panel: a 1 m trim line whose normal passes within 0.5-5 deg of vertical,
    # so the A/C head runs near its pole (C held within a 1-degree tilt cone).
    ("trim_panel", "ac_head", False, ("--place", "auto", "--tilt-tolerance", "1", *TECH_TILTED), None),
]
# Sims whose tool-axis stray from the poses and tip overspeed in LinuxCNC's blends are reported,
# not asserted (docs/linuxcnc.md, "Not done": near the pole LinuxCNC's joint-space blends over
# short moves with fast C overspeed the tip by ~20 % and stray up to 0.67 deg); the tip against
# the budget, the limits, the framing and the beam are asserted as for every sim.
NOTED_ONLY = {"trim_panel",
              # The hole beside the wall, tilted 2.4 degrees to clear it: the A/C head within a
              # few degrees of its pole, C swinging; LinuxCNC's blends stray 1.19 degrees from
              # the poses' axes there (2026-12-05). The head's clearance is measured along the
              # executed samples, stray included (`simulate_head`).
              "head_wall"}
# The real files, placed automatically on the gantry: every set-up's program through rs274.
REAL = ["nori_sheetmetal", "occt_propeller"]
USER = "kerfsim"
# The largest tool-axis stray from the poses' axes a simulation may show while the beam cuts.
MAX_AXIS_STRAY_DEG = 0.35
# Issue 29: the commanded power over the tip's speed within this share of its cut value.
MAX_POWER_RATIO_ERROR = 0.05
failures = []
# While a negative control runs, its failures are collected here instead (it must fail).
collecting = None


def fail(msg):
    if collecting is not None:
        print("expected:", msg, flush=True)
        collecting.append(msg)
        return
    print("FAIL:", msg, flush=True)
    failures.append(msg)


def run(cmd, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, **kw)


def machine_file(machine):
    """A shipped machine by name, or a machine file's path as given."""
    return machine if isinstance(machine, Path) else ROOT / "fixtures" / "machines" / f"{machine}.json"


def technology(outdir):
    """The shipped example table without its kerf widths: the sims measure the tip against
    the designed curve, which a kerf offset would move by half the kerf on purpose (the kerf is
    `simulate_kerf`'s subject)."""
    table = json.loads((ROOT / "fixtures" / "technology" / "fiber_3kw_example.json").read_text())
    for e in table["entries"]:
        e.pop("kerf_width_mm", None)
    path = outdir / "technology-no-kerf.json"
    path.write_text(json.dumps(table))
    return path


def kerf_run(kerf, fixture, machine, dialect, out, extra=()):
    r = run([str(kerf), "run", str(ROOT / "fixtures" / f"{fixture}.json"), "-m",
             str(machine_file(machine)), "--dialect", dialect,
             "-o", str(out), "-q", *extra])
    return r


def config(machine, out, display="true", tcp=False):
    r = run([sys.executable, str(HERE / "make_config.py"),
             str(machine_file(machine)), str(out), "--display", display, *(["--tcp"] if tcp else [])])
    if r.returncode != 0:
        raise SystemExit(f"make_config {machine}: {r.stderr}")


def rs274(cfg, program):
    """Parses `program` with rs274; returns the error-stream lines other than 'executing'."""
    r = run(["rs274", "-i", "kerf.ini", "-n", "0", "-g", str(program), "canon.txt"],
            cwd=cfg, stdin=subprocess.DEVNULL, timeout=120)
    lines = [l for l in (r.stderr + r.stdout).splitlines() if l.strip() and l.strip() != "executing"]
    if r.returncode != 0:
        lines.append(f"rs274 exit status {r.returncode}")
    canon = (Path(cfg) / "canon.txt").read_text() if (Path(cfg) / "canon.txt").exists() else ""
    if "PROGRAM_END()" not in canon:
        lines.append("rs274 did not reach the program end")
    return lines


def ensure_user():
    if os.geteuid() != 0:
        return None
    try:
        pwd.getpwnam(USER)
    except KeyError:
        subprocess.run(["useradd", "-m", "-s", "/bin/sh", USER], check=True)
    return USER


def first_cuts(text, cuts, beam_on="M64 P0", beam_off="M65 P0"):
    """The program cut short after its `cuts`-th cut (the beam-off line after its beam-on; the
    preamble switches the beam off once before any cut), then ended."""
    out, seen, on = [], 0, False
    for line in text.splitlines():
        out.append(line)
        if line.strip() == beam_on:
            on = True
        elif line.strip() == beam_off and on:
            on = False
            seen += 1
            if seen == cuts:
                break
    return "\n".join(out + ["M2", ""])


def simulate(kerf, measure, fixture, machine, flat, outdir, tag="", extra=(), traj=(), edit=None,
             cuts=None, measure_env=None, compare=False, synchronized=False, dialect="linuxcnc",
             kerf_machine=None):
    """One simulator run; `extra` are more `kerf run` arguments, `traj` more [TRAJ] lines of
    the INI, `edit` a function applied to the program text (for the experiments), `cuts` the
    number of cuts to run (a long real part cut short; all when None). With `compare` the
    program leaves the kerf to the controller: its tip runs half a kerf off its own poses and
    the curve by design, so those asserts give way to `kerf_compare` (`simulate_kerf`), and the
    beam's framing is checked by its count only; `measure_env` goes to `lcnc_measure`. With
    `synchronized` the machine's beam codes are M62/M63 (they act when the next move starts;
    kerf lights the pierce with the immediate M64, so the framing holds as for M64/M65): the
    tip's asserts are left to the other runs. `dialect` is kerf's (`linuxcnc-tcp`: the
    configuration runs LinuxCNC's own tool-tip kinematics for `machine`); `kerf_machine` is the
    machine file kerf plans with and measures by (the negative control: a parameter off), the
    configuration being `machine`'s."""
    if cuts is not None:
        edit = lambda text, e=edit: first_cuts(e(text) if e else text, cuts)
    extra_in = extra
    fixture_tag = fixture.replace("/", "-") + tag
    work = Path(tempfile.mkdtemp(prefix=f"kerf-sim-{fixture_tag}-"))
    os.chmod(work, 0o777)
    kout = outdir / f"sim-{fixture_tag}"
    extra = tuple(str(technology(outdir)) if a == "@TECH" else a for a in extra)
    kerf_machine = kerf_machine or machine
    r = kerf_run(kerf, fixture, kerf_machine, dialect, kout, extra)
    if r.returncode != 0:
        fail(f"sim {fixture}: kerf run: {r.stderr.strip()}")
        return None
    shutil.copy(HERE / "display.py", work / "display.py")
    os.chmod(work / "display.py", 0o755)
    config(machine, work, display=str(work / "display.py"), tcp=dialect == "linuxcnc-tcp")
    if traj:
        ini = (work / "kerf.ini").read_text().replace("[TRAJ]\n", "[TRAJ]\n" + "".join(t + "\n" for t in traj))
        (work / "kerf.ini").write_text(ini)
    text = (kout / "program.nc").read_text()
    (work / "program.ngc").write_text(edit(text) if edit else text)
    user = ensure_user()
    env = {"KERF_PROGRAM": str(work / "program.ngc"), "KERF_SAMPLES": str(work / "samples.txt"),
           "KERF_RESULT": str(work / "result.json"), "KERF_TIMEOUT": "240"}
    cmd = ["env", *[f"{k}={v}" for k, v in env.items()], "linuxcnc", "kerf.ini"]
    if user:
        for p in work.iterdir():
            shutil.chown(p, user)
        shutil.chown(work, user)
        cmd = ["runuser", "-u", user, "--", *cmd]
    t0 = time.time()
    try:
        p = run(cmd, cwd=work, timeout=300)
        log = p.stdout + p.stderr
    except subprocess.TimeoutExpired as e:
        log = f"timeout: {e}"
    (outdir / f"sim-{fixture_tag}.log").write_text(log)
    wall = time.time() - t0
    res_path = work / "result.json"
    if not res_path.exists():
        fail(f"sim {fixture_tag}: LinuxCNC gave no result (log in {outdir}/sim-{fixture_tag}.log)")
        return None
    res = json.loads(res_path.read_text())
    shutil.copy(work / "samples.txt", outdir / f"sim-{fixture_tag}-samples.txt")
    m = run([str(measure), str(machine_file(kerf_machine)), str(kout),
             str(work / "samples.txt"), "0.001", *([str(cuts)] if cuts is not None else [])],
            env={**os.environ, **(measure_env or {})})
    if m.returncode != 0:
        fail(f"sim {fixture}: lcnc_measure: {m.stderr.strip()}")
        return None
    fig = json.loads(m.stdout)
    fig.update({"fixture": fixture, "machine": str(machine), "linuxcnc_errors": res["errors"],
                "linuxcnc_end": res["code"], "wall_s": wall})
    fig["variant"] = tag
    fig["dialect"] = dialect
    name = f"sim {fixture_tag} on {Path(str(machine)).stem} ({dialect})"

    if res["errors"] or res["code"] != "done":
        fail(f"{name}: LinuxCNC errors {res['errors']}, end {res['code']}")
    if fig["sample_gaps"]:
        fail(f"{name}: {fig['sample_gaps']} gaps in the samples (sampler overrun)")
    if (not fig["framing_ok"] and not compare) or fig["beam_intervals"] != fig["cuts"]:
        fail(f"{name}: beam on {fig['beam_intervals']} times for {fig['cuts']} cuts, framing ok {fig['framing_ok']}")
    # A laser left on after the program is a safety defect, whatever codes switch it.
    if fig["beam_on_at_end"]:
        fail(f"{name}: the beam is still on after the program ended")
    if compare or synchronized:
        if synchronized:
            print(f"{name}: beam {fig['beam_intervals']}/{fig['cuts']} cuts, on at the end: {fig['beam_on_at_end']}", flush=True)
        shutil.rmtree(work, ignore_errors=True)
        return fig
    if not fig["max_deviation_beam_on_mm"] <= fig["tolerance_budget_mm"]:
        fail(f"{name}: tip deviation {fig['max_deviation_beam_on_mm']} mm > budget {fig['tolerance_budget_mm']} mm")
    # End to end: the tip against the designed NURBS curve itself (closest point), wherever the
    # beam cuts the contour rather than a lead: the figure the budget is a claim about.
    if fig.get("max_deviation_from_curve_mm") is None:
        fail(f"{name}: the tip was not measured against the designed curves")
    elif not fig["max_deviation_from_curve_mm"] <= fig["tolerance_budget_mm"]:
        fail(f"{name}: tip {fig['max_deviation_from_curve_mm']} mm from the designed curve > budget {fig['tolerance_budget_mm']} mm")
    if fig["limit_violations"]:
        fail(f"{name}: {fig['limit_violations']} samples outside the axis limits")
    # The tool axis against the poses' axes (interpolated at the nearest point of the nearest
    # block) wherever the beam cuts the contour: what the blends leave. Measured 2026-12-03:
    # 0.007 deg on the saddle, 0.27 deg on the propeller's first 12 cuts; an overcut whose end
    # took the next cutting point's axis showed as 0.54 deg on both.
    strict = fixture.split("/")[-1] not in NOTED_ONLY
    if not fig["max_tool_axis_deviation_deg"] <= MAX_AXIS_STRAY_DEG and strict:
        fail(f"{name}: tool axis {fig['max_tool_axis_deviation_deg']:.3f} deg off the poses' > {MAX_AXIS_STRAY_DEG}")
    # 1e-6 mm of sample rounding over 1 ms^2 is 1 mm/s^2: 1 % slack on the limits. Under
    # tool-tip kinematics LinuxCNC 2.9 bounds the tip's world axes, not the joints
    # (docs/linuxcnc.md, "Tool-tip programs"): the joints' figures are reported there.
    over = [f"rapid acceleration of {k} at {v:.3f} x its limit"
            for k, v in fig["max_acceleration_ratio_rapids"].items() if v > 1.01]
    over += [f"velocity of {k} at {v:.3f} x its limit"
             for k, v in fig["max_velocity_ratio"].items() if v > 1.01]
    for o in over:
        if dialect == "linuxcnc-tcp":
            print(f"{name}: {o} (the controller plans the tip, not the joints: reported)", flush=True)
        else:
            fail(f"{name}: {o}")
    if fig["max_tip_speed_beam_on_mm_per_min"] > 1.01 * fig["feed_mm_per_min"] and strict:
        fail(f"{name}: tip at {fig['max_tip_speed_beam_on_mm_per_min']:.0f} mm/min, feed {fig['feed_mm_per_min']}")
    pw = fig.get("power")
    if "@TECH" in extra_in:
        if not pw or pw["samples_checked"] < 1000:
            fail(f"{name}: the power was not measured ({pw and pw['samples_checked']} samples above the floor)")
        elif not pw["max_ratio_error"] <= MAX_POWER_RATIO_ERROR:
            fail(f"{name}: power / tip speed {pw['max_ratio_error']:.4f} off its cut value > {MAX_POWER_RATIO_ERROR} (at {pw['worst']})")
        else:
            print(f"{name}: power follows the tip speed within {pw['max_ratio_error']:.4f} over {pw['samples_checked']} samples "
                  f"({pw['samples_at_floor']} at the floor)", flush=True)
        # Small holes run at their factor: the executed tip reaches the hole's share of the feed
        # and never passes it (the power's own factor is in the ratio above).
        if pw:
            cap = pw["reference_feed_mm_per_min"] * pw["small_hole_feed_factor"]
            for c in (c for c in pw["per_cut"] if c["small_hole"]):
                if not 0.9 * cap <= c["peak_tip_speed_mm_per_min"] <= 1.01 * cap:
                    fail(f"{name}: small hole {c['id']} peaks at {c['peak_tip_speed_mm_per_min']:.0f} mm/min, its feed {cap:.0f}")
            holes = [c["id"] for c in pw["per_cut"] if c["small_hole"]]
            if holes:
                print(f"{name}: small holes {', '.join(holes)} at their feed {cap:.0f} mm/min", flush=True)
    if "--micro-joints" in extra_in:
        mj = fig.get("micro_joints") or {}
        if not mj.get("grouped") or not mj.get("planned"):
            fail(f"{name}: micro-joints not framed: {mj} ({fig['beam_intervals']} beam intervals)")
        elif not (mj["max_switch_distance_mm"] <= MAX_JOINT_SWITCH_MM
                  and mj["max_dark_length_error_mm"] <= 2 * MAX_JOINT_SWITCH_MM):
            fail(f"{name}: micro-joint switches {mj['max_switch_distance_mm']:.4f} mm from their places "
                 f"(limit {MAX_JOINT_SWITCH_MM}), dark length off by {mj['max_dark_length_error_mm']:.4f} mm")
        else:
            print(f"{name}: {mj['planned']} micro-joints, every switch within {mj['max_switch_distance_mm']:.4f} mm "
                  f"of its place, dark length within {mj['max_dark_length_error_mm']:.4f} mm", flush=True)
    if flat and not 0.9 <= fig["time_ratio"] <= 1.1:
        fail(f"{name}: time LinuxCNC / kerf {fig['time_ratio']:.3f} outside [0.9, 1.1]")
    print(f"{name}: deviation {fig['max_deviation_beam_on_mm']:.5f} mm from the poses, "
          f"tool axis {fig['max_tool_axis_deviation_deg']:.4f} deg, "
          f"{fig.get('max_deviation_from_curve_mm') or float('nan'):.5f} mm from the curve (budget {fig['tolerance_budget_mm']}), "
          f"beam {fig['beam_intervals']}/{fig['cuts']} cuts framed {fig['framing_ok']}, "
          f"time {fig['linuxcnc_time_s']:.3f} s / kerf {fig['kerf_predicted_s']:.3f} s = {fig['time_ratio']:.3f}, "
          f"tip speed max {fig['max_tip_speed_beam_on_mm_per_min']:.0f} mm/min, wall {wall:.1f} s", flush=True)
    shutil.rmtree(work, ignore_errors=True)
    return fig


# The controller's kerf compensation (issue 27): the flat part with a 0.2 mm kerf, once offset
# by kerf (`--kerf-width`) and once left to LinuxCNC's G41.1/G42.1 (`--kerf-in-control`), both
# with a 0.5 um blending tolerance; where LinuxCNC's executed tip runs on the compensated
# contour it must lie within KERF_AGREEMENT_MM of kerf's own offset path.
KERF_AGREEMENT_MM = 0.002


def simulate_kerf(kerf, measure, outdir):
    args = ("--kerf-width", "0.2", "--blend-tolerance", "0.0005", "--tolerance", "0.001")
    ref = outdir / "kerf-in-computer"
    r = kerf_run(kerf, "sheet_metal_holes", "gantry_ac", "linuxcnc", ref, args)
    if r.returncode != 0:
        fail(f"kerf in the computer: kerf run: {r.stderr.strip()}")
        return None
    fig = simulate(kerf, measure, "sheet_metal_holes", "gantry_ac", True, outdir,
                   tag="-kerf-in-control", extra=(*args, "--kerf-in-control"),
                   measure_env={"KERF_COMPARE_DIR": str(ref), "KERF_COMPARE_OFFSET_MM": "0.1"},
                   compare=True)
    if not fig:
        return None
    c = fig.get("kerf_compare") or {}
    name = "sim sheet_metal_holes with G41.1/G42.1"
    if c.get("samples_on_the_offset", 0) < 0.6 * max(c.get("beam_on_samples", 0), 1):
        fail(f"{name}: only {c.get('samples_on_the_offset')} of {c.get('beam_on_samples')} beam-on samples run half a kerf from the contour: the controller did not compensate")
    elif not c["max_distance_to_computer_offset_mm"] <= KERF_AGREEMENT_MM:
        fail(f"{name}: LinuxCNC's tip {c['max_distance_to_computer_offset_mm']:.5f} mm from kerf's offset > {KERF_AGREEMENT_MM}")
    print(f"{name}: {c.get('samples_on_the_offset')}/{c.get('beam_on_samples')} beam-on samples on the offset, "
          f"at most {c.get('max_distance_to_computer_offset_mm', float('nan')):.5f} mm from kerf's own offset path "
          f"(limit {KERF_AGREEMENT_MM}), time {fig['linuxcnc_time_s']:.3f} s", flush=True)
    return fig


# Issue 30: tool-tip programs executed by LinuxCNC's own tool-tip kinematics (xyzac-trt-kins
# and 5axiskins, implementations of the machines' inverse kinematics independent of kerf's): the joints it
# computes go through kerf's *forward* kinematics in lcnc_measure and must put the tip on kerf's
# path within the budget. Each fixture runs twice, as a joint-space program (trivkins) and as
# a tool-tip program, for LinuxCNC's time against kerf's plan side by side.
TCP_SIMS = [
    ("dome", "xyzac_trt", TECH_TILTED),
    ("trim_panel", "xyzac_trt", ("--place", "auto", "--tilt-tolerance", "1")),
    ("tube_saddle", "bc_head_5axiskins", TECH_TILTED),
]
# The negative controls: kerf's machine file with a pivot offset this much (mm) off the
# controller's. The table: the A axis farther above the C table; kerf's tip from LinuxCNC's
# joints then leaves the path by 2 sin(A/2) of it (A 26-53 degrees on the dome: 0.045-0.089 mm,
# above its 0.021 mm budget). The head: a longer pivot (L and d together), off by up to
# 2 sin(B/2) of it (B to 90 degrees on the saddle: 0.14 mm).
WRONG_PIVOT_MM = 0.1


def longer_table_pivot(kin):
    kin["z_offset"] += WRONG_PIVOT_MM


def longer_head_pivot(kin):
    kin["L"] += WRONG_PIVOT_MM
    kin["d"][2] += WRONG_PIVOT_MM


NEGATIVE_CONTROLS = [
    ("dome", "xyzac_trt", TECH_TILTED, longer_table_pivot, "z_offset"),
    ("tube_saddle", "bc_head_5axiskins", TECH_TILTED, longer_head_pivot, "pivot L"),
]


def simulate_tcp(kerf, measure, outdir):
    global collecting
    figs = []
    for fixture, machine, extra in TCP_SIMS:
        joint = simulate(kerf, measure, fixture, machine, False, outdir, tag="-joints", extra=extra)
        tcp = simulate(kerf, measure, fixture, machine, False, outdir, tag="-tcp", extra=extra,
                       dialect="linuxcnc-tcp")
        if joint and tcp:
            print(f"sim {fixture} on {machine}: LinuxCNC's time / kerf's plan {tcp['time_ratio']:.3f} "
                  f"as a tool-tip program, {joint['time_ratio']:.3f} in joint space", flush=True)
        figs += [f for f in (joint, tcp) if f]
    for fixture, machine, extra, edit, what in NEGATIVE_CONTROLS:
        m = json.loads(machine_file(machine).read_text())
        edit(m["kinematics"])
        wrong = outdir / f"{machine}-pivot-{WRONG_PIVOT_MM}-off.json"
        wrong.write_text(json.dumps(m))
        collecting = []
        try:
            fig = simulate(kerf, measure, fixture, machine, False, outdir, tag="-tcp-wrong-pivot",
                           extra=extra, dialect="linuxcnc-tcp", kerf_machine=wrong)
        finally:
            caught, collecting = collecting, None
        name = f"negative control: {fixture} on {machine} with kerf's {what} {WRONG_PIVOT_MM} mm off the controller's"
        tip = [c for c in caught if "tip deviation" in c or "from the designed curve" in c]
        if not tip:
            fail(f"{name}: the tool-tip check did not notice ({caught})")
        else:
            print(f"{name}: the check fails as it must ({len(caught)} assertion(s): {tip[0]})", flush=True)
        if fig:
            fig["expected_failures"] = caught
            figs.append(fig)
    return figs


# Issue 28: the head against the part as LinuxCNC runs the program (`head_wall`: a hole 47 mm
# from a wall's foot, the 90 mm body 2 mm from the wall upright): cut at a 3 mm cutting
# clearance with a 10-degree tilt tolerance, the head model swept along every executed sample
# (cuts and traverses) keeps the clearance less the check's resolution (0.5 mm), half its sample
# step and the tolerance budget from the exact floor and wall (`lcnc_measure`'s
# `head_clearance`); the same part cut upright with the collision accepted must fail it (the
# negative control: the measure sees the head 2 mm from the wall).
HEAD_CLEARANCE_MM = 3.0
HEAD_SLACK_MM = 0.5 + 0.25


def simulate_head(kerf, measure, outdir):
    figs = []
    runs = [("-head-tilted", ("--tilt-tolerance", "10"), False),
            ("-head-upright-accepted", ("--accept-head-collisions",), True)]
    for tag, more, negative in runs:
        extra = ("--cut-clearance", str(HEAD_CLEARANCE_MM), *more)
        fig = simulate(kerf, measure, "head_wall", "gantry_ac", False, outdir, tag=tag, extra=extra,
                       measure_env={"KERF_HEAD_CHECK": "1"})
        if not fig:
            continue
        figs.append(fig)
        h = fig.get("head_clearance") or {}
        d = h.get("min_distance_mm")
        name = f"sim head_wall{tag} on gantry_ac"
        need = HEAD_CLEARANCE_MM - HEAD_SLACK_MM - fig["tolerance_budget_mm"]
        if d is None:
            fail(f"{name}: the head was not measured")
            continue
        where = (f"{d:.3f} mm from {h.get('surface')} at sample {h.get('sample')} "
                 f"(beam {'on' if h.get('beam_on') else 'off'}), {h.get('samples_checked')} samples "
                 f"x {h.get('points_per_sample')} head points above the {h.get('tip_zone_mm'):.2f} mm tip zone")
        if negative:
            if h.get("surface") != "wall":
                fail(f"negative control {name}: the nearest surface is not the wall ({where})")
            elif d >= need:
                fail(f"negative control {name}: the head measure did not notice the upright head ({where})")
            else:
                print(f"negative control {name}: the upright head measured {where}, under {need:.3f} mm as it must", flush=True)
        elif d < need:
            fail(f"{name}: the head comes {where} < {need:.3f} mm")
        else:
            print(f"{name}: the head keeps {where} >= {need:.3f} mm", flush=True)
    return figs


def simulate_synchronized(kerf, measure, outdir):
    """The flat part on a gantry whose `process` names the beam codes synchronized with motion
    (`M62 P0` / `M63 P0`, what a LinuxCNC laser configuration uses): the beam must be off when
    the program has ended (issue 29: a last `M63` with no move after it never fired), and every
    pierce lit for its dwell (the pierce's beam-on written as the immediate `M64`)."""
    machine = json.loads((ROOT / "fixtures" / "machines" / "gantry_ac.json").read_text())
    machine.setdefault("process", {}).update({"beam_on": ["M62 P0"], "beam_off": ["M63 P0"]})
    path = outdir / "gantry_ac-m62.json"
    path.write_text(json.dumps(machine))
    return simulate(kerf, measure, "sheet_metal_holes", path, True, outdir, tag="-m62",
                    synchronized=True)


def main():
    args = sys.argv[1:]
    # Absolute: rs274 and the simulator run in the configuration directory.
    outdir = (Path(args[args.index("--out") + 1]) if "--out" in args else Path(tempfile.mkdtemp(prefix="kerf-lcnc-"))).resolve()
    outdir.mkdir(parents=True, exist_ok=True)
    sims = SIMS
    if "--sim" in args:
        names = args[args.index("--sim") + 1:]
        sims = [s for s in SIMS if s[0] in names or s[0].split("/")[-1] in names]
    for tool in ("rs274", "linuxcnc", "halsampler"):
        if shutil.which(tool) is None:
            print(f"FAIL: {tool} not found: install LinuxCNC (apt-get install linuxcnc-uspace)")
            return 1
    t0 = time.time()
    b = run(["cargo", "build", "--release", "-p", "kerf-cli", "--bin", "kerf", "--example", "lcnc_measure"], cwd=ROOT)
    if b.returncode != 0:
        print(b.stderr)
        return 1
    kerf = ROOT / "target" / "release" / "kerf"
    measure = ROOT / "target" / "release" / "examples" / "lcnc_measure"
    # 1. The interpreter on every fixture and machine.
    cfgs = {}
    for m in MACHINES:
        cfgs[m] = outdir / f"ini-{m}"
        config(m, cfgs[m])
    parsed = []
    fixtures = sorted(p.stem for p in (ROOT / "fixtures").glob("*.json"))
    for f in fixtures:
        ran = []
        for m in MACHINES:
            # The generic program too, on the first machine that holds the fixture; the tool-tip
            # program where LinuxCNC has the machine's kinematics.
            dialects = ("linuxcnc", "generic") if not ran else ("linuxcnc",)
            for dialect in dialects + (("linuxcnc-tcp",) if m in TCP_MACHINES else ()):
                out = outdir / f"{f}-{m}-{dialect}"
                r = kerf_run(kerf, f, m, dialect, out)
                if r.returncode != 0 and "the head comes too close" in r.stderr:
                    # `mixed`, `trim_creases` and the upright head fixtures meet the head as
                    # drawn (refused by default): their programs' blocks with the check off.
                    r = kerf_run(kerf, f, m, dialect, out, ("--cut-clearance", "off"))
                if r.returncode != 0:
                    continue  # outside this machine's travel: kerf refuses, nothing to parse
                ran.append(m)
                msgs = rs274(cfgs[m], out / "program.nc")
                if msgs:
                    fail(f"rs274 {f} on {m} ({dialect}): {msgs[:5]}")
                parsed.append({"fixture": f, "machine": m, "dialect": dialect, "ok": not msgs})
                shutil.rmtree(out, ignore_errors=True)
        if not ran:
            fail(f"{f}: no machine file holds it, nothing parsed")
    for f in REAL:
        out = outdir / f"real-{f}"
        # Bend and blade edges, which the head meets (refused by default): the head check off.
        r = kerf_run(kerf, f"realdata/{f}", "gantry_ac", "linuxcnc", out,
                     ("--place", "auto", "--cut-clearance", "off"))
        if r.returncode != 0:
            fail(f"{f}: kerf run --place auto: {r.stderr.strip()[:300]}")
            continue
        programs = sorted(out.glob("program*.nc"))
        if not programs:
            fail(f"{f}: no program written")
        for prog in programs:
            msgs = rs274(cfgs["gantry_ac"], prog)
            if msgs:
                fail(f"rs274 {f} {prog.name} on gantry_ac: {msgs[:5]}")
            parsed.append({"fixture": f"realdata/{f}/{prog.name}", "machine": "gantry_ac",
                           "dialect": "linuxcnc", "ok": not msgs})
        shutil.rmtree(out, ignore_errors=True)
    print(f"rs274: {sum(p['ok'] for p in parsed)}/{len(parsed)} programs parse without error or warning "
          f"({len(fixtures)} fixtures, {len(REAL)} real parts)", flush=True)
    # 2. The simulator.
    figs = []
    if "--no-sim" not in args:
        for f, m, flat, extra, cuts in sims:
            fig = simulate(kerf, measure, f, m, flat, outdir, extra=extra, cuts=cuts)
            if fig:
                figs.append(fig)
        if "--sim" not in args or "synchronized" in args[args.index("--sim") + 1:]:
            fig = simulate_synchronized(kerf, measure, outdir)
            if fig:
                figs.append(fig)
        if "--sim" not in args or "tcp" in args[args.index("--sim") + 1:]:
            figs += simulate_tcp(kerf, measure, outdir)
        if "--sim" not in args or "kerf" in args[args.index("--sim") + 1:]:
            fig = simulate_kerf(kerf, measure, outdir)
            if fig:
                figs.append(fig)
        if "--sim" not in args or "head" in args[args.index("--sim") + 1:]:
            figs += simulate_head(kerf, measure, outdir)
    summary = {"linuxcnc": run(["dpkg-query", "-W", "-f", "${Version}", "linuxcnc-uspace"]).stdout,
               "parsed": parsed, "simulations": figs, "failures": failures,
               "seconds": time.time() - t0}
    (outdir / "summary.json").write_text(json.dumps(summary, indent=2))
    print(f"figures in {outdir}/summary.json; {len(failures)} failure(s); {time.time() - t0:.0f} s")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

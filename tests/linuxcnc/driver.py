#!/usr/bin/python3
"""Headless LinuxCNC "display" of cnccomp's oracle tests (tests/linuxcnc/test_linuxcnc_sim.cpp).

LinuxCNC starts it as `driver.py -ini <ini>`; the run ends when it exits. It turns the machine on, homes every joint
and then works through the job file ($CNCCOMP_JOB), one command per line:
    mdi <G-code>     one MDI block; waits until the interpreter is idle and motion is in position (a "G0 <words>"
                     block also until the commanded position has reached its words)
    record <label>   waits until every joint's comp filter has reached its target (backlash-filt == backlash-corr,
                     at most 1 s) and the joints' pos-cmd pins hold still (two reads 20 ms apart agree, at most
                     2 s) and writes one line to $CNCCOMP_OUT:
                     <label> <settled 0|1> <motion.tooloffset.z> then, per joint, joint.N.pos-cmd, then
                     joint.N.motor-pos-cmd, joint.N.backlash-corr, joint.N.backlash-filt (repr, full precision), then
                     the 9 values of stat.g5x_offset (the active work offset)
    auto <file>      runs the program in AUTO to its end (then back to MDI)
    sample <file>    the same with the HAL sampler (sampler.0, enabled only while the program runs) read by halsampler
                     into $CNCCOMP_OUT.samples: one line per servo cycle, "<cycle> <value> ..." (halsampler -t, %f)
    setp <name> <value>
                     sets a HAL pin or parameter (hal.set_p, as halcmd setp), between programs
    setp <name> <value>
                     sets a HAL pin or parameter (hal.set_p, as halcmd setp), between programs
The output is written to $CNCCOMP_OUT.part and renamed when the whole job is done, so an output file means success.
Any LinuxCNC error (error channel) or timeout ends the run with exit code 1 and the reason on stderr.
Needs /usr/bin/python3 (the linuxcnc and hal modules of the Debian package live in the system dist-packages).
"""
import os
import re
import signal
import subprocess
import sys
import time

import hal
import linuxcnc

INI = linuxcnc.ini(sys.argv[sys.argv.index("-ini") + 1])
JOINTS = int(INI.find("KINS", "JOINTS"))
JOB = [line.rstrip("\n") for line in open(os.environ["CNCCOMP_JOB"])]
OUT = os.environ["CNCCOMP_OUT"]

stat, command, errors = linuxcnc.stat(), linuxcnc.command(), linuxcnc.error_channel()
comp = hal.component("cnccomp-driver")
comp.ready()


def check_errors(context):
    while True:
        err = errors.poll()
        if not err:
            return
        kind, text = err
        if kind in (linuxcnc.NML_ERROR, linuxcnc.OPERATOR_ERROR):
            raise RuntimeError("LinuxCNC error during %s: %s" % (context, text))
        sys.stderr.write("LinuxCNC message during %s: %s\n" % (context, text))


def wait(predicate, timeout, what):
    start = time.time()
    while time.time() - start < timeout:
        stat.poll()
        if predicate():
            return
        check_errors(what)
        time.sleep(0.002)
    raise RuntimeError("timeout waiting for " + what)


def arrived(targets):
    # stat.position: the commanded position motion works with = program + G5x offset + tool offset (no G92, no
    # rotation in these jobs), so the move is over once it equals the block's words with those offsets.
    return all(abs(stat.position[i] - (v + stat.g5x_offset[i] + stat.tool_offset[i])) < 1e-6 for i, v in targets)


def mdi(block):
    # A move's block names its target: waiting for "idle, in position, empty queue" alone can return before motion
    # has picked the move up on a loaded machine.
    words = block.split()
    targets = [("XYZABCUVW".index(w[0]), float(w[1:])) for w in words[1:]] if words[0] == "G0" else []
    command.mdi(block)
    command.wait_complete(30)
    # Motion runs in servo cycles of 50 us (the comp filter's bound needs them short); on a loaded machine a cycle takes
    # far longer in wall time, so a long rotary move may need minutes: the timeout only guards against a hang.
    wait(lambda: stat.interp_state == linuxcnc.INTERP_IDLE and stat.inpos and stat.queue == 0 and arrived(targets),
         400, block)
    check_errors(block)


def run_program(path, timeout=900):
    command.mode(linuxcnc.MODE_AUTO)
    command.wait_complete()
    command.program_open(path)
    command.wait_complete()
    command.auto(linuxcnc.AUTO_RUN, 0)
    command.wait_complete()
    time.sleep(0.5)  # the interpreter has picked the program up (a short one may be over already)
    def over():
        if stat.interp_state == linuxcnc.INTERP_PAUSED or stat.task_paused:
            command.auto(linuxcnc.AUTO_RESUME)  # an M0 of the program (the operator's cycle start)
            return False
        return (stat.interp_state == linuxcnc.INTERP_IDLE and stat.exec_state == linuxcnc.EXEC_DONE and stat.inpos
                and stat.queue == 0)
    wait(over, timeout, "program " + path)
    check_errors("program " + path)
    command.mode(linuxcnc.MODE_MDI)
    command.wait_complete()


def sample_program(path):
    out = OUT + ".samples"
    sampler = subprocess.Popen(["halsampler", "-c", "0", "-t", out])
    time.sleep(0.5)  # attached to the stream
    hal.set_p("sampler.0.enable", "1")
    try:
        run_program(path)
    finally:
        hal.set_p("sampler.0.enable", "0")
    wait(lambda: int(hal.get_value("sampler.0.curr-depth")) == 0, 60, "halsampler to drain the sampler")
    time.sleep(0.5)
    sampler.send_signal(signal.SIGTERM)
    sampler.wait(30)
    with open(out + ".info", "w") as f:
        f.write("%d %d\n" % (int(hal.get_value("sampler.0.sample-num")), int(hal.get_value("sampler.0.overruns"))))


def pins(name):
    return [float(hal.get_value(name % j)) for j in range(JOINTS)]


def record(label):
    start, settled = time.time(), False
    while time.time() - start < 1.0:
        if all(c == f for c, f in zip(pins("joint.%d.backlash-corr"), pins("joint.%d.backlash-filt"))):
            settled = True
            break
        time.sleep(0.002)
    # stat.position (the arrival test of mdi) can reach the block's words a servo cycle before the joint pins
    # carry that cycle's inverse: the joints are read once two reads some cycles apart agree.
    start, last = time.time(), None
    while time.time() - start < 2.0:
        now = pins("joint.%d.pos-cmd")
        if now == last:
            break
        last = now
        time.sleep(0.02)
    values = (pins("joint.%d.pos-cmd") + pins("joint.%d.motor-pos-cmd") + pins("joint.%d.backlash-corr")
              + pins("joint.%d.backlash-filt"))
    stat.poll()
    return " ".join([label, "1" if settled else "0", repr(float(hal.get_value("motion.tooloffset.z")))]
                    + [repr(v) for v in values] + [repr(float(v)) for v in stat.g5x_offset])


def main():
    wait(lambda: stat.task_state != 0, 10, "task")
    command.state(linuxcnc.STATE_ESTOP_RESET)
    wait(lambda: stat.task_state == linuxcnc.STATE_ESTOP_RESET, 5, "estop reset")
    command.state(linuxcnc.STATE_ON)
    wait(lambda: stat.task_state == linuxcnc.STATE_ON, 5, "machine on")
    command.mode(linuxcnc.MODE_MANUAL)
    command.wait_complete()
    command.teleop_enable(0)
    command.wait_complete()
    command.home(-1)
    command.wait_complete()
    wait(lambda: all(stat.homed[j] for j in range(JOINTS)), 10, "homing")
    # The tool table reaches task through iocontrol, which may still be loading it on a busy machine ("Requested tool
    # N not found in the tool table" on the first T word): wait until every tool the job names is there.
    tools = {int(n) for step in JOB for n in re.findall(r"\bT(\d+)", step)}
    wait(lambda: tools <= {t.id for t in stat.tool_table}, 30, "the tool table (tools %s)" % sorted(tools))
    command.mode(linuxcnc.MODE_MDI)
    command.wait_complete()
    lines = []
    for step in JOB:
        if not step.strip():
            continue
        verb, _, rest = step.partition(" ")
        if verb == "mdi":
            mdi(rest)
        elif verb == "record":
            lines.append(record(rest))
        elif verb == "auto":
            run_program(rest)
        elif verb == "sample":
            sample_program(rest)
        elif verb == "setp":
            name, value = rest.split()
            hal.set_p(name, value)
        elif verb == "setp":
            name, value = rest.split()
            hal.set_p(name, value)
        else:
            raise RuntimeError("unknown job line: " + step)
    with open(OUT + ".part", "w") as f:
        f.write("\n".join(lines) + "\n")
    os.rename(OUT + ".part", OUT)
    command.state(linuxcnc.STATE_OFF)
    command.wait_complete()


try:
    main()
except Exception as ex:  # the reason goes to LinuxCNC's log, which the test prints
    sys.stderr.write("cnccomp driver: %s\n" % ex)
    sys.exit(1)

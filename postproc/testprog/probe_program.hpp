#pragma once
// `cnccomp testprog` for the sphere runs of a plan (measurement/sphere_run.hpp): ONE probing program for all of them,
// in four dialects, and the result file it writes (io/probe_log.hpp: "TOUCH <pose> <touch> [<flag>] X Y Z A B C").
// The moves are sphereCommands() (identification/sphere_probe.hpp) in the controller's machine coordinates
// (MachineModel::toController), joint mode (no tool-tip transformation), work offset zero; LinuxCNC with G43.1 (below).
//
// Per pose: the park axis (the tool axis, e.g. Z) up to the park value, the other axes to the pose (rotary axes at the
// pose's angles, the stylus over the safe point), the park axis down to the safe point; per touch: rapid to the point
// above the touch, rapid to the approach point, the probing move towards the target (the stylus ball centre `approach`
// mm inside the nominal surface) at the plan's feed, the result line, rapid back to the approach point and up.
//
// LinuxCNC (the contract with tests/linuxcnc): (LOGOPEN,<log>) at the top; the run's tool length L given with
// G43.1 Z<L> and every Z word written as the machine coordinate minus L (as the ball-bar and R-test programs:
// program_syntax.hpp passToolLength); each touch
//     G4 P0.05
//     G38.3 X.. Y.. Z.. F<feed>
//     #100=[#5063+L]
//     (LOG,TOUCH <pose> <touch> #5070 #5061 #5062 #100 #5064 #5065 #5066)
// (with L = 0: no G43.1, and #5063 itself).
// LinuxCNC's stale DONE, why the dwell (kSettleDwell): task sends a probe once motion reports DONE, i.e. in position with an empty
// queue (src/emc/task/emctaskmain.cc emcTaskCheckPreconditions: EMC_TRAJ_PROBE_TYPE waits for motion and IO;
// src/emc/task/taskintf.cc emcTrajUpdate: DONE = inpos && queue == 0). Motion echoes a command in its command handler
// (src/emc/motion/command.c) but counts the queue later in the servo cycle (control.c: depth = tpQueueDepth), so a
// status read between the two shows the rapids just sent as done while the stylus still sits on the last contact.
// The probe then starts tripped: G38.2 stops with "Probe is already tripped", G38.3 records the old contact as a new
// touch (control.c process_probe_inputs), a silent wrong touch. The dwell is timed by task (EMC_TRAJ_DELAY: waits for
// motion, then for its time), so the probe's own check reads a status of a later servo cycle. Seen twice in cnccomp's
// headless LinuxCNC tests (tests/linuxcnc/test_linuxcnc_virtual_sphere.cpp, G38.2, on a loaded 2-core machine with
// non-realtime threads); on a realtime machine the window is shorter, not closed.
// G38.3 = probe towards the piece, stop on contact, NO error when the probe does not trip: #5070 = 1 tripped, 0 not,
// #5061–#5069 = X Y Z A B C U V W of the controlled point where it tripped (the programmed point if it did not), in the
// current work coordinate system (LinuxCNC docs/src/gcode/g-code.adoc "G38.n Straight Probe";
// src/emc/rs274ngc/interp_parameter_def.hh G38_X=5061 … G38_TRIPPED=5070). A missed touch is logged with 0 and the
// program goes on (it retracts along the same line), so the log names every miss; the reader refuses it.
// (LOG,...) expands #n with "%lf" (six decimals; src/emc/rs274ngc/interp_convert.cc convert_param_comment);
// LOGOPEN truncates the file, LOGCLOSE closes it (docs/src/gcode/overview.adoc "Logging").
//
// Fanuc: G31 skip move; the skip position #5061–#5063 (#5064… for the 4th… axis, in the order of the controlled axes
// [G]), written with POPEN / DPRNT / PCLOS; DPRNT[TOUCH*#100[40]*…*#5061[44]…]: text A–Z and '*' (a blank), a variable
// with [integer digits, fraction digits], at most 8 together, leading blanks, no point when the fraction has no digits
// (Fanuc-compatible "Formatted Output (DPRNT)" as in the Haas mill operator's manual 96-8000 and the Fanuc custom macro
// chapter); no trip flag: the reader takes a touch at the end of its move as missed.
// Sinumerik: MEAS=1 G01 (measure with deletion of distance-to-go, probe 1: "the positions coinciding with the switching
// edge of the probe are acquired for all axes programmed in the NC block", Job planning 6FC5398-2BP10 section 5.7
// "Measurements with touch trigger probe (MEAS, MEAW)"), $AC_MEA[1] (probe 1 triggered) and $AA_MM[axis] (measured
// position, machine coordinate system), written with WRITE to the file CNCCOMP_PROBE_TXT [G: WRITE's file naming and
// the REAL-to-string form of '<<'].
// HEIDENHAIN: TCH PROBE 4 MEASURING IN 3-D along the touch's move [G: block syntax], the contact position from Q115–Q117
// ("coordinates of the spindle position at the moment of contact … length of the stylus and radius of the ball tip are
// not compensated", TNC 640 user's manual, "Preassigned Q parameters"), written by FN 16: F-PRINT with the format file
// PROBE.A to TNC:\<log> [G: format-file syntax, appending on repeated output].
#include <string>
#include <vector>

#include "cnccomp/io/plan_xml.hpp"
#include "postproc/testprog/program_syntax.hpp"

namespace cnccomp::postproc::testprog {

/// The dwell before each LinuxCNC probing move (the header: "LinuxCNC's stale DONE"); 0.05 s = 5 task cycles at
/// [TASK] CYCLE_TIME 0.010, 50 at 0.001.
inline constexpr const char* kSettleDwell = "G4 P0.05";

struct ProbeProgramOptions {
    postproc::Dialect dialect = postproc::Dialect::Rs274ngc;
    std::string log = "cnccomp-probe.txt";  ///< result file the program writes (LinuxCNC LOGOPEN, Sinumerik WRITE, …)
    int decimals = 6;
    std::string machineFile, planFile;      ///< for the header (file names only)
};

struct ProbeProgramFile {
    std::string file, text;
};

struct ProbeProgram {
    std::vector<ProbeProgramFile> files;  ///< the program first (HEIDENHAIN: also the FN 16 format file)
    int poses = 0, touches = 0;
    /// Commanded probing targets, in program order (description frame), with their pose and touch numbers.
    struct Target {
        int pose = 0, touch = 0;
        AxisVector approach, target;
    };
    std::vector<Target> targets;
};

/// File name of the probing program: "probe" + the dialect's extension ("PROBE.h" for HEIDENHAIN).
std::string probeProgramFileName(postproc::Dialect d);

/// The probing program of the plan's sphere runs. Throws ModelError (sphereCommands) naming the run, pose and touch
/// for a point outside the travel; the plan must have sphere runs.
ProbeProgram makeProbeProgram(const MachineModel& machine, const measurement::MeasurementPlan& plan, const ProbeProgramOptions& options);

}  // namespace cnccomp::postproc::testprog

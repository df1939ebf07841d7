#pragma once
// `cnccomp testprog`: the NC programs that make a plan's measurements, one per run plus an index.
// Each program: a setup block in comments (run type, geometry, where the balls go, sweep, feed, direction, when to
// start and stop the instrument), safe approach, the setup pose with a stop to set the instrument, the start pose
// with a stop to mount the bar and start the capture, feed-in overshoot, the measured sweep CW then CCW (as ball-bar
// software expects; stop-and-go runs: forward then back), feed-out overshoot, a stop to end the capture, retract,
// program end. Positions are the controller's machine coordinates (MachineModel::toController).
//
// Comment markers let `cnccomp verify` find the setup pose and the samples in a program read back through the
// post-processor, also after `cnccomp correct` has split blocks (which keep their N number on the first piece):
//   "CNCCOMP SETUP"                 follows the block that reaches the setup pose;
//   "CNCCOMP PASS <k> <dir> BEGIN"  follows the block that reaches the first sample of pass k;
//   "CNCCOMP PASS <k> END"          follows the block that reaches its last point.
// Between BEGIN and END every numbered block (N word; Klartext: every block) reaches one sweep point.
#include <string>
#include <vector>

#include "cnccomp/io/plan_xml.hpp"
#include "postproc/testprog/program_syntax.hpp"
#include "postproc/testprog/run_motion.hpp"

namespace cnccomp::postproc::testprog {

/// The header line every test program carries (all dialects): the kinematics mode the controller must run it in.
/// The words are machine coordinates, so the controller's tool-tip transformation must be off; `cnccomp verify` runs
/// the programs in this mode (controllers' apply models: joint mode, e.g. LinuxCNC's linuxcnc_apply.hpp).
inline constexpr const char* kKinematicsModeLine =
    "kinematics mode: joint (machine coordinates; tool-tip transformation OFF: LinuxCNC joint mode, "
    "Sinumerik TRAORI off, Heidenhain M128/FUNCTION TCPM off, Fanuc G43.4/G43.5 off)";

struct TestProgramOptions {
    postproc::Dialect dialect = postproc::Dialect::Rs274ngc;
    double feed = 1000.0;        ///< mm/min along the sweep and the overshoot arcs
    double approachFeed = 500.0; ///< mm/min onto the setup and start poses
    double overshootDeg = 10.0;  ///< feed-in / feed-out overshoot, in units of the sweep parameter (deg); reduced where
                                 ///< an axis' travel ends, never below 0
    double clearance = 50.0;     ///< mm: retract along the tool axis before and after the run
    double dwellSeconds = 1.0;   ///< stop-and-go runs: dwell at each pose for the reading
    int decimals = 6;            ///< digits after the point (1e-6 mm / 1e-6 deg)
    std::string machineFile, planFile;  ///< for the header (file names only)
};

struct TestProgram {
    std::string run;
    std::string file;          ///< file name inside the output folder
    std::string text;
    int number = 0;            ///< order in the plan, from 1 (Fanuc O number 1000 + number)
    RunKind kind = RunKind::Ballbar;
    std::string firstPass;     ///< "CW", "CCW" or "forward"
    double overshootStart = 0, overshootEnd = 0;  ///< overshoot actually written at each end of the sweep (deg)
    bool arcs = false;         ///< the sweep is written as circular blocks
    size_t samples = 0;
};

struct TestProgramSet {
    std::vector<TestProgram> programs;
    std::string indexFile = "index.csv";
    std::string index;         ///< CSV: order,run,kind,file,samples,first_pass,arcs,overshoot_deg
};

/// File name of the program of run number `order` (from 1): "TP01_<run>" with characters other than letters,
/// digits and '_' replaced by '_', plus the dialect's extension.
std::string programFileName(const std::string& run, int order, postproc::Dialect d);

/// The program of one run. Throws ModelError naming the run and the axis when a command the measurement needs (setup,
/// approach, sweep) leaves an axis' travel; the overshoot is shortened instead.
TestProgram makeTestProgram(const MachineModel& machine, const RunMotion& motion, int order, const TestProgramOptions& options);

/// Programs for every run of the plan, plus the index. Nothing is written: errors come before any output.
TestProgramSet makeTestPrograms(const MachineModel& machine, const measurement::MeasurementPlan& plan, const TestProgramOptions& options);

/// Writes every program and the index into `dir` (created if missing): all or none (each file is staged under a
/// temporary name first, then renamed). Refuses to overwrite any of `inputs` or a file that is not a regular file.
void writeTestPrograms(const TestProgramSet& set, const std::string& dir, const std::vector<std::string>& inputs);

}  // namespace cnccomp::postproc::testprog

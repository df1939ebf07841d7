#pragma once
// A test program read back through the post-processor (`cnccomp poses`: postproc/poses.hpp, Klartext through
// postproc/klartext_reader.hpp): the commands it makes at the setup pose and at every sweep point of both passes, found
// by the comment markers of test_program.hpp. Works on the programs as written and after `cnccomp correct` (split blocks
// are grouped with the numbered block they came from).
#include <string>
#include <string_view>
#include <vector>

#include "postproc/dialect.hpp"
#include "postproc/testprog/run_motion.hpp"

namespace cnccomp::postproc::testprog {

/// One row of the poses CSV: a motion endpoint, description-frame commands (mm, rad).
struct PoseRow {
    long line = 0;
    std::string motion;   ///< G0 G1 G2 G3 G53 or "-"
    AxisVector q;         ///< commands (fromController of the program's values)
    unsigned known = 0;   ///< axes whose value the row gives
};

/// Every row of `cnccomp poses` for a program text (the CSV parsed back). Throws InputError naming `source`.
std::vector<PoseRow> readPoses(const MachineModel& machine, std::string_view text, postproc::Dialect dialect, const std::string& source);

struct PassCommands {
    std::string label;              ///< "CW", "CCW", "forward", "reverse" (from the marker)
    std::vector<double> t;          ///< sweep parameter of each point, in pass order
    std::vector<size_t> index;      ///< index of each point in motion.points
    std::vector<AxisVector> q;      ///< commands at each point (description frame)
    std::vector<long> lines;        ///< program line of each point's last move
};

struct ProgramCommands {
    AxisVector setup;
    long setupLine = 0;
    std::vector<PassCommands> passes;  ///< two passes
};

/// The commands of a test program for `motion`. The points of a pass get the parameters of motion.points in the
/// pass's direction (forward when its first point reads back nearer the sweep's start than its end). Throws InputError
/// (source:line) when markers are missing, a point has no move or an axis is unknown, or the number of points differs
/// from the plan's.
ProgramCommands readTestProgram(const MachineModel& machine, const RunMotion& motion, std::string_view text,
                                postproc::Dialect dialect, const std::string& source);

/// The commanded end points of the probing moves of a probing program (probe_program.hpp), in program order
/// (description frame; axes a block does not give keep the value the program last commanded; a LinuxCNC G43.1 Z<L> adds L
/// to later Z words until G49): RS274NGC G38.2–G38.5,
/// Fanuc G31 and Sinumerik MEAS=… G01 blocks through the post-processor's lexer (postproc/lexer.hpp); HEIDENHAIN
/// TCH PROBE 4.2 (incremental vector) from the position of the last L block (the Klartext reader does not read TCH
/// PROBE cycles). Throws InputError (source:line) for a probing block whose words cannot be evaluated.
std::vector<AxisVector> readProbeTargets(const MachineModel& machine, std::string_view text, postproc::Dialect dialect,
                                         const std::string& source);

/// The samples of a pass (the simulation's sample parameters, without the closing point of a whole turn), in pass order.
void passSamples(const RunMotion& motion, const PassCommands& pass, std::vector<double>& t, std::vector<AxisVector>& q);

}  // namespace cnccomp::postproc::testprog

#pragma once
// The component route of the LinuxCNC backend: a kinematics component generated for the machine with its
// deviations (kins_component.hpp: the exact model, every location, squareness and component error, forward and
// inverse, joint mode and tool-tip mode), the INI and HAL fragments that load it and set its deviation pins, and the
// apply model that reads those files back and moves like LinuxCNC with the component loaded.
//
// Files (names chosen so that a folder holding both routes reads as the component route by default):
//   cnccomp_kins.comp   the component source (halcompile --install cnccomp_kins.comp)
//   cnccomp-kins.ini    [KINS] KINEMATICS / JOINTS, [TRAJ] COORDINATES
//   cnccomp-kins.hal    the tool-offset net and one setp per deviation pin (every pin of the component)
// The pins-and-tables route (linuxcnc_backend.cpp, linuxcnc_apply.hpp) keeps cnccomp.ini, cnccomp.hal,
// cnccomp-g54.ngc, the joint tables <axis>.comp and README-pins.txt; README.txt describes both.
//
// Apply model (KinsComponentModel): written from the component's documented behaviour (kins_component.hpp) and
// LinuxCNC's: world words → joints by cnccomp's exact-model inverse (solveToolPose, inverse_kinematics.hpp) with the
// deviation values READ FROM the HAL file's setp lines (not from the deviation set in memory):
// - joint mode (switchkins-type 0, the component's default): the words are the nominal machine's commands; the
//   joints put the erroneous machine's tool tip and tool axis where the nominal one puts them, the tool length being
//   the tool-offset pin = motion.tooloffset.z (0 under G49; `cnccomp testprog`'s programs give their tool length
//   with G43.1 Z<L> and write the Z words minus L, so the words LinuxCNC hands the component are still the nominal
//   commands and the tool tip at L is exact even where the tool axis cannot follow, near a singular pose);
// - tool-tip mode (switchkins-type 1): program X Y Z = the tool tip in the workpiece frame as it lies at machine zero
//   (R0·p + t0, p in the description's workpiece frame; G54 = 0 here), rotary words = the angles; LinuxCNC hands the
//   component program + G54 + (0, 0, tool length) under G43 (emccanon.cc), and the component takes the tool-offset
//   pin off Z again (as trtfuncs.c does), so that the tip is where the program says.
// The real LinuxCNC is the oracle of this model (tests/linuxcnc).
#include <memory>
#include <string>
#include <vector>

#include "cnccomp/kinematics.hpp"
#include "controllers/backend.hpp"
#include "controllers/common/directional.hpp"
#include "controllers/linuxcnc/linuxcnc_apply.hpp"

namespace cnccomp::controllers::linuxcnc {

inline constexpr const char* kKinsName = "cnccomp_kins";
inline constexpr const char* kKinsSourceFile = "cnccomp_kins.comp";
inline constexpr const char* kKinsIniFile = "cnccomp-kins.ini";
inline constexpr const char* kKinsHalFile = "cnccomp-kins.hal";

/// The component route's files (component source, INI and HAL fragments) and its coverage (every deviation of the
/// set: the component holds the whole model). Throws ModelError when the component cannot describe the machine.
EmitResult emitComponentRoute(const EmitRequest& request);

/// What the component route's INI and HAL fragments say.
struct KinsFiles {
    std::string module;       ///< [KINS] KINEMATICS
    std::string coordinates;  ///< [TRAJ] COORDINATES, joint order
    int joints = 0;           ///< [KINS] JOINTS
    bool toolOffsetNet = false;  ///< motion.tooloffset.z => <module>.tool-offset
    /// [JOINT_n] BACKLASH per joint (0 when not given; joint n = machine axis n), mm or deg: LinuxCNC adds ±BACKLASH/2
    /// by the joint's direction of motion (control.c compute_screw_comp; this route writes no COMP_FILE).
    std::vector<double> backlash;
};

/// Reads cnccomp-kins.ini and cnccomp-kins.hal (InputError naming file and line): the module, its joints, and the
/// deviation values of the setp lines into `values` (every pin of the machine's deviations must be set once).
KinsFiles readKinsFiles(const MachineModel& m, const std::vector<OutputFile>& files, DeviationSet& values);

class KinsComponentModel final : public AppliedCompensation, public common::DirectionalCompensation {
public:
    /// The machine must outlive the model.
    KinsComponentModel(const MachineModel& m, const std::vector<OutputFile>& files, KinsMode mode = KinsMode::Joint);

    KinsMode mode() const { return mode_; }
    const std::string& coordinates() const { return files_.coordinates; }
    const DeviationSet& values() const { return values_; }
    /// Joint positions (description frame commands, mm/rad) for world words `world` (description frame commands in
    /// joint mode; in tool-tip mode X Y Z replaced by the tool tip in the workpiece frame) and the tool-offset pin.
    AxisVector joints(const AxisVector& world, double toolOffset) const;
    /// Program words (joint order of the coordinates, LinuxCNC units) for nominal commands q: joint mode the
    /// controller coordinates; tool-tip mode X Y Z = the nominal tool tip at tool length L in the workpiece frame.
    JointValues program(const AxisVector& q, double toolLength) const;

    /// driveCommands: a program run under G49 (tool-offset pin 0). driveCommandsForTool: the tool-offset pin = the
    /// tool length (joint mode: the test programs' G43.1 Z<L>; tool-tip mode: G43 with the tool length).
    AxisVector driveCommands(const AxisVector& programmed) const override { return driveCommandsForTool(programmed, 0.0); }
    AxisVector driveCommandsForTool(const AxisVector& programmed, double toolLength) const override;
    /// The same plus ±BACKLASH/2 of each joint by the direction its axis' command moves (0: nothing; the ramp of
    /// control.c's backlash_filt is not modelled). Joint mode: a joint moves the way its axis' words do.
    AxisVector driveCommandsMoving(const AxisVector& programmed, double toolLength, const AxisVector& motion) const override;

private:
    const MachineModel* machine_;
    KinsMode mode_;
    KinsFiles files_;
    DeviationSet values_;
    Kinematics nominal_, actual_;
};

}  // namespace cnccomp::controllers::linuxcnc

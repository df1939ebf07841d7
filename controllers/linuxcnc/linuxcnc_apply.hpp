#pragma once
// The LinuxCNC 2.9 apply model: what the real controller does with the files `cnccomp emit --controller linuxcnc`
// wrote, transcribed from LinuxCNC's source independently of the emitter (it never calls the emitter's pin, work
// offset or table calculations; it reads the files). A program runs in one of two kinematics modes, and the model
// runs it in the mode the program states (`cnccomp testprog` writes joint-mode programs and says so in its header):
// - joint mode (KinsMode::Joint): the program's words are the machine's joint positions (machine coordinates,
//   MachineModel::toController). xyzac/xyzbc-trt-kins are switchable kinematics (switchkins.c): LinuxCNC runs such a
//   program with the identity kinematics (switchkins-type 1 of the trt modules, M429 in LinuxCNC's sample configs
//   configs/sim/axis/vismach/5axis/table-rotary-tilting), so the trt pins do nothing and only the joint tables act;
//   trivkins is the identity anyway;
// - tool-tip mode (KinsMode::ToolTip, trt modules only, switchkins-type 0, their startup default): the program
//   commands the tool tip in the workpiece frame (the description's nominal exact kinematics,
//   Kinematics::toolPointInWorkpiece) under G54 and G43: the position motion receives is program + G54 + (0, 0, tool
//   length) (emccanon.cc adds the work and tool offsets); trtfuncs.c 2.9 inverse with the HAL pins of cnccomp.hal,
//   tool-offset = the tool length (motion.tooloffset.z);
// - in both modes the joint tables (usrmotintf.cc usrmotLoadComp, COMP_FILE_TYPE 0 or 1; control.c
//   compute_screw_comp): trim by the direction of motion, linear interpolation, end values held, looked up at the raw
//   joint position.
// Backend::apply gives the joint mode: the mode of the test programs `verify` runs (a tool-tip-mode prediction of
// machine-coordinate programs predicted 18.7 um where the real LinuxCNC gave 60.1 um).
// The tests compare it with the real LinuxCNC (tests/linuxcnc).
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "cnccomp/kinematics.hpp"
#include "controllers/backend.hpp"
#include "controllers/common/directional.hpp"
#include "controllers/linuxcnc/comp_table.hpp"
#include "controllers/linuxcnc/trt_kins.hpp"

namespace cnccomp::controllers::linuxcnc {

/// File names of the emitted configuration.
inline constexpr const char* kIniFile = "cnccomp.ini";
inline constexpr const char* kHalFile = "cnccomp.hal";
inline constexpr const char* kWorkOffsetFile = "cnccomp-g54.ngc";
inline constexpr const char* kReadmeFile = "README-pins.txt";  ///< the pins route's README

/// How LinuxCNC reads a program's axis words (above).
enum class KinsMode { Joint, ToolTip };

/// Values per LinuxCNC joint (joint order of the INI's coordinates=), mm and deg.
using JointValues = AxisVector;

class LinuxcncModel final : public AppliedCompensation, public common::DirectionalCompensation {
public:
    /// Reads cnccomp.ini, the COMP_FILEs, and for a trt module cnccomp.hal and cnccomp-g54.ngc (InputError
    /// naming file and line). The machine must outlive the model. ModelError for KinsMode::ToolTip on trivkins.
    LinuxcncModel(const MachineModel& machine, const std::vector<OutputFile>& files, KinsMode mode = KinsMode::Joint);

    KinsMode mode() const { return mode_; }
    /// The program's words for the nominal machine at commands q (joint mode: the joint positions; tool-tip mode: X Y Z of the tool tip at tool length L in
    /// the G54 frame, then the rotary positions; trivkins: joint positions), in joint order.
    JointValues program(const AxisVector& q, double toolLength) const;
    /// joint.N.pos-cmd: the kinematics inverse of the program (joint mode: the words; tool-tip mode: with G54, G43
    /// and tool-offset = toolLength).
    JointValues jointPositions(const JointValues& program, double toolLength) const;
    /// joint.N.motor-pos-cmd: joint positions plus the table trims; directions[n] > 0 uses the forward column,
    /// < 0 the reverse one, 0 their mean. A joint without a table and with [JOINT_n] BACKLASH gets +BACKLASH/2 for
    /// directions[n] > 0, −BACKLASH/2 for < 0, nothing for 0 (control.c compute_screw_comp; the ramp of backlash_filt,
    /// limited by the joint's velocity and acceleration, is not modelled: the value after the ramp).
    JointValues motorPositions(const JointValues& joints, const JointValues& directions) const;
    /// [JOINT_n] BACKLASH of each joint (0 when not given), LinuxCNC units.
    const std::vector<double>& backlash() const { return backlash_; }

    /// Drive commands (description frame) for a program for the nominal machine; tool length 0, mean column.
    AxisVector driveCommands(const AxisVector& programmed) const override { return driveCommandsForTool(programmed, 0.0); }
    AxisVector driveCommandsForTool(const AxisVector& programmed, double toolLength) const override;
    /// The same with each joint moving the way its axis' command does (motion, description order; the joints are
    /// the axes' controller coordinates, of the same sign): the tables' forward / reverse column, BACKLASH by direction.
    AxisVector driveCommandsMoving(const AxisVector& programmed, double toolLength, const AxisVector& motion) const override;

    const std::string& coordinates() const { return coordinates_; }
    const std::optional<TrtType>& trt() const { return trt_; }
    const TrtPins& pins() const { return pins_; }
    const std::array<double, 3>& workOffset() const { return g54_; }
    /// Machine axis index of joint n.
    int jointAxis(int n) const { return jointAxis_[n]; }

private:
    const MachineModel* machine_;
    KinsMode mode_ = KinsMode::Joint;
    Kinematics nominal_;
    std::string coordinates_;
    std::vector<int> jointAxis_;
    std::vector<double> unit_;  ///< internal units per LinuxCNC unit (1 or kDeg)
    std::optional<TrtType> trt_;
    TrtPins pins_;
    std::array<double, 3> g54_{};
    int jx_ = -1, jy_ = -1, jz_ = -1, jt_ = -1, jc_ = -1;
    std::vector<std::optional<CompTable>> tables_;
    std::vector<double> backlash_;
};

}  // namespace cnccomp::controllers::linuxcnc

#include "controllers/linuxcnc/linuxcnc_apply.hpp"

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/common/files.hpp"
#include "controllers/linuxcnc/config_files.hpp"

namespace cnccomp::controllers::linuxcnc {
using namespace cnccomp::controllers::common;
namespace {

/// The trt module the machine's chains fit, read from the chains alone (not through the emitter's matcher): the
/// workpiece chain holds exactly two rotary axes, A about +X or B about +Y, then C about +Z.
std::optional<TrtType> trtOfChains(const MachineModel& m) {
    std::vector<const Link*> rot;
    for (const Link& l : m.workpiece.links)
        if (l.kind == AxisKind::Rotary) rot.push_back(&l);
    if (rot.size() != 2 || rot[1]->name != "C" || (rot[1]->direction - Vec3::UnitZ()).norm() > 1e-9) return std::nullopt;
    if (rot[0]->name == "A" && (rot[0]->direction - Vec3::UnitX()).norm() < 1e-9) return TrtType::AC;
    if (rot[0]->name == "B" && (rot[0]->direction - Vec3::UnitY()).norm() < 1e-9) return TrtType::BC;
    return std::nullopt;
}

}  // namespace

LinuxcncModel::LinuxcncModel(const MachineModel& m, const std::vector<OutputFile>& files, KinsMode mode)
    : machine_(&m), mode_(mode), nominal_(m) {
    const IniFragment ini = parseIni(requireFile(files, kIniFile, "LinuxCNC").content, kIniFile);
    coordinates_ = ini.coordinates;
    if (coordinates_.empty()) throw InputError(kIniFile, 0, "the KINEMATICS line needs coordinates=LETTERS");
    if (static_cast<int>(coordinates_.size()) != m.axisCount())
        throw InputError(kIniFile, 0, fmt::format("coordinates={} do not match the {} axes of machine '{}'", coordinates_,
                                                  m.axisCount(), m.name));
    for (char c : coordinates_) {
        const int axis = m.axisIndex(std::string(1, c));
        if (axis < 0) throw InputError(kIniFile, 0, fmt::format("machine '{}' has no axis {}", m.name, c));
        jointAxis_.push_back(axis);
        unit_.push_back(m.axisLink(axis).kind == AxisKind::Rotary ? kDeg : 1.0);
    }
    const auto jointOf = [&](char c) { return static_cast<int>(coordinates_.find(c)); };
    if (ini.kinematics == "xyzac-trt-kins" || ini.kinematics == "xyzbc-trt-kins") {
        const TrtType type = ini.kinematics == "xyzac-trt-kins" ? TrtType::AC : TrtType::BC;
        if (trtOfChains(m) != type)
            throw InputError(kIniFile, 0, fmt::format("kinematics {} does not fit machine '{}'", ini.kinematics, m.name));
        trt_ = type;
        const auto pins = parseHal(requireFile(files, kHalFile, "LinuxCNC").content, kHalFile, ini.kinematics);
        if (!pins) throw InputError(kHalFile, 0, fmt::format("no {} pin is set", ini.kinematics));
        pins_ = *pins;
        g54_ = parseWorkOffset(requireFile(files, kWorkOffsetFile, "LinuxCNC").content, kWorkOffsetFile);
        jx_ = jointOf('X');
        jy_ = jointOf('Y');
        jz_ = jointOf('Z');
        jt_ = jointOf(type == TrtType::AC ? 'A' : 'B');
        jc_ = jointOf('C');
        if (jx_ < 0 || jy_ < 0 || jz_ < 0 || jt_ < 0 || jc_ < 0)
            throw InputError(kIniFile, 0, fmt::format("coordinates={} lack a letter of {}", coordinates_, ini.kinematics));
    } else if (ini.kinematics != "trivkins") {
        throw InputError(kIniFile, 0, fmt::format("kinematics {} is not modelled (trivkins, xyzac-trt-kins, xyzbc-trt-kins)",
                                                  ini.kinematics));
    }
    if (mode_ == KinsMode::ToolTip && !trt_)
        throw ModelError(fmt::format("{}: {} has no tool-tip mode (only xyzac/xyzbc-trt-kins switch to it)", kIniFile, ini.kinematics));
    tables_.resize(coordinates_.size());
    backlash_.assign(coordinates_.size(), 0.0);
    for (const auto& [n, b] : ini.backlash) {
        if (n >= static_cast<int>(coordinates_.size()))
            throw InputError(kIniFile, 0, fmt::format("[JOINT_{}] BACKLASH but only {} joints", n, coordinates_.size()));
        backlash_[static_cast<size_t>(n)] = b;
    }
    for (const auto& [n, file] : ini.compFile) {
        if (n >= static_cast<int>(coordinates_.size()))
            throw InputError(kIniFile, 0, fmt::format("[JOINT_{}] but only {} joints", n, coordinates_.size()));
        const CompTable t = parseCompTable(requireFile(files, file, "LinuxCNC").content, file);
        const auto type = ini.compType.find(n);
        tables_[n] = type != ini.compType.end() && type->second == 1 ? t : fromActualPositions(t);
    }
}

JointValues LinuxcncModel::program(const AxisVector& q, double toolLength) const {
    const AxisVector c = machine_->toController(q);
    const int n = static_cast<int>(coordinates_.size());
    JointValues p(n);
    for (int i = 0; i < n; ++i) p[i] = c[jointAxis_[i]] / unit_[i];
    if (mode_ == KinsMode::ToolTip) {
        // With the module's rotary joints at 0 the workpiece frame's axes are the joint axes (trt chains have no
        // rotated placements), so the G54 frame is the workpiece frame shifted to the G54 origin.
        const Vec3 tip = nominal_.toolPointInWorkpiece(q, nominal_.toolPoint(toolLength));
        p[jx_] = tip.x();
        p[jy_] = tip.y();
        p[jz_] = tip.z();
    }
    return p;
}

JointValues LinuxcncModel::jointPositions(const JointValues& program, double toolLength) const {
    JointValues j = program;
    if (mode_ == KinsMode::Joint) return j;  // identity kinematics: the trt pins do nothing
    // emccanon.cc: motion gets program + G54 + tool offset (G43: the tool length along Z).
    TrtPose world{{program[jx_] + g54_[0], program[jy_] + g54_[1], program[jz_] + g54_[2] + toolLength}, program[jt_], program[jc_]};
    TrtPins pins = pins_;
    pins.toolOffset = toolLength;  // motion.tooloffset.z => <module>.tool-offset
    const TrtPose jj = trtInverse(*trt_, pins, world);
    j[jx_] = jj.xyz[0];
    j[jy_] = jj.xyz[1];
    j[jz_] = jj.xyz[2];
    j[jt_] = jj.tilt;
    j[jc_] = jj.c;
    return j;
}

JointValues LinuxcncModel::motorPositions(const JointValues& joints, const JointValues& directions) const {
    JointValues m = joints;
    for (int i = 0; i < m.size(); ++i) {
        const int d = directions[i] > 0 ? 1 : directions[i] < 0 ? -1 : 0;
        if (tables_[i]) m[i] += tables_[i]->trim(joints[i], d);
        else m[i] += 0.5 * backlash_[static_cast<size_t>(i)] * d;  // no COMP_FILE: ±BACKLASH/2
    }
    return m;
}

AxisVector LinuxcncModel::driveCommandsForTool(const AxisVector& q, double toolLength) const {
    return driveCommandsMoving(q, toolLength, AxisVector::Zero(q.size()));
}

AxisVector LinuxcncModel::driveCommandsMoving(const AxisVector& q, double toolLength, const AxisVector& motion) const {
    const int n = static_cast<int>(coordinates_.size());
    JointValues directions = JointValues::Zero(n);
    if (motion.size() == q.size())
        for (int i = 0; i < n; ++i) directions[i] = motion[jointAxis_[i]];
    const JointValues motor = motorPositions(jointPositions(program(q, toolLength), toolLength), directions);
    AxisVector c = machine_->toController(q);
    for (int i = 0; i < n; ++i) c[jointAxis_[i]] = motor[i] * unit_[i];
    return machine_->fromController(c);
}

}  // namespace cnccomp::controllers::linuxcnc

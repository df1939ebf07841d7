// Backend "heidenhain-tnc": kinematics description with the location errors as Trans rows and KinematicsComp
// .COM tables for the component errors (kinematics_table.hpp). Apply model: the TNC's TCP (M128 / FUNCTION
// TCPM) on the corrected kinematics read back from the files — the programmed commands' nominal tool pose is
// reached on the chain the rows describe, with the tables interpolated linearly at the axis positions.
#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"
#include "controllers/backend.hpp"
#include "controllers/common/directional.hpp"
#include "controllers/common/files.hpp"
#include "controllers/common/set_backlash.hpp"
#include "controllers/heidenhain/kinematics_table.hpp"
#include "controllers/heidenhain/laser_com.hpp"

namespace cnccomp::controllers::heidenhain {
using namespace cnccomp::controllers::common;
using namespace cnccomp::io;
namespace {

class HeidenhainCompensation final : public AppliedCompensation, public DirectionalCompensation {
public:
    HeidenhainCompensation(TcpTransform tcp, std::vector<double> backlash) : tcp_(std::move(tcp)), backlash_(std::move(backlash)) {}
    AxisVector driveCommands(const AxisVector& programmed) const override { return tcp_.solve(programmed); }
    /// M128 / FUNCTION TCPM computes with the active tool's length from the tool table.
    AxisVector driveCommandsForTool(const AxisVector& programmed, double toolLength) const override {
        return tcp_.solve(programmed, toolLength);
    }
    /// The same plus MP710 by the direction of motion (controllers/common/set_backlash.hpp).
    AxisVector driveCommandsMoving(const AxisVector& programmed, double toolLength, const AxisVector& motion) const override {
        return withBacklashOffsets(driveCommandsForTool(programmed, toolLength), backlash_, motion);
    }

private:
    TcpTransform tcp_;
    std::vector<double> backlash_;
};

/// MP710.x of CNCCOMP_BACKLASH.MP per machine axis (mm); empty without the file. InputError file:line otherwise.
std::vector<double> readBacklash(const MachineModel& m, const std::vector<OutputFile>& files) {
    const OutputFile* f = findFile(files, kBacklashFile);
    if (!f) return {};
    std::vector<double> b(static_cast<size_t>(m.axisCount()), 0.0);
    for (const TextLine& l : splitLines(f->content)) {
        const std::string_view t = trim(l.text);
        if (t.empty() || t.front() == ';') continue;
        const size_t colon = t.find(':');
        int axis = -1;
        if (t.starts_with("MP710.") && colon != std::string_view::npos)
            for (int a = 0; a < m.axisCount(); ++a)
                if (std::to_string(tncAxisIndex(m.axisNames[static_cast<size_t>(a)])) == t.substr(6, colon - 6)) axis = a;
        const auto v = colon == std::string_view::npos ? std::nullopt : parseNumber(t.substr(colon + 1));
        if (axis < 0 || !v) throw InputError(f->name, l.number, "expected MP710.<X 0, Y 1, Z 2 of the machine>:<mm> or a ';' comment");
        b[static_cast<size_t>(axis)] = *v;
    }
    return b;
}

class HeidenhainBackend final : public Backend {
public:
    std::string_view name() const override { return "heidenhain-tnc"; }
    std::string_view description() const override {
        return "HEIDENHAIN iTNC 530: kinematics description (Trans rows for the location errors) and KinematicsComp "
               ".COM tables for the component errors (not for TNC 640 / TNC7, whose kinematics live in the machine "
               "configuration)";
    }
    std::vector<std::string> checks() const override {
        return {"the control is an iTNC 530 with KinematicsComp (option); a TNC 640 or TNC7 does not read .TAB kinematics",
                "tool-side rows are read from the tool to MachBase with their motion inverted, and their .COM columns hold "
                "-error (cnccomp's reading of KinematicsDesign); check one axis in KinematicsDesign before loading",
                "the MachAxis letters are the TNC's axis names and each axis moves along +X/+Y/+Z or turns about them",
                "100 COMPTAB entries including the MachAxis rows, 50 Trans+MachAxis rows, 256 rows per .COM table",
                "CNCCOMP_BACKLASH.MP: MP710.0/1/2 = the backlash of X/Y/Z in the TNC's axis order, in the machine-parameter "
                "file syntax cnccomp assumes (MP710.0:+0.004000); enter the values by hand if yours differs"};
    }
    EmitResult emit(const EmitRequest& request) const override { return emitFiles(request, Options{}); }
    std::unique_ptr<AppliedCompensation> apply(const MachineModel& machine,
                                               const std::vector<OutputFile>& files) const override {
        const ParsedKinematics p = parseFiles(machine, files);
        std::unique_ptr<const ControllerModel> model;
        try {
            model = std::make_unique<ControllerModel>(machine, p.workpiece, p.tool, p.tables);
        } catch (const ModelError& e) {
            throw InputError("<heidenhain-tnc kinematics>", 0, e.what());
        }
        return std::make_unique<HeidenhainCompensation>(TcpTransform(machine, std::move(model)), readBacklash(machine, files));
    }
};

const RegisterBackend registration(std::make_unique<HeidenhainBackend>());

}  // namespace
}  // namespace cnccomp::controllers::heidenhain

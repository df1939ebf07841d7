// Backend "heidenhain-tnc": kinematics description with the location errors as Trans rows and KinematicsComp
// .COM tables for the component errors (kinematics_table.hpp). Apply model: the TNC's TCP (M128 / FUNCTION
// TCPM) on the corrected kinematics read back from the files — the programmed commands' nominal tool pose is
// reached on the chain the rows describe, with the tables interpolated linearly at the axis positions.
#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/backend.hpp"
#include "controllers/heidenhain/kinematics_table.hpp"

namespace cnccomp::controllers::heidenhain {
namespace {

class HeidenhainCompensation final : public AppliedCompensation {
public:
    explicit HeidenhainCompensation(TcpTransform tcp) : tcp_(std::move(tcp)) {}
    AxisVector driveCommands(const AxisVector& programmed) const override { return tcp_.solve(programmed); }
    /// M128 / FUNCTION TCPM computes with the active tool's length from the tool table.
    AxisVector driveCommandsForTool(const AxisVector& programmed, double toolLength) const override {
        return tcp_.solve(programmed, toolLength);
    }

private:
    TcpTransform tcp_;
};

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
                "100 COMPTAB entries including the MachAxis rows, 50 Trans+MachAxis rows, 256 rows per .COM table"};
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
        return std::make_unique<HeidenhainCompensation>(TcpTransform(machine, std::move(model)));
    }
};

const RegisterBackend registration(std::make_unique<HeidenhainBackend>());

}  // namespace
}  // namespace cnccomp::controllers::heidenhain

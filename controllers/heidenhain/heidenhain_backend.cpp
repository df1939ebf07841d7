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

private:
    TcpTransform tcp_;
};

class HeidenhainBackend final : public Backend {
public:
    std::string_view name() const override { return "heidenhain-tnc"; }
    std::string_view description() const override {
        return "HEIDENHAIN TNC: kinematics description (Trans rows for the location errors) and KinematicsComp "
               ".COM tables for the component errors";
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

#pragma once
// Backend "fanuc-30i" (see fanuc_backend.cpp): emit with explicit limits, and the apply model.
#include <memory>
#include <vector>

#include "controllers/backend.hpp"
#include "controllers/common/directional.hpp"
#include "controllers/common/controller_model.hpp"
#include "controllers/fanuc/pitch_error.hpp"

namespace cnccomp::controllers::fanuc {

inline constexpr const char* kParameterFile = "CNCCOMP.PRM";

EmitResult emitFiles(const EmitRequest& request, const PitchOptions& options);

class FanucCompensation final : public AppliedCompensation, public common::DirectionalCompensation {
public:
    FanucCompensation(const MachineModel& m, std::unique_ptr<const common::ControllerModel> tcp, std::vector<PitchTable> pitch,
                      double unit);
    /// With the default tool length of the TCP (kControllerToolLength).
    AxisVector driveCommands(const AxisVector& programmed) const override;
    /// The TCP with the active tool's length, then the tables at the resulting machine positions.
    AxisVector driveCommandsForTool(const AxisVector& programmed, double toolLength) const override;
    /// The same plus the backlash 1851 by the direction of motion (controllers/common/set_backlash.hpp).
    AxisVector driveCommandsMoving(const AxisVector& programmed, double toolLength, const AxisVector& motion) const override;
    const common::TcpTransform& tcp() const { return tcp_; }
    const std::vector<PitchTable>& pitch() const { return pitch_; }
    /// 1851 of each axis (description order), mm; empty when the file sets none.
    std::vector<double> backlash;

private:
    const MachineModel* machine_;
    common::TcpTransform tcp_;
    std::vector<PitchTable> pitch_;
    double unit_;
};

/// Reads CNCCOMP.PRM (InputError file:line).
std::unique_ptr<FanucCompensation> readFiles(const MachineModel& m, const std::vector<OutputFile>& files);

}  // namespace cnccomp::controllers::fanuc

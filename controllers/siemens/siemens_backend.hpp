#pragma once
// Backend "siemens-840d": Sinumerik 840D sl files from a deviation set (see siemens_plan.hpp for what goes
// where) and the apply model: TRAORI on the kinematic chain read back from the file (the programmed commands'
// nominal tool pose is reached on the corrected chain), then the CEC trims added to the output axes and the
// EEC errors taken off each axis, interpolated at the commanded positions as the NCK does.
#include <memory>
#include <vector>

#include "controllers/backend.hpp"
#include "controllers/common/directional.hpp"
#include "controllers/common/controller_model.hpp"
#include "controllers/siemens/siemens_plan.hpp"

namespace cnccomp::controllers::siemens {

/// MD32450 $MA_BACKLASH of the set's reversal values (written when the set has one; laser_eec.hpp's line).
inline constexpr const char* kBacklashFile = "CNCCOMP_BACKLASH.INI";

/// emit with explicit controller limits (the registered backend uses the defaults).
EmitResult emitFiles(const EmitRequest& request, const Options& options);

class SiemensCompensation final : public AppliedCompensation, public common::DirectionalCompensation {
public:
    SiemensCompensation(const MachineModel& m, std::unique_ptr<const common::ControllerModel> chain, std::vector<CecTable> cec,
                        std::vector<EecTable> eec);
    /// With the default tool length of the TCP (kControllerToolLength).
    AxisVector driveCommands(const AxisVector& programmed) const override;
    /// The TCP with the active tool's length, then the tables at the resulting machine positions.
    AxisVector driveCommandsForTool(const AxisVector& programmed, double toolLength) const override;
    const common::TcpTransform& tcp() const { return tcp_; }
    const std::vector<CecTable>& cec() const { return cec_; }
    const std::vector<EecTable>& eec() const { return eec_; }
    /// The same plus MD32450 by the direction of motion (controllers/common/set_backlash.hpp).
    AxisVector driveCommandsMoving(const AxisVector& programmed, double toolLength, const AxisVector& motion) const override;
    /// MD32450 of each axis (description order), mm; empty when no file sets one.
    std::vector<double> backlash;

private:
    const MachineModel* machine_;
    common::TcpTransform tcp_;
    std::vector<CecTable> cec_;
    std::vector<EecTable> eec_;
};

/// Reads the files (InputError file:line) into the apply model.
std::unique_ptr<SiemensCompensation> readFiles(const MachineModel& m, const std::vector<OutputFile>& files);

}  // namespace cnccomp::controllers::siemens

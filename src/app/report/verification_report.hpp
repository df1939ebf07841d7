#pragma once
// The report of `cnccomp verify`: ReportData (report_data.hpp) filled from a VerifyResult (verify.hpp). "Before" is
// what the instrument reads when the test programs run as written on the simulated machine (the true one with
// --truth, else the identified one), "after" what it reads through the compensation (the files the user loads, or the
// corrected programs).
//  - per ball-bar and DBB5 circle: the CW and CCW passes before and after overlaid in one polar plot, ISO 230-4
//    G, F max / min, mean radius and H before and after (evaluateCircularRun, as in the identification report), the
//    eccentricity of each pass in the notes;
//  - the span of every pass of every run (ball bar and R-test); the largest after is verify's residual;
//  - the compensation: its files, the backend's compensated and NOT-compensated lists (each deviation left with its
//    value in the simulated machine and the backend's reason), the volumetric tool-tip error over the plan's
//    workspace before and after, the largest span before and after;
//  - maps of the simulated machine before and after the compensation on one colour scale from 0 (a compensation
//    model is needed: corrected programs compensate their own poses only, so they get none, and the page says so).
#include <optional>
#include <string>

#include "app/report/compensation_map.hpp"
#include "app/report/report_data.hpp"
#include "app/verify.hpp"

namespace cnccomp::app::report {

struct VerificationReportInputs {
    std::string machineFile, planFile, compensationPath;  ///< as given on the command line (shown in the page)
    std::string dialect;                                  ///< of the in-memory test programs, e.g. "linuxcnc"
    std::optional<double> gateUm;                         ///< --max-residual-um
    std::optional<double> volumetricGateUm;               ///< --max-volumetric-um
    /// The deviation set when the compensation is one (ideal compensation): its deviations are listed as compensated.
    const DeviationSet* compensationSet = nullptr;
    /// Grid and plane of the maps; the tool length is the first run's (VerifyResult::volumetric.toolLengths).
    MapOptions map;
};

/// The page's data. `simulated` is the deviation set of the machine the commands reached (as given to verify()).
ReportData verificationReport(const MachineModel& machine, const DeviationSet& simulated, const VerifyCompensation& compensation,
                              const VerifyResult& result, const VerificationReportInputs& inputs);

}  // namespace cnccomp::app::report

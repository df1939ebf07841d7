#include "cnccomp/io/laser_report.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/io/markup.hpp"

namespace cnccomp::io {

namespace laser_report_detail {

std::string environmentText(const LaserPositioningResult& r, bool stated) {
    if (!stated) return "not stated in the file (evaluated as not done)";
    return r.environmentCompensated ? "done (stated in the file)" : "not done (stated in the file)";
}

std::string lrNum(double v) { return jsonNumber(v, 6); }

}  // namespace laser_report_detail

std::string formatLaserTable(const LaserPositioningResult& r, bool environmentStated) {
    using namespace laser_report_detail;
    std::string o = fmt::format("ISO 230-2 positioning of axis {}: {} targets, {} runs in each direction; environment "
                                "compensation: {}\n",
                                r.axis, r.targets.size(), r.runs, environmentText(r, environmentStated));
    o += fmt::format("{:>12} {:>10} {:>10} {:>10} {:>9} {:>9} {:>9} {:>9}\n", "target_mm", "mean_up_um", "mean_dn_um",
                     "mean_um", "B_i_um", "R_up_um", "R_dn_um", "R_i_um");
    for (const LaserTargetResult& t : r.targets)
        o += fmt::format("{:>12.3f} {:>10.3f} {:>10.3f} {:>10.3f} {:>9.3f} {:>9.3f} {:>9.3f} {:>9.3f}\n", t.target,
                         t.meanForward, t.meanReverse, t.mean, t.reversal, t.repeatabilityForward,
                         t.repeatabilityReverse, t.repeatability);
    o += fmt::format("systematic positional deviation  E  = {:.3f} um   E up = {:.3f} um   E down = {:.3f} um\n", r.E,
                     r.EForward, r.EReverse);
    o += fmt::format("accuracy                         A  = {:.3f} um   A up = {:.3f} um   A down = {:.3f} um\n", r.A,
                     r.AForward, r.AReverse);
    o += fmt::format("reversal value                   B  = {:.3f} um   mean reversal B-bar = {:.3f} um\n", r.B,
                     r.meanReversal);
    o += fmt::format("repeatability                    R  = {:.3f} um   R up = {:.3f} um   R down = {:.3f} um\n", r.R,
                     r.RForward, r.RReverse);
    o += fmt::format("range of mean bidirectional dev. M  = {:.3f} um\n", r.M);
    for (const std::string& w : r.warnings) o += "warning: " + w + "\n";
    return o;
}

std::string formatLaserJson(const LaserPositioningResult& r, bool environmentStated, const std::string& file) {
    using namespace laser_report_detail;
    std::string targets = "[";
    for (size_t i = 0; i < r.targets.size(); ++i) {
        const LaserTargetResult& t = r.targets[i];
        targets += fmt::format("{}\n    {{\"target_mm\": {}, \"mean_forward_um\": {}, \"mean_reverse_um\": {}, "
                               "\"mean_um\": {}, \"B_um\": {}, \"s_forward_um\": {}, \"s_reverse_um\": {}, "
                               "\"R_forward_um\": {}, \"R_reverse_um\": {}, \"R_um\": {}}}",
                               i ? "," : "", lrNum(t.target), lrNum(t.meanForward), lrNum(t.meanReverse),
                               lrNum(t.mean), lrNum(t.reversal), lrNum(t.sForward), lrNum(t.sReverse),
                               lrNum(t.repeatabilityForward), lrNum(t.repeatabilityReverse), lrNum(t.repeatability));
    }
    targets += "\n  ]";
    std::string warnings = "[";
    for (size_t i = 0; i < r.warnings.size(); ++i) warnings += (i ? ", " : "") + jsonString(r.warnings[i]);
    warnings += "]";
    return fmt::format(
        "{{\n  \"schema\": \"cnccomp-laser-positioning/1\",\n  \"standard\": \"ISO 230-2:2014\",\n  \"file\": {},\n"
        "  \"axis\": {},\n  \"runs\": {},\n  \"environment_compensated\": {},\n  \"environment_stated\": {},\n"
        "  \"E_um\": {}, \"E_forward_um\": {}, \"E_reverse_um\": {},\n  \"A_um\": {}, \"A_forward_um\": {}, "
        "\"A_reverse_um\": {},\n  \"B_um\": {}, \"B_mean_um\": {},\n  \"R_um\": {}, \"R_forward_um\": {}, "
        "\"R_reverse_um\": {},\n  \"M_um\": {},\n  \"warnings\": {},\n  \"targets\": {}\n}}\n",
        jsonString(file), jsonString(r.axis), r.runs, r.environmentCompensated ? "true" : "false",
        environmentStated ? "true" : "false", lrNum(r.E), lrNum(r.EForward), lrNum(r.EReverse), lrNum(r.A),
        lrNum(r.AForward), lrNum(r.AReverse), lrNum(r.B), lrNum(r.meanReversal), lrNum(r.R), lrNum(r.RForward),
        lrNum(r.RReverse), lrNum(r.M), warnings, targets);
}

}  // namespace cnccomp::io

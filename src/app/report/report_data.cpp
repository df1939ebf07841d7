#include "app/report/report_data.hpp"

namespace cnccomp::app::report {

IsoFigures isoFigures(const CircularRunResult& r) {
    IsoFigures f;
    f.G = r.circularDeviation;
    f.Fmax = r.radialMax;
    f.Fmin = r.radialMin;
    f.meanRadius = r.meanRadius;
    f.H = r.hysteresis;
    return f;
}

}  // namespace cnccomp::app::report

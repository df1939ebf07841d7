#include "controllers/siemens/siemens_plan.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/common/controller_model.hpp"

namespace cnccomp::controllers::siemens {
using namespace cnccomp::controllers::common;

std::string axisName(const MachineModel& m, int machineAxis) {
    return fmt::format("AX{}", controllerAxisNumber(m, machineAxis));
}

namespace {

/// A table whose values all print as 0.000000 mm (or deg) is not written.
constexpr double kNegligible = 5e-7;

Pose translation(const Vec3& t) {
    Pose p = Pose::Identity();
    p.translation() = t;
    return p;
}

std::string joined(const std::vector<std::string>& v, const char* sep = ", ") {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : sep) + x;
    return s;
}

void addUnique(std::vector<std::string>& v, const std::string& s) {
    if (std::find(v.begin(), v.end(), s) == v.end()) v.push_back(s);
}

struct Builder {
    const MachineModel& m;
    const DeviationSet& d;
    const Options& o;
    Plan plan;
    int lastLinear[2] = {-1, -1};
    std::vector<Vec3> real, ctl;        // per machine axis: bed direction of a linear axis (real / controller)
    std::vector<Mat3> frame;            // per machine axis: bed rotation of the frame before its motion (real)
    std::vector<int> sigma;             // +1 tool side, -1 workpiece side
    std::vector<char> rotaryUpstream;   // a rotary axis of the same chain carries this axis
    std::map<std::pair<int, int>, size_t> cecIndex;
    std::map<int, size_t> eecIndex;

    Builder(const MachineModel& m_, const DeviationSet& d_, const Options& o_) : m(m_), d(d_), o(o_) {
        const int n = m.axisCount();
        real.assign(n, Vec3::Zero());
        ctl.assign(n, Vec3::Zero());
        frame.assign(n, Mat3::Identity());
        sigma.assign(n, 1);
        rotaryUpstream.assign(n, 0);
    }

    bool isLinear(int axis) const { return m.axisLink(axis).kind == AxisKind::Linear; }

    void chains() {
        for (Side side : {Side::Workpiece, Side::Tool}) {
            const Chain& c = m.chain(side);
            const int s = sideIndex(side);
            for (int i = 0; i < static_cast<int>(c.links.size()); ++i)
                if (c.links[i].kind == AxisKind::Linear) lastLinear[s] = i;
            bool rotarySeen = false;
            Pose preal = Pose::Identity(), pctl = Pose::Identity();
            plan.placed[s].assign(c.links.size(), Pose::Identity());
            for (int i = 0; i < static_cast<int>(c.links.size()); ++i) {
                const Link& l = c.links[i];
                if (l.kind == AxisKind::Linear && rotarySeen)
                    throw ModelError(fmt::format(
                        "siemens-840d: linear axis {} is carried by a rotary axis; the CEC trims need the linear axes "
                        "of a chain upstream of its rotary axes", l.name));
                const Vec6 e = linkLocationError(m, d.values, side, i);
                const Pose E = errorTransform(e);
                if (l.axisIndex >= 0) {
                    sigma[l.axisIndex] = side == Side::Tool ? 1 : -1;
                    rotaryUpstream[l.axisIndex] = rotarySeen;
                    frame[l.axisIndex] = (preal * l.placement * E).linear();
                }
                if (i <= lastLinear[s]) {
                    const Pose Et = translation(e.head<3>());
                    preal = preal * l.placement * E;
                    pctl = pctl * l.placement * Et;
                    if (l.kind == AxisKind::Linear) {
                        real[l.axisIndex] = preal.linear() * l.direction;
                        ctl[l.axisIndex] = pctl.linear() * l.direction;
                    }
                    plan.placed[s][i] = l.placement * Et;
                } else {
                    // Beyond the linear prefix the rotations do not change with the slides: track the real frame
                    // for the component errors of rotary axes (their own motion is applied where used).
                    preal = preal * l.placement * E;
                    plan.placed[s][i] = l.placement * E;
                }
                if (l.kind == AxisKind::Rotary) rotarySeen = true;
            }
            if (lastLinear[s] < 0) continue;
            // Fold what the slides' rotations do to everything they carry (exact pose, at zero commands).
            Pose preal0 = Pose::Identity(), pctl0 = Pose::Identity();
            // At the controller's zero: every slide at its machine zero (the chain's axis elements carry that offset).
            for (int i = 0; i <= lastLinear[s]; ++i) {
                const Link& l = c.links[i];
                const Vec6 e = linkLocationError(m, d.values, side, i);
                const Pose zero = translation(l.direction * (l.kind == AxisKind::Linear ? l.machineZero : 0.0));
                preal0 = preal0 * l.placement * errorTransform(e) * zero;
                pctl0 = pctl0 * l.placement * translation(e.head<3>()) * zero;
            }
            const Pose fold = pctl0.inverse(Eigen::Isometry) * preal0;
            const int p = lastLinear[s] + 1;
            if (p < static_cast<int>(c.links.size()))
                plan.placed[s][p] = fold * plan.placed[s][p];
            else
                plan.end[s] = fold;
        }
    }

    EquidistantTable& cec(int input, int output, const EquidistantTable& grid, const std::string& source) {
        const auto key = std::make_pair(input, output);
        auto it = cecIndex.find(key);
        if (it == cecIndex.end()) {
            CecTable t;
            t.input = input;
            t.output = output;
            t.table = grid;
            std::fill(t.table.values.begin(), t.table.values.end(), 0.0);
            plan.cec.push_back(std::move(t));
            it = cecIndex.emplace(key, plan.cec.size() - 1).first;
        }
        addUnique(plan.cec[it->second].sources, source);
        return plan.cec[it->second].table;
    }

    EquidistantTable& eec(int axis, const EquidistantTable& grid, const std::string& source) {
        auto it = eecIndex.find(axis);
        if (it == eecIndex.end()) {
            EecTable t;
            t.axis = axis;
            t.table = grid;
            std::fill(t.table.values.begin(), t.table.values.end(), 0.0);
            plan.eec.push_back(std::move(t));
            it = eecIndex.emplace(axis, plan.eec.size() - 1).first;
        }
        addUnique(plan.eec[it->second].sources, source);
        return plan.eec[it->second].table;
    }

    std::vector<int> linearAxes() const {
        std::vector<int> out;
        for (int a : controllerAxisOrder(m))
            if (isLinear(a)) out.push_back(a);
        return out;
    }

    void squareness() {
        // Slide j moves along real[j]; the controller's chain has it along ctl[j]. The trims on the other
        // slides k make the relative motion follow the controller's: slope_jk = σk σj ctl_k·(ctl_j − real_j).
        const auto lin = linearAxes();
        for (int j : lin) {
            const Link& lj = m.axisLink(j);
            for (int k : lin) {
                if (k == j) continue;
                const double slope = sigma[k] * sigma[j] * ctl[k].dot(ctl[j] - real[j]);
                EquidistantTable grid;
                try {
                    grid = gridOverTravel(lj, o.tablePoints);
                } catch (const ModelError&) {
                    continue;  // reported with the deviations below
                }
                const double span = std::max(std::abs(grid.min), std::abs(grid.max()));
                if (!(std::abs(slope) * span >= kNegligible)) continue;
                std::vector<std::string> names;
                for (const auto& def : m.deviations) {
                    const int di = static_cast<int>(&def - m.deviations.data());
                    if (def.kind != DeviationKind::Location || !def.isAngle() || !d.present[di]) continue;
                    if (def.link <= lastLinear[sideIndex(def.side)]) names.push_back(def.name);
                }
                EquidistantTable& t = cec(j, k, grid, names.empty() ? "squareness" : joined(names, "/"));
                for (size_t n = 0; n < t.values.size(); ++n) t.values[n] += slope * (grid.min + grid.step * n);
            }
        }
    }

    // Returns the coverage note, or an empty string (with `why` set) when not compensated.
    std::string component(int di, std::string& why) {
        const DeviationDef& def = m.deviations[di];
        const Link& l = m.chain(def.side).links[def.link];
        const int j = l.axisIndex;
        const double* coef = d.values.data() + def.offset;
        const auto err = [&](double q) { return def.basis.evaluate(q, coef, l.modulo); };
        EquidistantTable grid;
        try {
            grid = gridOverTravel(l, o.tablePoints);
        } catch (const ModelError& e) {
            why = e.what();
            return {};
        }
        if (grid.modulo && std::abs(err(l.machineZero) - err(l.machineZero + 2 * kPi)) > 1e-9) {
            why = "not periodic over one revolution: a modulo table must close on itself";
            return {};
        }
        const int c = def.component;
        const Vec3 unitLocal = Vec3::Unit(c % 3);
        const auto lin = linearAxes();
        std::vector<std::string> used;
        if (c >= 3) {
            const double along = unitLocal.dot(l.direction);
            if (l.kind == AxisKind::Rotary && std::abs(std::abs(along) - 1.0) < 1e-9) {
                EquidistantTable& t = eec(j, grid, def.name);
                for (size_t n = 0; n < t.values.size(); ++n)
                    t.values[n] += along * err(commandOf(l, grid.min + grid.step * n)) / kDeg;
                return fmt::format("EEC table of {} (positioning error of the rotary axis)", axisName(m, j));
            }
            why = l.kind == AxisKind::Linear
                      ? "angular error of a linear axis: its effect depends on the tool offset (Abbe); needs VCS "
                        "volumetric compensation, whose file format is not public"
                      : "tilt (wobble) error of a rotary axis: needs VCS volumetric compensation (format not public)";
            return {};
        }
        if (l.kind == AxisKind::Rotary && rotaryUpstream[j]) {
            why = "radial/axial error of a rotary axis carried by another rotary axis: a function of two axes, "
                  "which a CEC table (one input) cannot hold";
            return {};
        }
        for (int k : lin) {
            std::vector<double> vals(grid.values.size());
            double peak = 0;
            for (size_t n = 0; n < vals.size(); ++n) {
                const double q = commandOf(l, grid.min + grid.step * n);
                const Mat3 r = l.kind == AxisKind::Rotary ? Mat3(frame[j] * axisRotation(l.direction, q)) : frame[j];
                const Vec3 rel = sigma[j] * (r * unitLocal) * err(q);  // tool relative to workpiece, bed frame
                const double trim = -sigma[k] * ctl[k].dot(rel);
                vals[n] = trim;
                peak = std::max(peak, std::abs(trim));
            }
            if (!(peak >= kNegligible)) continue;
            if (k == j) {
                EquidistantTable& t = eec(j, grid, def.name);
                for (size_t n = 0; n < vals.size(); ++n) t.values[n] -= vals[n];  // EEC holds the error
                used.push_back(fmt::format("EEC {}", axisName(m, j)));
            } else {
                EquidistantTable& t = cec(j, k, grid, def.name);
                for (size_t n = 0; n < vals.size(); ++n) t.values[n] += vals[n];
                used.push_back(fmt::format("CEC {}->{}", axisName(m, j), axisName(m, k)));
            }
        }
        if (used.empty()) {
            why = "no linear axis moves along this error";
            return {};
        }
        return joined(used);
    }

    void coverage() {
        for (size_t di = 0; di < m.deviations.size(); ++di) {
            if (!d.present[di]) continue;
            const DeviationDef& def = m.deviations[di];
            const Link& l = m.chain(def.side).links[def.link];
            const std::string linkName =
                l.axisIndex >= 0 ? fmt::format("{} ({})", l.name, axisName(m, l.axisIndex)) : l.name;
            if (def.kind == DeviationKind::Location) {
                if (def.isAngle() && def.link <= lastLinear[sideIndex(def.side)])
                    plan.compensated.push_back({def.name, "squareness: CEC straight lines (output = slope x input) and "
                                                          "the carried head/table orientation in the kinematic chain"});
                else
                    plan.compensated.push_back(
                        {def.name, fmt::format("kinematic chain ($NK_ element{} of {})",
                                               def.isAngle() ? " ROT_CONST/$NK_A_OFF" : " OFFSET", linkName)});
                continue;
            }
            std::string why;
            const std::string note = component(static_cast<int>(di), why);
            if (note.empty())
                plan.notCompensated.push_back({def.name, why});
            else
                plan.compensated.push_back({def.name, note});
        }
    }

    void limits() const {
        if (static_cast<int>(plan.cec.size()) > o.cecMaxTables)
            throw ModelError(fmt::format("siemens-840d: {} CEC tables needed, the NCK holds {}", plan.cec.size(),
                                         o.cecMaxTables));
        for (const CecTable& t : plan.cec) {
            const auto n = t.table.values.size();
            if (static_cast<int>(n) > o.cecMaxPoints)
                throw ModelError(fmt::format("siemens-840d: CEC table {}->{}: (MAX-MIN)/STEP+1 = {} points exceed "
                                             "MM_CEC_MAX_POINTS = {}",
                                             axisName(m, t.input), axisName(m, t.output), n, o.cecMaxPoints));
        }
        for (const EecTable& t : plan.eec)
            if (static_cast<int>(t.table.values.size()) > o.eecMaxPoints)
                throw ModelError(fmt::format("siemens-840d: EEC table of {}: {} points exceed MM_ENC_COMP_MAX_POINTS = {}",
                                             axisName(m, t.axis), t.table.values.size(), o.eecMaxPoints));
    }
};

}  // namespace

Plan makePlan(const MachineModel& m, const DeviationSet& d, const Options& o) {
    d.requireMachine(m);
    if (!d.values.allFinite()) throw ModelError("the deviation set holds a value that is not a finite number");
    Builder b(m, d, o);
    b.chains();
    b.squareness();
    b.coverage();
    b.limits();
    return std::move(b.plan);
}

}  // namespace cnccomp::controllers::siemens

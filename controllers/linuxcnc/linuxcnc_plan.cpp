#include "controllers/linuxcnc/linuxcnc_plan.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/linuxcnc/comp_table.hpp"

namespace cnccomp::controllers::linuxcnc {
namespace {

constexpr double kAligned = 1.0 - 1e-12;

/// k (0..2) when the unit vector is ±e_k, else -1.
int alignedComponent(const Vec3& d) {
    for (int k = 0; k < 3; ++k)
        if (std::abs(d[k]) >= kAligned) return k;
    return -1;
}

bool isIdentityRotation(const Pose& p) { return (p.linear() - Mat3::Identity()).cwiseAbs().maxCoeff() < 1e-12; }

/// Index of the first rotary link of a chain, or the chain length.
int firstRotary(const Chain& c) {
    for (int i = 0; i < static_cast<int>(c.links.size()); ++i)
        if (c.links[i].kind == AxisKind::Rotary) return i;
    return static_cast<int>(c.links.size());
}

/// Rotation of the frame in which link i's location error is expressed (nominal placements only).
Mat3 errorFrame(const Chain& c, int i) {
    Mat3 r = Mat3::Identity();
    for (int k = 0; k <= i; ++k) r = r * c.links[k].placement.linear();
    return r;
}

/// Workpiece-chain indices of the tilt and C links of a trt machine.
std::pair<int, int> trtLinks(const MachineModel& m) {
    int tilt = -1, c = -1;
    const auto& l = m.workpiece.links;
    for (int i = 0; i < static_cast<int>(l.size()); ++i) {
        if (l[i].kind != AxisKind::Rotary) continue;
        (tilt < 0 ? tilt : c) = i;
    }
    return {tilt, c};
}

std::string describeUnit(bool rotary) { return rotary ? "deg" : "mm"; }

}  // namespace

std::vector<int> linuxcncJointOrder(const MachineModel& m) {
    std::vector<int> out;
    for (char letter : std::string("XYZABCUVW"))
        if (const int a = m.axisIndex(std::string(1, letter)); a >= 0) out.push_back(a);
    for (int a = 0; a < m.axisCount(); ++a)
        if (std::find(out.begin(), out.end(), a) == out.end()) out.push_back(a);
    return out;
}

std::optional<TrtType> matchTrt(const MachineModel& m) {
    // Workpiece chain: exactly two rotary links (A about +X or B about +Y, then C about +Z), no linear ones.
    // Tool chain: exactly the three linear slides along ±X ±Y ±Z, tool along −Z. No rotated placements.
    int rot = 0;
    for (const Link& l : m.workpiece.links) {
        if (l.kind == AxisKind::Linear || !isIdentityRotation(l.placement)) return std::nullopt;
        if (l.kind == AxisKind::Rotary) ++rot;
    }
    if (rot != 2) return std::nullopt;
    int lin = 0, dirs = 0;
    for (const Link& l : m.tool.links) {
        if (l.kind == AxisKind::Rotary || !isIdentityRotation(l.placement)) return std::nullopt;
        if (l.kind == AxisKind::Linear) {
            const int k = alignedComponent(l.direction);
            if (k < 0 || l.direction[k] < 0) return std::nullopt;
            dirs |= 1 << k;
            ++lin;
        }
    }
    if (lin != 3 || dirs != 7 || (m.toolDirection - Vec3(0, 0, -1)).norm() > 1e-12) return std::nullopt;
    const auto [tilt, c] = trtLinks(m);
    const Link &lt = m.workpiece.links[tilt], &lc = m.workpiece.links[c];
    // A table-table machine whose axes turn the other way is not one of LinuxCNC's trt modules, and trivkins would
    // replace the user's tool-tip kinematics in [KINS]: refuse it by name.
    const auto refuse = [&](const Link& l, const char* axis, const char* want) {
        throw ModelError(fmt::format("{}: rotary axis {} turns about {}: LinuxCNC's {} turns it about {} (trtfuncs.c), and the "
                                     "pins route has no other table-table kinematics (trivkins would replace your tool-tip "
                                     "kinematics); use the component route (cnccomp emit --controller linuxcnc)",
                                     m.name, l.name, axis, lc.name == "C" && lt.name == "B" ? "xyzbc-trt-kins" : "xyzac-trt-kins",
                                     want));
    };
    const auto axisName = [](const Vec3& d) -> std::string {
        const int k = alignedComponent(d);
        return k < 0 ? fmt::format("({:.3f}, {:.3f}, {:.3f})", d.x(), d.y(), d.z()) : fmt::format("{}{}", d[k] < 0 ? "-" : "+", "XYZ"[k]);
    };
    if (lc.name == "C" && (lc.direction - Vec3::UnitZ()).norm() > 1e-12 && alignedComponent(lc.direction) == 2)
        refuse(lc, axisName(lc.direction).c_str(), "+Z");
    if (lt.name == "A" && (lt.direction - Vec3::UnitX()).norm() > 1e-12 && alignedComponent(lt.direction) == 0)
        refuse(lt, axisName(lt.direction).c_str(), "+X");
    if (lt.name == "B" && (lt.direction - Vec3::UnitY()).norm() > 1e-12 && alignedComponent(lt.direction) == 1)
        refuse(lt, axisName(lt.direction).c_str(), "+Y");
    if ((lc.direction - Vec3::UnitZ()).norm() > 1e-12 || lc.name != "C") return std::nullopt;
    if ((lt.direction - Vec3::UnitX()).norm() < 1e-12 && lt.name == "A") return TrtType::AC;
    if ((lt.direction - Vec3::UnitY()).norm() < 1e-12 && lt.name == "B") return TrtType::BC;
    return std::nullopt;
}

namespace {

/// Translation of link i of the workpiece chain at rotary position 0: its placement plus, with a deviation set, its
/// translation location errors (the frames before it are unrotated on a trt machine).
Vec3 workpieceTranslation(const MachineModel& m, int i, const DeviationSet* d) {
    Vec3 t = m.workpiece.links[i].placement.translation();
    if (d)
        for (const DeviationDef& def : m.deviations)
            if (def.side == Side::Workpiece && def.link == i && def.kind == DeviationKind::Location && def.component < 3)
                t[def.component] += d->values[def.offset];
    return t;
}

/// T0: the nominal tool control point (tool length 0) in the bed frame at joint position 0 of every linear joint,
/// i.e. the origin of LinuxCNC's frame: the tool chain's fixed offsets plus each slide at its machine-zero.
Vec3 linuxcncOrigin(const MachineModel& m) {
    Vec3 t = Vec3::Zero();
    for (const Link& l : m.tool.links) {
        t += l.placement.translation();
        if (l.kind == AxisKind::Linear) t += l.direction * l.machineZero;
    }
    return t;
}

void requireRotaryZero(const MachineModel& m, int link, TrtType type) {
    const Link& l = m.workpiece.links[link];
    if (l.machineZero != 0.0)
        throw ModelError(fmt::format("{}: axis {} has machine-zero {} deg, but LinuxCNC's {} needs the {} joint to read 0 where "
                                     "the table is level and unturned (trtfuncs.c); home the joint there",
                                     m.name, l.name, l.machineZero / kDeg, trtModule(type), l.name));
}

}  // namespace

TrtPins trtPins(const MachineModel& m, TrtType type, const DeviationSet* d) {
    const auto [tilt, c] = trtLinks(m);
    requireRotaryZero(m, tilt, type);
    requireRotaryZero(m, c, type);
    Vec3 a = Vec3::Zero(), cc = Vec3::Zero();
    for (int i = 0; i <= c; ++i) (i <= tilt ? a : cc) += workpieceTranslation(m, i, d);
    // In the bed frame the tilt axis line passes through a, the C line (at tilt 0) through a + cc. trtfuncs.c's
    // inverse, J = r + D + R_tilt·(R_C·(p − r) − D), turns about the C line through r and the tilt line through
    // r + D (D = (0, y-offset, z-offset) for AC, (x-offset, 0, z-offset) for BC): so r = a + cc − T0 in LinuxCNC's
    // frame, and D = −cc (its component along the tilt axis does not matter).
    const Vec3 r = a + cc - linuxcncOrigin(m);
    TrtPins p;
    p.xRotPoint = r.x();
    p.yRotPoint = r.y();
    p.zRotPoint = r.z();
    if (type == TrtType::AC) p.yOffset = -cc.y();
    else p.xOffset = -cc.x();
    p.zOffset = -cc.z();
    return p;
}

Vec3 trtWorkOffset(const MachineModel& m, const DeviationSet* d) {
    Vec3 o = Vec3::Zero();
    for (int i = 0; i < static_cast<int>(m.workpiece.links.size()); ++i) o += workpieceTranslation(m, i, d);
    return o - linuxcncOrigin(m);
}

LinuxcncPlan planLinuxcnc(const MachineModel& m, const DeviationSet& d) {
    LinuxcncPlan plan;
    for (int a : linuxcncJointOrder(m)) {
        const Link& l = m.axisLink(a);
        JointPlan j;
        j.axis = a;
        j.name = l.name;
        j.rotary = l.kind == AxisKind::Rotary;
        j.modulo = l.modulo;
        j.machineZero = l.machineZero;
        plan.coordinates += l.name;
        plan.joints.push_back(j);
    }
    const auto joint = [&](int axis) -> JointPlan& {
        for (JointPlan& j : plan.joints)
            if (j.axis == axis) return j;
        throw ModelError("internal: joint not found");
    };
    plan.trt = matchTrt(m);
    int trtLast = -1;
    if (plan.trt) {
        plan.nominalPins = trtPins(m, *plan.trt, nullptr);
        plan.pins = trtPins(m, *plan.trt, &d);
        plan.nominalWorkOffset = trtWorkOffset(m, nullptr);
        plan.workOffset = trtWorkOffset(m, &d);
        trtLast = trtLinks(m).second;
    }
    const std::string module = plan.trt ? trtModule(*plan.trt) : "trivkins";

    // Linear joints usable for constant shifts: linear links before any rotary link of their chain.
    std::vector<std::pair<int, Vec3>> shiftAxes;  // axis, effect on the tool relative to the workpiece per mm
    for (const Chain* c : {&m.workpiece, &m.tool}) {
        const int fr = firstRotary(*c);
        for (int i = 0; i < fr; ++i) {
            const Link& l = c->links[i];
            if (l.kind != AxisKind::Linear) continue;
            const Vec3 u = (errorFrame(*c, i) * l.direction).normalized();
            shiftAxes.emplace_back(l.axisIndex, c->side == Side::Tool ? u : Vec3(-u));
        }
    }
    Eigen::Matrix<double, 3, Eigen::Dynamic> A(3, static_cast<int>(shiftAxes.size()));
    for (size_t k = 0; k < shiftAxes.size(); ++k) A.col(static_cast<int>(k)) = shiftAxes[k].second;
    const bool canShift = shiftAxes.size() >= 3 && Eigen::FullPivLU<Eigen::MatrixXd>(A).rank() == 3;
    std::string shiftNames;
    for (const auto& [axis, u] : shiftAxes) shiftNames += m.axisNames[axis];

    Vec3 shift = Vec3::Zero();  // wanted correction of the tool relative to the workpiece, bed frame
    for (size_t k = 0; k < m.deviations.size(); ++k) {
        if (!d.present[k]) continue;
        const DeviationDef& def = m.deviations[k];
        const Chain& c = m.chain(def.side);
        const Link& l = c.links[def.link];
        const auto yes = [&](std::string note) { plan.compensated.push_back({def.name, std::move(note)}); };
        const auto no = [&](std::string note) { plan.notCompensated.push_back({def.name, std::move(note)}); };
        if (def.kind == DeviationKind::Component) {
            const int k3 = alignedComponent(l.direction);
            const bool own = k3 >= 0 && def.component == (l.kind == AxisKind::Rotary ? 3 + k3 : k3);
            if (own) {
                joint(l.axisIndex).components.push_back({static_cast<int>(k), l.direction[k3]});
                yes(fmt::format("positioning error of {}: joint table {}.comp", l.name, l.name));
            } else {
                no(fmt::format("cross-axis component error of {}: a LinuxCNC joint table corrects a joint along itself only", l.name));
            }
            continue;
        }
        const double v = d.values[def.offset];
        if (def.isAngle()) {
            const int k3 = alignedComponent(l.direction);
            if (l.kind == AxisKind::Rotary && k3 >= 0 && def.component == 3 + k3) {
                joint(l.axisIndex).constantTrim -= l.direction[k3] * v;
                yes(fmt::format("zero position of {}: constant trim in {}.comp", l.name, l.name));
            } else if (l.kind == AxisKind::Fixed) {
                no(fmt::format("tilt of the fixed link {}: no LinuxCNC kinematics pin ({}) or table takes it", l.name, module));
            } else if (l.kind == AxisKind::Rotary) {
                no(fmt::format("orientation of the {} axis line: no LinuxCNC kinematics pin ({}) or table takes it", l.name, module));
            } else {
                no(fmt::format("squareness / angular error at {}: LinuxCNC has no cross-axis compensation", l.name));
            }
            continue;
        }
        // Translation location error.
        if (plan.trt && def.side == Side::Workpiece) {
            // Listed as NOT compensated: the test programs (and every joint-mode program) run with the identity
            // kinematics, where the pins and the G54 do nothing (linuxcnc_apply.hpp).
            if (def.link <= trtLast)
                no(fmt::format("{} position of the {} axis line: {} HAL pins (rot-point / offset); joint-mode programs (cnccomp "
                               "testprog's) do not get it",
                               kToolTipModeOnly, l.name, module));
            else
                no(fmt::format("{} position of the workpiece origin on the table ({}): G54 of cnccomp-g54.ngc; joint-mode "
                               "programs do not get it",
                               kToolTipModeOnly, l.name));
            continue;
        }
        if (def.link <= firstRotary(c)) {
            if (!canShift) {
                no(fmt::format("offset at {}: needs three linear joints before the rotary axes to shift", l.name));
                continue;
            }
            Vec3 e = Vec3::Zero();
            e[def.component] = v;
            const Vec3 vb = errorFrame(c, def.link) * e;
            shift += def.side == Side::Tool ? Vec3(-vb) : vb;
            yes(fmt::format("offset at {} (before any rotary axis): constant trims of joints {}", l.name, shiftNames));
            continue;
        }
        no(fmt::format("offset behind a rotary axis at {}: no pin of the LinuxCNC kinematics ({}) takes it", l.name, module));
    }
    if (shift.norm() > 0) {
        const Eigen::VectorXd t = A.colPivHouseholderQr().solve(shift);
        for (size_t k = 0; k < shiftAxes.size(); ++k) joint(shiftAxes[k].first).constantTrim += t[static_cast<int>(k)];
    }
    for (const JointPlan& j : plan.joints) {
        const double limit = j.rotary ? 5.0 * kDeg : 5.0;
        if (std::abs(j.constantTrim) > limit)
            throw ModelError(fmt::format("joint {}: constant trim {:.4f} {} exceeds the ±5 {} sanity limit (check the deviation units)",
                                         j.name, j.constantTrim / (j.rotary ? kDeg : 1.0), describeUnit(j.rotary),
                                         describeUnit(j.rotary)));
    }
    return plan;
}

double jointTrim(const MachineModel& m, const DeviationSet& d, const JointPlan& j, double p) {
    double q = p + j.constantTrim;
    for (int it = 0; it < 8; ++it) {
        double e = 0;
        for (const OwnComponent& c : j.components) {
            const DeviationDef& def = m.deviations[c.deviation];
            e += c.sign * def.basis.evaluate(q, d.values.data() + def.offset, j.modulo);
        }
        q = p + j.constantTrim - e;
    }
    return q - p;
}

std::vector<double> tableNodes(const MachineModel& m, const JointPlan& j) {
    const Link& l = m.axisLink(j.axis);
    const double unit = j.rotary ? kDeg : 1.0;
    if (!std::isfinite(l.min) || !std::isfinite(l.max) || !(l.max > l.min))
        throw ModelError(fmt::format("{}: axis {} has no finite travel (min/max): LinuxCNC looks a compensation table up at the raw "
                                     "joint position (no modulo), so the table must cover the joint's travel",
                                     m.name, l.name));
    bool allTables = true;
    std::set<double> s{l.min, l.max};
    const double period = 2 * kPi;
    for (const OwnComponent& c : j.components) {
        const ComponentBasis& b = m.deviations[c.deviation].basis;
        if (b.type != ComponentBasis::Type::Table) allTables = false;
        for (double n : b.nodes) {
            if (!j.modulo) {
                if (n > l.min && n < l.max) s.insert(n);
                continue;
            }
            // A modulo table repeats every turn: its breakpoints come back at n + k·360°.
            for (double k = std::ceil((l.min - n) / period); n + k * period < l.max; ++k)
                if (n + k * period > l.min) s.insert(n + k * period);
            if (s.size() > static_cast<size_t>(kMaxCompLines)) break;
        }
    }
    if (!j.components.empty() && (!allTables || s.size() > static_cast<size_t>(kMaxCompLines))) {
        s = {l.min, l.max};
        if (j.modulo) {
            // Equidistant at a spacing that divides 360°, aligned to multiples of it: every turn gets the same points.
            static constexpr double kDivisors[] = {0.25, 0.5, 1, 1.5, 2, 2.5, 3, 4, 5, 6, 7.5, 8, 9, 10, 12, 15, 18, 20, 22.5,
                                                   24, 30, 36, 40, 45, 60, 72, 90, 120, 180, 360};
            for (double deg : kDivisors) {
                const double h = deg * kDeg;
                const double first = std::ceil(l.min / h), last = std::floor(l.max / h);
                if (last - first + 3 > kMaxCompLines) continue;
                for (double k = first; k <= last; ++k) s.insert(k * h);
                break;
            }
        } else {
            for (int i = 1; i + 1 < kMaxCompLines; ++i) s.insert(l.min + (l.max - l.min) * i / (kMaxCompLines - 1));
        }
    }
    std::vector<double> out;
    // Nodes closer than 1e-6 mm / deg would print as the same nominal: keep the first.
    for (double u : s)
        if (out.empty() || u - out.back() > 1e-6 * unit) out.push_back(u);
    if (out.back() != l.max) out.back() = l.max;
    return out;
}

}  // namespace cnccomp::controllers::linuxcnc

#include "controllers/fanuc/tcp_parameters.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/fanuc/pitch_error.hpp"

namespace cnccomp::controllers::fanuc {
using namespace cnccomp::controllers::common;
namespace {

constexpr int kDecimals = 4;  // IS-C: 0.0001 mm / 0.0001 deg [G]

struct Walk {
    std::vector<Vec3> point, dir;
    Vec3 end = Vec3::Zero();
    Mat3 endRot = Mat3::Identity();
};

/// Chain at the controller's zero (every axis at its machine zero: the description's command Link::machineZero), with
/// the translation part of the location errors only, and each linear axis' positioning error at its machine zero (the
/// value the pitch table leaves, zero at the reference position: a constant offset of everything the axis carries).
/// Points and directions are those of each axis line.
Walk walk(const MachineModel& m, const Eigen::VectorXd& values, Side side) {
    const Chain& c = m.chain(side);
    Walk w;
    w.point.assign(c.links.size(), Vec3::Zero());
    w.dir.assign(c.links.size(), Vec3::Zero());
    Pose p = Pose::Identity();
    for (size_t i = 0; i < c.links.size(); ++i) {
        const Link& l = c.links[i];
        Pose t = Pose::Identity();
        t.translation() = linkLocationError(m, values, side, static_cast<int>(i)).head<3>();
        p = p * l.placement * t;
        w.point[i] = p.translation();
        w.dir[i] = p.linear() * l.direction;
        if (l.kind == AxisKind::Linear)
            p.translation() += p.linear() * l.direction * (l.machineZero + positioningError(m, values, l.axisIndex, l.machineZero));
        if (l.kind == AxisKind::Rotary) p.linear() = p.linear() * axisRotation(l.direction, l.machineZero);
    }
    w.end = p.translation();
    w.endRot = p.linear();
    return w;
}

RotaryParameter rotaryOf(const MachineModel& m, const Link& l, const Vec3& dir) {
    RotaryParameter r;
    r.axis = l.axisIndex;
    for (int k = 0; k < 3; ++k)
        for (int s = 0; s < 2; ++s)
            if ((dir - (s == 0 ? 1.0 : -1.0) * Vec3::Unit(k)).norm() < 1e-9) {
                r.direction = k + 1;
                r.sense = s;
                return r;
            }
    throw ModelError(fmt::format("fanuc-30i: rotary axis {} of machine '{}' does not turn about X, Y or Z", l.name, m.name));
}

Parameter path(int number, const std::string& v) {
    Parameter p;
    p.number = number;
    p.kind = 'L';
    p.values[1] = v;
    return p;
}

Vec3 unitOf(const RotaryParameter& r) { return (r.sense == 0 ? 1.0 : -1.0) * Vec3::Unit(r.direction - 1); }

Pose shift(const Vec3& v) {
    Pose p = Pose::Identity();
    p.translation() = v;
    return p;
}

}  // namespace

TcpParameters tcpFromMachine(const MachineModel& m, const Eigen::VectorXd& values) {
    std::vector<int> toolRot, wpRot;
    bool rotarySeen = false;
    for (size_t i = 0; i < m.tool.links.size(); ++i) {
        const Link& l = m.tool.links[i];
        if (l.kind == AxisKind::Rotary) {
            toolRot.push_back(static_cast<int>(i));
            rotarySeen = true;
        } else if (l.kind == AxisKind::Linear && rotarySeen) {
            throw ModelError(fmt::format("fanuc-30i: linear axis {} is carried by a rotary axis; the TCP wants the linear axes first", l.name));
        }
    }
    for (size_t i = 0; i < m.workpiece.links.size(); ++i) {
        const Link& l = m.workpiece.links[i];
        if (l.kind == AxisKind::Linear)
            throw ModelError(fmt::format("fanuc-30i: linear axis {} moves the workpiece; the TCP parameters describe linear axes "
                                         "that move the tool", l.name));
        if (l.kind == AxisKind::Rotary) wpRot.push_back(static_cast<int>(i));
    }
    if (toolRot.size() + wpRot.size() > 2 || (toolRot.size() == 2 && !wpRot.empty()))
        throw ModelError(fmt::format("fanuc-30i: machine '{}' has {} rotary axes; the 30i TCP takes two", m.name,
                                     toolRot.size() + wpRot.size()));
    const Walk tw = walk(m, values, Side::Tool), ww = walk(m, values, Side::Workpiece);
    TcpParameters p;
    const Vec3 tool = tw.endRot * m.toolDirection;
    p.toolAxis = 0;
    for (int k = 0; k < 3; ++k)
        if ((tool + Vec3::Unit(k)).norm() < 1e-9) p.toolAxis = k + 1;
    if (p.toolAxis == 0)
        throw ModelError("fanuc-30i: at the controller's zero the tool must point to -X, -Y or -Z (reference tool axis direction 19697)");
    RotaryParameter hypothetical;
    hypothetical.axis = -1;
    const Vec3 D = tw.end;
    Vec3 c0 = D;
    if (!toolRot.empty() && wpRot.empty()) {
        p.type = 2;
        const Vec3 F = tw.point[toolRot[0]];
        p.rotary[0] = rotaryOf(m, m.tool.links[toolRot[0]], tw.dir[toolRot[0]]);
        Vec3 E = F;
        if (toolRot.size() == 2) {
            E = tw.point[toolRot[1]];
            p.rotary[1] = rotaryOf(m, m.tool.links[toolRot[1]], tw.dir[toolRot[1]]);
        } else {
            p.rotary[1] = hypothetical;
        }
        p.toolIntersection = F - E;
        p.toolOffset = E - D;
        c0 = F;
    } else if (toolRot.size() == 1 && wpRot.size() == 1) {
        p.type = 21;
        const Vec3 E = tw.point[toolRot[0]];
        p.rotary[0] = rotaryOf(m, m.tool.links[toolRot[0]], tw.dir[toolRot[0]]);
        p.rotary[1] = rotaryOf(m, m.workpiece.links[wpRot[0]], ww.dir[wpRot[0]]);
        p.toolOffset = E - D;
        c0 = E;
        p.tablePosition = ww.point[wpRot[0]] - c0;
    } else if (!wpRot.empty()) {
        p.type = 12;
        p.rotary[0] = rotaryOf(m, m.workpiece.links[wpRot[0]], ww.dir[wpRot[0]]);
        p.tablePosition = ww.point[wpRot[0]] - c0;
        Vec3 B = p.tablePosition;
        if (wpRot.size() == 2) {
            p.rotary[1] = rotaryOf(m, m.workpiece.links[wpRot[1]], ww.dir[wpRot[1]]);
            B = ww.point[wpRot[1]] - c0;
        } else {
            p.rotary[1] = hypothetical;
        }
        p.tableOffset = B - p.tablePosition;
    }
    p.workZero = ww.end - c0;
    return p;
}

std::vector<Parameter> tcpLines(const MachineModel& m, const TcpParameters& p) {
    std::vector<Parameter> out;
    const auto vec = [&](int first, const Vec3& v) {
        for (int k = 0; k < 3; ++k) out.push_back(path(first + k, decimal(v[k], kDecimals)));
    };
    out.push_back(path(19680, std::to_string(p.type)));
    if (p.type != 0) {
        for (int r = 0; r < 2; ++r) {
            const RotaryParameter& a = p.rotary[r];
            const int base = r == 0 ? 19681 : 19686;
            out.push_back(path(base, std::to_string(a.axis < 0 ? 0 : controllerAxisNumber(m, a.axis))));
            out.push_back(path(base + 1, std::to_string(a.direction)));
            out.push_back(path(base + 3, std::to_string(a.sense)));
            if (a.axis < 0) out.push_back(path(base + 4, decimal(a.angleDeg, kDecimals)));
        }
        std::string bits = "000000";
        bits += p.rotary[1].axis < 0 ? '1' : '0';
        bits += p.rotary[0].axis < 0 ? '1' : '0';
        out.push_back(path(19696, bits));
    }
    out.push_back(path(19697, std::to_string(p.toolAxis)));
    if (p.type == 12 || p.type == 21) vec(19700, p.tablePosition);
    if (p.type == 12) vec(19703, p.tableOffset);
    if (p.type == 2 || p.type == 21) {
        vec(19709, p.toolOffset);
        if (p.type == 2) vec(19712, p.toolIntersection);
        out.push_back(path(19666, decimal(0.0, kDecimals)));
    }
    std::sort(out.begin(), out.end(), [](const Parameter& a, const Parameter& b) { return a.number < b.number; });
    Parameter w;
    w.number = 1220;
    w.kind = 'A';
    for (int a : controllerAxisOrder(m))
        if (m.axisLink(a).kind == AxisKind::Linear)
            w.values[controllerAxisNumber(m, a)] = decimal(p.workZero.dot(m.nominalDirection(a)), kDecimals);
    if (!w.values.empty()) out.insert(out.begin(), w);
    return out;
}

TcpParameters tcpFromFile(const MachineModel& m, const ParameterFile& f) {
    TcpParameters p;
    const auto line = [&](int n) {
        const Parameter* q = f.find(n);
        return q ? q->line : 0;
    };
    const auto whole = [&](int n, double lo, double hi, double fallback) {
        const double v = value(f, n, 1, fallback);
        if (v != std::floor(v) || v < lo || v > hi)
            throw InputError(f.path, line(n), fmt::format("parameter {}: {} is not a whole number {}..{}", n, v, lo, hi));
        return static_cast<int>(v);
    };
    p.type = static_cast<int>(required(f, 19680, 1));
    if (p.type != 0 && p.type != 2 && p.type != 12 && p.type != 21)
        throw InputError(f.path, line(19680), fmt::format("parameter 19680: machine type {} is not 0, 2, 12 or 21", p.type));
    const double bitsValue = value(f, 19696, 1, 0.0);
    const Parameter* bitsParam = f.find(19696);
    const std::string bits = bitsParam && bitsParam->values.count(1) ? bitsParam->values.at(1) : "0";
    (void)bitsValue;
    for (char c : bits)
        if (c != '0' && c != '1') throw InputError(f.path, line(19696), "parameter 19696 is a bit parameter (digits 0 and 1)");
    const auto bit = [&](int b) { return bits.size() > static_cast<size_t>(b) && bits[bits.size() - 1 - b] == '1'; };
    if (p.type != 0) {
        for (int r = 0; r < 2; ++r) {
            const int base = r == 0 ? 19681 : 19686;
            RotaryParameter& a = p.rotary[r];
            a.direction = whole(base + 1, 1, 3, -1);
            a.sense = whole(base + 3, 0, 1, 0);
            if (bit(r)) {
                a.axis = -1;
                a.angleDeg = value(f, base + 4, 1, 0.0);
                continue;
            }
            const int number = whole(base, 1, 32, -1);
            a.axis = machineAxisOfNumber(m, number);
            if (a.axis < 0 || m.axisLink(a.axis).kind != AxisKind::Rotary)
                throw InputError(f.path, line(base), fmt::format("parameter {}: axis {} is not a rotary axis of machine '{}'", base, number, m.name));
            const Side side = m.axisSide(a.axis);
            const bool toolSide = p.type == 2 || (p.type == 21 && r == 0);
            if ((side == Side::Tool) != toolSide)
                throw InputError(f.path, line(base), fmt::format("parameter {}: axis {} turns the {}, but machine type {} wants a {} rotary axis here",
                                                                 base, m.axisNames[a.axis], side == Side::Tool ? "tool" : "table",
                                                                 p.type, toolSide ? "tool" : "table"));
        }
        if (p.rotary[0].axis < 0) throw InputError(f.path, line(19696), "the first rotary axis cannot be hypothetical here");
        if (p.type == 21 && p.rotary[1].axis < 0) throw InputError(f.path, line(19696), "type 21 needs two real rotary axes");
    }
    p.toolAxis = whole(19697, 1, 3, 3);
    const auto vec = [&](int first) {
        return Vec3(required(f, first, 1), required(f, first + 1, 1), required(f, first + 2, 1));
    };
    if (p.type == 12 || p.type == 21) p.tablePosition = vec(19700);
    if (p.type == 12) p.tableOffset = vec(19703);
    if (p.type == 2 || p.type == 21) p.toolOffset = vec(19709);
    if (p.type == 2) p.toolIntersection = vec(19712);
    if (value(f, 19666, 1, 0.0) != 0.0)
        throw InputError(f.path, line(19666), "parameter 19666 (tool holder offset) other than 0 is not modelled");
    for (int a : controllerAxisOrder(m))
        if (m.axisLink(a).kind == AxisKind::Linear)
            p.workZero += value(f, 1220, controllerAxisNumber(m, a), 0.0) * m.nominalDirection(a);
    return p;
}

void tcpChains(const MachineModel& m, const TcpParameters& p, std::vector<ChainElement>& workpiece,
               std::vector<ChainElement>& tool) {
    // The controller's zero: machine coordinates 0, i.e. the description's commands at the machine zeros.
    const Kinematics nominal(m);
    const AxisVector zero = m.fromController(AxisVector::Zero(m.axisCount()));
    const auto rotation = [](const Mat3& r) {
        Pose q = Pose::Identity();
        q.linear() = r;
        return ChainElement::constant(q);
    };
    const auto rotary = [&](const RotaryParameter& a, std::vector<ChainElement>& out) {
        if (a.axis < 0) out.push_back(rotation(axisRotation(unitOf(a), a.angleDeg * kDeg)));
        else out.push_back(ChainElement::motion(a.axis, unitOf(a)));
    };
    tool.clear();
    workpiece.clear();
    for (const Link& l : m.tool.links)
        if (l.kind == AxisKind::Linear) tool.push_back(ChainElement::motion(l.axisIndex, m.nominalDirection(l.axisIndex)));
    if (p.type == 2) {
        rotary(p.rotary[0], tool);
        tool.push_back(ChainElement::constant(shift(-p.toolIntersection)));
        rotary(p.rotary[1], tool);
        tool.push_back(ChainElement::constant(shift(-p.toolOffset)));
    } else if (p.type == 21) {
        rotary(p.rotary[0], tool);
        tool.push_back(ChainElement::constant(shift(-p.toolOffset)));
    }
    // Tool frame: the tool along the reference tool axis direction (19697), turned about it as nominally.
    const Vec3 want = -Vec3::Unit(p.toolAxis - 1);
    Mat3 r0 = nominal.baseToTool(zero).linear();
    if ((r0 * m.toolDirection - want).norm() > 1e-9) r0 = Eigen::Quaterniond::FromTwoVectors(m.toolDirection, want).toRotationMatrix();
    tool.push_back(rotation(r0));
    if (p.type == 12) {
        workpiece.push_back(ChainElement::constant(shift(p.tablePosition)));
        rotary(p.rotary[0], workpiece);
        workpiece.push_back(ChainElement::constant(shift(p.tableOffset)));
        rotary(p.rotary[1], workpiece);
        workpiece.push_back(ChainElement::constant(shift(p.workZero - p.tablePosition - p.tableOffset)));
    } else if (p.type == 21) {
        workpiece.push_back(ChainElement::constant(shift(p.tablePosition)));
        rotary(p.rotary[1], workpiece);
        workpiece.push_back(ChainElement::constant(shift(p.workZero - p.tablePosition)));
    } else {
        workpiece.push_back(ChainElement::constant(shift(p.workZero)));
    }
    // The workpiece coordinate system is turned as the nominal machine's (no parameter holds a rotation).
    workpiece.push_back(rotation(nominal.baseToWorkpiece(zero).linear()));
}

}  // namespace cnccomp::controllers::fanuc

#include "cnccomp/identification/dbb5_axis_line.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::identification {

namespace {

void checkAxisIndex(int along) {
    if (along < 0 || along > 2) throw ModelError(fmt::format("axis index {} is not 0 (X), 1 (Y) or 2 (Z)", along));
}

/// Rotation vector turning unit `from` onto `to` (exact, smallest rotation).
Vec3 rotationBetween(const Vec3& from, const Vec3& to) {
    const Vec3 c = from.cross(to);
    const double s = c.norm();
    if (s < 1e-300) return Vec3::Zero();
    return std::atan2(s, from.dot(to)) * c / s;
}

Dbb5AxisLine makeLine(const std::string& axis, int along) {
    checkAxisIndex(along);
    Dbb5AxisLine l;
    l.axis = axis;
    l.along = along;
    l.first = (along + 1) % 3;
    l.second = (along + 2) % 3;
    return l;
}

}  // namespace

std::string Dbb5AxisLine::positionName(int k) const { return fmt::format("E{}0{}", "XYZ"[k], axis); }
std::string Dbb5AxisLine::rotationName(int k) const { return fmt::format("E{}0{}", "ABC"[k], axis); }

double dbb5CentreShift(double meanRadialError, const Vec3& u, int e) {
    checkAxisIndex(e);
    const Vec3 n = u.normalized();
    if (!(std::abs(n[e]) > 0.5))
        throw ModelError(fmt::format("bar direction ({:g} {:g} {:g}) is not along machine axis {}", u.x(), u.y(), u.z(),
                                     "XYZ"[e]));
    return -meanRadialError / n[e];
}

Dbb5AxisLine axisLineFromShifts(const std::string& axis, int along, const Dbb5ShiftPair& first,
                                const Dbb5ShiftPair& second) {
    Dbb5AxisLine l = makeLine(axis, along);
    l.shiftFirst = first;
    l.shiftSecond = second;
    Vec3 lean = Vec3::Zero(), offset = Vec3::Zero();
    for (const auto& [k, p] : {std::pair<int, const Dbb5ShiftPair*>{l.first, &first}, {l.second, &second}}) {
        if (!(std::abs(p->s2 - p->s1) > 1e-9))
            throw ModelError(fmt::format("axis {}: the two runs along {} are at the same position", axis, "XYZ"[k]));
        lean[k] = (p->c2 - p->c1) / (p->s2 - p->s1);
        offset[k] = p->c1 - lean[k] * p->s1;
    }
    l.position = offset;
    const Vec3 e = Vec3::Unit(along);
    l.rotation = rotationBetween(e, (e + lean).normalized());
    return l;
}

Dbb5AxisLine axisLineFromGeometry(const std::string& axis, int along, const Vec3& point, const Vec3& direction) {
    Dbb5AxisLine l = makeLine(axis, along);
    Vec3 d = direction.normalized();
    if (d[along] < 0) d = -d;
    if (!(d[along] > 0.5))
        throw ModelError(fmt::format("axis {}: its line is far from machine axis {}", axis, "XYZ"[along]));
    l.position = point - (point[along] / d[along]) * d;
    l.position[along] = 0;
    l.rotation = rotationBetween(Vec3::Unit(along), d);
    return l;
}

Dbb5PaperInnerAxis paperInnerAxis(double rx1, double ry1, double rx2, double ry2, double Z1, double Z2) {
    if (!(std::abs(Z2 - Z1) > 1e-9)) throw ModelError("eq. (1)-(3): the two heights must differ");
    Dbb5PaperInnerAxis p;
    p.beta = (rx2 - rx1) / (Z2 - Z1);  // (1)
    p.alpha = (ry2 - ry1) / (Z2 - Z1);  // (2)
    p.dx = rx1 - p.beta * Z1;           // (3)
    p.dy = -ry1 + p.alpha * Z1;         // (3)
    return p;
}

Dbb5PaperOuterAxis paperOuterAxis(double rx1, double rz1, double rx2, double rz2, double y1, double y2) {
    if (!(std::abs(y2 - y1) > 1e-9)) throw ModelError("eq. (6)-(7): the two positions must differ");
    return {(rx2 - rx1) / (y2 - y1), -(rz2 - rz1) / (y2 - y1)};
}

Dbb5PaperTilt paperXycTilt(double dx, double dy, double R) {
    if (!(std::abs(R) > 1e-9)) throw ModelError("eq. (4)-(5): the radius R must not be zero");
    return {dx / R, -dy / R};
}

}  // namespace cnccomp::identification

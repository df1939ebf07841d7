#include "cnccomp/iso_names.hpp"

#include <array>
#include <cmath>
#include <cstring>
#include <optional>

#include <Eigen/LU>
#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp {
namespace {

using Rows = Eigen::Matrix<double, 3, Eigen::Dynamic>;
constexpr const char* kLetters = "XYZABC";

struct LinkRef {
    Side side = Side::Tool;
    int link = -1;
};

/// First-order displacement of every link frame (after its location error) as a linear function of the location
/// deviations: rotation W (3 × n) and displacement of the frame origin T (3 × n), bed frame, commands at zero.
struct FirstOrder {
    std::vector<Mat3> R[2];  ///< nominal rotation of each link's placed frame (before its location error)
    std::vector<Vec3> o[2];  ///< nominal origin of each link's placed frame
    std::vector<Rows> W[2], T[2];
};

int sideIndex(Side s) { return s == Side::Tool ? 1 : 0; }

FirstOrder firstOrder(const MachineModel& m, const std::vector<int>& column, int n) {
    FirstOrder f;
    for (Side side : {Side::Workpiece, Side::Tool}) {
        const int s = sideIndex(side);
        const Chain& c = m.chain(side);
        Pose frame = Pose::Identity();
        for (const Link& l : c.links) {
            frame = frame * l.placement;  // motion at zero commands is the identity
            f.R[s].push_back(frame.linear());
            f.o[s].push_back(frame.translation());
        }
        for (size_t j = 0; j < c.links.size(); ++j) {
            Rows W = Rows::Zero(3, n), T = Rows::Zero(3, n);
            for (size_t d = 0; d < m.deviations.size(); ++d) {
                const DeviationDef& def = m.deviations[d];
                if (column[d] < 0 || def.side != side || def.link > static_cast<int>(j)) continue;
                const Mat3& Ri = f.R[s][static_cast<size_t>(def.link)];
                const Vec3& oi = f.o[s][static_cast<size_t>(def.link)];
                if (def.component < 3) {
                    T.col(column[d]) += Ri.col(def.component);
                } else {
                    const Vec3 w = Ri.col(def.component - 3);
                    W.col(column[d]) += w;
                    T.col(column[d]) += w.cross(f.o[s][j] - oi);
                }
            }
            f.W[s].push_back(W);
            f.T[s].push_back(T);
        }
    }
    return f;
}

std::optional<LinkRef> findLink(const MachineModel& m, const std::string& name) {
    std::optional<LinkRef> found;
    for (Side side : {Side::Workpiece, Side::Tool}) {
        const Chain& c = m.chain(side);
        for (int i = 0; i < static_cast<int>(c.links.size()); ++i)
            if (c.links[static_cast<size_t>(i)].name == name) {
                if (found) return std::nullopt;  // ambiguous: not an ISO target
                found = LinkRef{side, i};
            }
    }
    return found;
}

/// A linear axis named X, Y or Z that moves along the matching coordinate axis (either sense).
std::optional<LinkRef> referenceAxis(const MachineModel& m, int k) {
    const std::optional<LinkRef> r = findLink(m, std::string(1, kLetters[k]));
    if (!r) return std::nullopt;
    const Link& l = m.chain(r->side).links[static_cast<size_t>(r->link)];
    if (l.kind != AxisKind::Linear) return std::nullopt;
    return r;
}

/// ISO name pattern E<letter>0<target>: letter index 0..5, target link name.
std::optional<std::pair<int, std::string>> parseName(const std::string& n) {
    if (n.size() < 4 || n[0] != 'E' || n[2] != '0') return std::nullopt;
    if (n[1] == '\0') return std::nullopt;
    const char* p = std::strchr(kLetters, n[1]);
    if (!p) return std::nullopt;
    return std::make_pair(static_cast<int>(p - kLetters), n.substr(3));
}

double clean(double c) {
    if (std::abs(c) < 1e-12) return 0.0;
    const double r = std::round(c);
    return std::abs(c - r) < 1e-9 * std::max(1.0, std::abs(c)) ? r : c;
}

}  // namespace

void deriveIsoMeaning(MachineModel& m) {
    const int count = static_cast<int>(m.deviations.size());
    std::vector<int> column(static_cast<size_t>(count), -1), owner;
    for (int d = 0; d < count; ++d)
        if (m.deviations[static_cast<size_t>(d)].kind == DeviationKind::Location) {
            column[static_cast<size_t>(d)] = static_cast<int>(owner.size());
            owner.push_back(d);
        }
    for (DeviationDef& d : m.deviations) d.isoTerms.clear(), d.linkTerms.clear();
    for (int d = 0; d < count; ++d)
        if (column[static_cast<size_t>(d)] < 0) {
            m.deviations[static_cast<size_t>(d)].isoTerms = {{d, 1.0}};
            m.deviations[static_cast<size_t>(d)].linkTerms = {{d, 1.0}};
        }
    const int n = static_cast<int>(owner.size());
    if (n == 0) return;
    const FirstOrder f = firstOrder(m, column, n);

    // Reference frame of the linear axes: its rotation Ω (3 × n) in the bed frame. Rotation about k is fixed by the
    // first linear axis of the pair for k whose tilt about k the machine does not declare as a squareness error.
    const auto declared = [&](int axis, int k) {
        const std::string name = fmt::format("E{}0{}", kLetters[3 + k], kLetters[axis]);
        for (const DeviationDef& d : m.deviations)
            if (d.kind == DeviationKind::Location && d.name == name) return true;
        return false;
    };
    const int pairs[3][2] = {{1, 2}, {0, 2}, {0, 1}};  // about x: Y then Z; about y: X then Z; about z: X then Y
    Rows omega = Rows::Zero(3, n);
    for (int k = 0; k < 3; ++k) {
        std::vector<int> taken;  // axes of the pair whose tilt about k is a declared squareness error
        for (int axis : pairs[k]) {
            const std::optional<LinkRef> r = referenceAxis(m, axis);
            if (!r) continue;
            if (declared(axis, k)) {
                taken.push_back(axis);
                continue;
            }
            omega.row(k) = f.W[sideIndex(r->side)][static_cast<size_t>(r->link)].row(k);
            taken.clear();
            break;
        }
        if (taken.size() == 2)
            throw ModelError(fmt::format(
                "machine '{}': both E{}0{} and E{}0{} are declared; ISO 230-1 has one squareness error per pair of "
                "linear axes (one of the two is the reference)",
                m.name, kLetters[3 + k], kLetters[taken[0]], kLetters[3 + k], kLetters[taken[1]]));
    }

    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, n);
    for (int row = 0; row < n; ++row) {
        const int d = owner[static_cast<size_t>(row)];
        const DeviationDef& def = m.deviations[static_cast<size_t>(d)];
        M(row, row) = 1.0;  // the link's own component unless the name says otherwise
        const auto parsed = parseName(def.name);
        if (!parsed) continue;
        const std::optional<LinkRef> target = findLink(m, parsed->second);
        if (!target) continue;
        const Chain& chain = m.chain(target->side);
        const Link& tl = chain.links[static_cast<size_t>(target->link)];
        if (tl.kind == AxisKind::Fixed) continue;
        const int s = sideIndex(target->side);
        const size_t j = static_cast<size_t>(target->link);
        int carrier = -1;
        for (int i = target->link - 1; i >= 0; --i)
            if (chain.links[static_cast<size_t>(i)].kind == AxisKind::Rotary) {
                carrier = i;
                break;
            }
        Rows w, t;
        if (carrier >= 0) {
            const size_t k = static_cast<size_t>(carrier);
            const Mat3 Rt = f.R[s][k].transpose();
            w = Rt * (f.W[s][j] - f.W[s][k]);
            t = Rt * (f.T[s][j] - f.T[s][k] + skew(f.o[s][j] - f.o[s][k]) * f.W[s][k]);
        } else {
            w = f.W[s][j] - omega;
            t = f.T[s][j] + skew(f.o[s][j]) * omega;
        }
        const int letter = parsed->first;
        for (int c = 0; c < n; ++c) M(row, c) = clean(letter < 3 ? t(letter, c) : w(letter - 3, c));
    }

    for (int row = 0; row < n; ++row)
        if (M.row(row).cwiseAbs().maxCoeff() == 0.0) {
            const DeviationDef& def = m.deviations[static_cast<size_t>(owner[static_cast<size_t>(row)])];
            throw ModelError(fmt::format(
                "machine '{}': deviation '{}' (link {}, component {}) does not change the quantity ISO 230-1 calls {} "
                "(see the README's name table: squareness is measured from X, then Y)",
                m.name, def.name, m.chain(def.side).links[static_cast<size_t>(def.link)].name,
                "xyzabc"[def.component], def.name));
        }
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(M);
    if (lu.rank() < n)
        throw ModelError(fmt::format("machine '{}': the ISO names of its deviations do not describe independent "
                                     "quantities (two names stand for the same error)",
                                     m.name));
    const Eigen::MatrixXd inv = lu.inverse();
    for (int row = 0; row < n; ++row) {
        DeviationDef& def = m.deviations[static_cast<size_t>(owner[static_cast<size_t>(row)])];
        for (int c = 0; c < n; ++c) {
            if (M(row, c) != 0.0) def.isoTerms.push_back({owner[static_cast<size_t>(c)], M(row, c)});
            const double v = clean(inv(row, c));
            if (v != 0.0) def.linkTerms.push_back({owner[static_cast<size_t>(c)], v});
        }
    }
}

bool aliasDiffersFromName(const MachineModel& m, int index) {
    const DeviationDef& d = m.deviations.at(static_cast<size_t>(index));
    if (d.alias.empty()) return false;
    if (d.aliasSign != 1.0) return true;
    return d.kind == DeviationKind::Location &&
           !(d.isoTerms.size() == 1 && d.isoTerms[0].deviation == index && d.isoTerms[0].coefficient == 1.0);
}

std::string isoMeaningText(const MachineModel& m, int deviation) {
    const DeviationDef& def = m.deviations.at(static_cast<size_t>(deviation));
    std::string s = def.name + " =";
    bool first = true;
    for (const DeviationTerm& t : def.isoTerms) {
        const DeviationDef& o = m.deviations[static_cast<size_t>(t.deviation)];
        const std::string sym = !o.alias.empty() && o.aliasSign == 1.0
                                    ? o.alias
                                    : fmt::format("[{}.{}]", m.chain(o.side).links[static_cast<size_t>(o.link)].name,
                                                  "xyzabc"[o.component]);
        const double a = std::abs(t.coefficient);
        const std::string mag = a == 1.0 ? "" : fmt::format("{:g}·", a);
        if (first) s += fmt::format(" {}{}{}", t.coefficient < 0 ? "-" : "", mag, sym);
        else s += fmt::format(" {} {}{}", t.coefficient < 0 ? "-" : "+", mag, sym);
        first = false;
    }
    return s;
}

}  // namespace cnccomp

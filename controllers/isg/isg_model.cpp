#include "controllers/isg/isg_model.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::controllers::isg {
namespace {

const std::string kAxisLetters = "XYZABC";

Pose translation(const Vec3& t) {
    Pose p = Pose::Identity();
    p.translation() = t;
    return p;
}

}  // namespace

Vec6 IsgModel::Table::at(double x) const {
    const size_t n = nodes.size();
    if (n == 0) return Vec6::Zero();
    if (n == 1) return values[0];
    if (wraps) {
        x = std::fmod(x - nodes.front(), 360.0);
        if (x < 0) x += 360.0;
        x += nodes.front();
    }
    if (x <= nodes.front()) return values.front();
    if (x >= nodes.back()) return values.back();
    const size_t i = static_cast<size_t>(std::upper_bound(nodes.begin(), nodes.end(), x) - nodes.begin()) - 1;
    const double t = (x - nodes[i]) / (nodes[i + 1] - nodes[i]);
    return values[i] + (values[i + 1] - values[i]) * t;
}

IsgModel::IsgModel(const IsgConfig& config, const std::vector<std::pair<std::string, std::vector<IsgBlock>>>& files)
    : chain_(config.chain), workpieceAxes_(config.workpieceAxes) {
    if (workpieceAxes_ > static_cast<int>(chain_.size()))
        throw InputError("compensation list", 0,
                         fmt::format("workpiece_axes {} exceeds the {} axes of chain {}", workpieceAxes_, chain_.size(), chain_));
    for (size_t i = 0; i < chain_.size(); ++i) {
        const size_t k = kAxisLetters.find(chain_[i]);
        if (k == std::string::npos || chain_.find(chain_[i]) != i)
            throw InputError("compensation list", 0, fmt::format("chain {}: each of X Y Z A B C at most once", chain_));
        Axis a;
        a.letter = chain_[i];
        a.rotary = k >= 3;
        a.workpiece = static_cast<int>(i) < workpieceAxes_;
        a.direction = Vec3::Unit(static_cast<int>(k % 3));
        axes_.push_back(a);
    }
    const auto axisOf = [&](char letter) -> Axis* {
        for (Axis& a : axes_)
            if (a.letter == letter) return &a;
        return nullptr;
    };
    bool n0Given = false;
    for (const auto& [file, blocks] : files) {
        for (const IsgBlock& b : blocks) {
            const std::string& arg = b.columns[0];
            if (arg.size() == 1 && kAxisLetters.find(arg[0]) != std::string::npos) {
                // Component errors over one axis: "X EXX EYX ..." (TF5280 "ISG CSV format").
                Axis* a = axisOf(arg[0]);
                if (!a) throw InputError(file, b.headerLine, fmt::format("axis {} is not in the chain {}", arg, chain_));
                if (!a->component.nodes.empty())
                    throw InputError(file, b.headerLine, fmt::format("a second table over {}", arg));
                std::vector<int> comp;
                for (size_t c = 1; c < b.columns.size(); ++c) {
                    const std::string& col = b.columns[c];
                    const size_t k = col.size() == 3 && col[0] == 'E' && col[2] == arg[0] ? kAxisLetters.find(col[1]) : std::string::npos;
                    if (k == std::string::npos)
                        throw InputError(file, b.headerLine, fmt::format("'{}' is not a component error of {} (E<X..C>{})", col, arg, arg));
                    comp.push_back(static_cast<int>(k));
                }
                for (size_t i = 0; i < b.rows.size(); ++i) {
                    const double x = b.rows[i][0];
                    if (i > 0 && !(x > a->component.nodes.back()))
                        throw InputError(file, b.rowLines[i], fmt::format("the values of {} must increase", arg));
                    Vec6 v = Vec6::Zero();
                    for (size_t c = 1; c < b.columns.size(); ++c) v[comp[c - 1]] = b.rows[i][c];
                    a->component.nodes.push_back(x);
                    a->component.values.push_back(v);
                }
                a->component.wraps = a->rotary && a->component.nodes.front() == 0.0 && a->component.nodes.back() == 360.0;
                continue;
            }
            if (b.rows.size() != 1) throw InputError(file, b.rowLines[1], "position errors and ISG parameters take one data row");
            for (size_t c = 0; c < b.columns.size(); ++c) {
                const std::string& col = b.columns[c];
                const double v = b.rows[0][c];
                const size_t k1 = col.size() == 3 ? kAxisLetters.find(col[1]) : std::string::npos;
                const size_t k2 = col.size() == 3 ? kAxisLetters.find(col[2]) : std::string::npos;
                if (col.size() == 3 && col[0] == 'P' && col[1] == '0' && k2 < 3) {
                    p0_[static_cast<int>(k2)] = v;
                } else if (col.size() == 3 && col[0] == 'N' && col[1] == '0' && k2 < 3) {
                    n0_[static_cast<int>(k2)] = v;
                    n0Given = true;
                } else if (col.size() == 3 && col[0] == 'P' && k1 < 3 && k2 != std::string::npos && k2 >= 3) {
                    Axis* a = axisOf(col[2]);
                    if (!a) throw InputError(file, b.headerLine, fmt::format("{}: axis {} is not in the chain {}", col, col[2], chain_));
                    a->centre[static_cast<int>(k1)] = v;
                } else if (col.size() == 3 && col[1] == '0' && kAxisLetters.find(col[0]) != std::string::npos && k2 != std::string::npos) {
                    Axis* a = axisOf(col[2]);
                    if (!a) throw InputError(file, b.headerLine, fmt::format("{}: axis {} is not in the chain {}", col, col[2], chain_));
                    a->position[static_cast<int>(kAxisLetters.find(col[0]))] = v;
                } else {
                    throw InputError(file, b.headerLine,
                                     fmt::format("'{}' is not a parameter of the volumetric compensation (P0X.., N0X.., PXA.., X0X..C0C)", col));
                }
            }
            if (n0Given && std::abs(n0_.norm() - 1.0) > 1e-6)
                throw InputError(file, b.rowLines[0], "N0X N0Y N0Z must be a unit vector (TF5280 \"Tool length\")");
        }
    }
}

Pose IsgModel::motion(const Axis& a, double value, bool withErrors) const {
    Pose m = Pose::Identity();
    if (a.rotary) m.linear() = axisRotation(a.direction, value * kDeg);
    else m.translation() = a.direction * value;
    if (withErrors) m = errorTransform(a.position) * m * errorTransform(a.component.at(value));
    return a.rotary ? translation(a.centre) * m * translation(-a.centre) : m;
}

Vec3 IsgModel::toolPoint(const std::map<char, double>& values, double length, bool withErrors) const {
    const auto value = [&](char letter) {
        const auto it = values.find(letter);
        return it == values.end() ? 0.0 : it->second;
    };
    // Chain order: workpiece end ... machine origin ... tool tip. The workpiece axes, from the bed outwards, carry the
    // workpiece; the tool is seen from it (their motion enters inverted).
    Pose tool = Pose::Identity(), workpiece = Pose::Identity();
    for (size_t i = static_cast<size_t>(workpieceAxes_); i < axes_.size(); ++i) tool = tool * motion(axes_[i], value(axes_[i].letter), withErrors);
    for (int i = workpieceAxes_ - 1; i >= 0; --i) workpiece = workpiece * motion(axes_[i], value(axes_[i].letter), withErrors);
    return workpiece.inverse(Eigen::Isometry) * (tool * (p0_ + length * n0_));
}

}  // namespace cnccomp::controllers::isg

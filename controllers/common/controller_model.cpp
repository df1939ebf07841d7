#include "controllers/common/controller_model.hpp"

#include <algorithm>
#include <cmath>
#include <string_view>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::controllers::common {

std::vector<int> controllerAxisOrder(const MachineModel& m) {
    static constexpr std::string_view kOrder = "XYZUVWABC";
    std::vector<int> out(m.axisCount());
    for (int i = 0; i < m.axisCount(); ++i) out[i] = i;
    const auto rank = [&](int i) -> size_t {
        const std::string& n = m.axisNames[i];
        if (n.size() == 1) {
            const size_t p = kOrder.find(n[0]);
            if (p != std::string_view::npos) return p;
        }
        return kOrder.size();
    };
    std::stable_sort(out.begin(), out.end(), [&](int a, int b) { return rank(a) < rank(b); });
    return out;
}

int controllerAxisNumber(const MachineModel& m, int machineAxis) {
    const auto order = controllerAxisOrder(m);
    for (size_t k = 0; k < order.size(); ++k)
        if (order[k] == machineAxis) return static_cast<int>(k) + 1;
    throw ModelError(fmt::format("machine '{}' has no axis number {}", m.name, machineAxis));
}

int machineAxisOfNumber(const MachineModel& m, int number) {
    const auto order = controllerAxisOrder(m);
    if (number < 1 || number > static_cast<int>(order.size())) return -1;
    return order[number - 1];
}

namespace {

void buildChain(const MachineModel& machine, const std::vector<ChainElement>& elements, Chain& chain,
                const char* endName) {
    Pose pending = Pose::Identity();
    for (const ChainElement& e : elements) {
        if (e.type == ChainElement::Type::Constant) {
            pending = pending * e.pose;
            continue;
        }
        if (e.axis < 0 || e.axis >= machine.axisCount())
            throw ModelError(fmt::format("controller model: axis index {} is not an axis of machine '{}'", e.axis,
                                         machine.name));
        if (!(std::abs(e.direction.norm() - 1.0) < 1e-9))
            throw ModelError(fmt::format("controller model: direction of axis {} is not a unit vector",
                                         machine.axisNames[e.axis]));
        const Link& real = machine.axisLink(e.axis);
        Link l = real;
        // The controller counts the axis from its own machine zero: same travel, other numbers.
        l.min = real.min - real.machineZero;
        l.max = real.max - real.machineZero;
        l.machineZero = 0.0;
        l.direction = e.direction;
        l.placement = pending;
        chain.links.push_back(l);
        pending = Pose::Identity();
    }
    Link end;
    end.name = endName;
    end.kind = AxisKind::Fixed;
    end.placement = pending;
    chain.links.push_back(end);
}

}  // namespace

ControllerModel::ControllerModel(const MachineModel& machine, const std::vector<ChainElement>& workpiece,
                                 const std::vector<ChainElement>& tool, const std::vector<ComponentTable>& tables)
    : model_(std::make_unique<MachineModel>()) {
    MachineModel& c = *model_;
    c.name = machine.name;
    c.description = "controller model of " + machine.name;
    c.sourceFile = machine.sourceFile;
    c.toolDirection = machine.toolDirection;
    buildChain(machine, workpiece, c.workpiece, "controller-workpiece-end");
    buildChain(machine, tool, c.tool, "controller-tool-end");
    for (const ComponentTable& t : tables) {
        if (t.axis < 0 || t.axis >= machine.axisCount())
            throw ModelError(fmt::format("controller model: table for an axis index {} the machine lacks", t.axis));
        if (t.component < 0 || t.component > 5)
            throw ModelError("controller model: table component outside x y z a b c");
        if (t.nodes.size() < 2 || t.nodes.size() != t.values.size())
            throw ModelError(fmt::format("controller model: table of axis {} needs two or more nodes with values",
                                         machine.axisNames[t.axis]));
        DeviationDef d;
        d.name = fmt::format("{}_table{}", machine.axisNames[t.axis], t.component);
        d.kind = DeviationKind::Component;
        d.component = t.component;
        d.basis.type = ComponentBasis::Type::Table;
        d.basis.nodes = t.nodes;
        bool found = false;
        for (Side s : {Side::Workpiece, Side::Tool}) {
            const Chain& ch = c.chain(s);
            for (int i = 0; i < static_cast<int>(ch.links.size()); ++i)
                if (ch.links[i].kind != AxisKind::Fixed && ch.links[i].name == machine.axisNames[t.axis]) {
                    d.side = s;
                    d.link = i;
                    found = true;
                }
        }
        if (!found)
            throw ModelError(fmt::format("controller model: table for axis {} which its chains do not hold",
                                         machine.axisNames[t.axis]));
        c.deviations.push_back(std::move(d));
    }
    c.finalize();
    if (c.axisNames != machine.axisNames) {
        std::string got, want;
        for (const auto& n : c.axisNames) got += n + " ";
        for (const auto& n : machine.axisNames) want += n + " ";
        throw ModelError(fmt::format("controller model: chains hold the axes [ {}] but machine '{}' has [ {}] "
                                     "(workpiece chain first, each from the bed outwards)",
                                     got, machine.name, want));
    }
    for (size_t k = 0; k < c.deviations.size(); ++k) {
        const DeviationDef& d = c.deviations[k];
        const Link& l = c.chain(d.side).links[d.link];
        for (size_t i = 1; i < d.basis.nodes.size(); ++i)
            if (!(d.basis.nodes[i] > d.basis.nodes[i - 1]))
                throw ModelError(fmt::format("controller model: table nodes of axis {} are not increasing", l.name));
        if (l.modulo && d.basis.nodes.back() - d.basis.nodes.front() >= 2 * kPi - 1e-12)
            throw ModelError(fmt::format("controller model: table of modulo axis {} must span less than 360 deg",
                                         l.name));
    }
    set_ = std::make_unique<DeviationSet>(c);
    for (size_t k = 0; k < tables.size(); ++k) {
        const DeviationDef& d = c.deviations[k];
        for (size_t i = 0; i < tables[k].values.size(); ++i) {
            if (!std::isfinite(tables[k].values[i])) throw ModelError("controller model: table value not finite");
            set_->values[d.offset + static_cast<int>(i)] = tables[k].values[i];
        }
        set_->present[k] = 1;
    }
    kinematics_ = std::make_unique<Kinematics>(c, *set_);
}

TcpTransform::TcpTransform(const MachineModel& machine, std::unique_ptr<const ControllerModel> controller,
                           double toolLength)
    : nominal_(machine), controller_(std::move(controller)), toolLength_(toolLength) {
    if (!controller_) throw ModelError("TCP transform without a controller model");
    if (!std::isfinite(toolLength)) throw ModelError("TCP tool length must be a finite number");
}

AxisVector TcpTransform::solve(const AxisVector& programmed) const { return solve(programmed, toolLength_); }

AxisVector TcpTransform::solve(const AxisVector& programmed, double toolLength) const {
    const Vec3 tip = nominal_.toolPoint(toolLength);
    const ToolPose target = toolPose(nominal_, programmed, tip);
    const MachineModel& m = nominal_.machine();
    const IkResult r = solveToolPose(controller_->kinematics(), target, tip, m.toController(programmed));
    return m.fromController(r.q);
}

Vec6 linkLocationError(const MachineModel& m, const Eigen::VectorXd& values, Side side, int link) {
    Vec6 e = Vec6::Zero();
    for (const DeviationDef& d : m.deviations)
        if (d.kind == DeviationKind::Location && d.side == side && d.link == link) e[d.component] += values[d.offset];
    return e;
}

Vec3 xyzAngles(const Mat3& r) {
    const double b = std::asin(std::clamp(r(0, 2), -1.0, 1.0));
    const double a = std::atan2(-r(1, 2), r(2, 2));
    const double c = std::atan2(-r(0, 1), r(0, 0));
    return {a, b, c};
}

Mat3 fromXyzAngles(const Vec3& abc) {
    return (Eigen::AngleAxisd(abc.x(), Vec3::UnitX()) * Eigen::AngleAxisd(abc.y(), Vec3::UnitY()) *
            Eigen::AngleAxisd(abc.z(), Vec3::UnitZ()))
        .toRotationMatrix();
}

std::string fixed(double v, int decimals) {
    std::string s = fmt::format("{:.{}f}", v, decimals);
    if (s.front() == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
    return s;
}

}  // namespace cnccomp::controllers::common

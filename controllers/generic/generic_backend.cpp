// Generic backend: the deviation set (CSV and JSON) and a grid map of the tool-tip error over the workspace (CSV and
// JSON), for controllers cnccomp has no backend for. The apply model is a controller with an N-dimensional lookup
// table: it interpolates the map at the programmed commands and moves the linear axes against the tip error.
#include <algorithm>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/inverse_kinematics.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "controllers/common/files.hpp"
#include "controllers/common/header.hpp"
#include "controllers/generic/deviation_json.hpp"
#include "controllers/generic/generic_backend.hpp"
#include "controllers/generic/grid_map.hpp"

namespace cnccomp::controllers::generic {
using namespace cnccomp::controllers::common;
using namespace cnccomp::io;
namespace {

constexpr const char* kDevCsv = "deviations.csv";
constexpr const char* kDevJson = "deviations.json";
constexpr const char* kMapCsv = "map.csv";
constexpr const char* kMapJson = "map.json";

std::vector<std::string> headerLines(const std::string& text) {
    std::vector<std::string> out;
    for (const TextLine& l : splitLines(text)) out.emplace_back(l.text);
    return out;
}

class GenericApplied final : public AppliedCompensation {
public:
    GenericApplied(const MachineModel& m, GridMap g) : map_(std::move(g)), nominal_(m) {
        for (int a = 0; a < m.axisCount(); ++a)
            if (m.axisLink(a).kind == AxisKind::Linear) linear_.push_back(a);
    }
    AxisVector driveCommands(const AxisVector& q) const override { return driveCommandsForTool(q, 0.0); }
    AxisVector driveCommandsForTool(const AxisVector& q, double toolLength) const override {
        const Vec3 tip = nominal_.toolPoint(toolLength);
        PoseJacobian J;
        toolPoseJacobian(nominal_, q, tip, J);
        // The map's errors are along the machine's X Y Z: the tip's motion per linear axis in that frame too.
        const Mat3 bRw = nominal_.baseToWorkpiece(q).linear();
        Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kMaxAxes> Jl(3, static_cast<int>(linear_.size()));
        for (size_t k = 0; k < linear_.size(); ++k) Jl.col(static_cast<int>(k)) = bRw * J.block<3, 1>(0, linear_[k]);
        const auto qr = Jl.colPivHouseholderQr();
        AxisVector out = q;
        for (int it = 0; it < 3; ++it) {  // the error at the corrected commands, not at the programmed ones
            Vec3 e0, dk;
            map_.at(out, e0, dk);
            const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxAxes, 1> step = qr.solve(Vec3(-(e0 + toolLength * dk)));
            out = q;
            for (size_t k = 0; k < linear_.size(); ++k) out[linear_[k]] += step[static_cast<int>(k)];
        }
        return out;
    }

private:
    GridMap map_;
    Kinematics nominal_;
    std::vector<int> linear_;
};

}  // namespace

EmitResult emitFiles(const EmitRequest& r, const GridMapOptions& options) {
    const MachineModel& m = r.machine;
    EmitResult out;
    int linear = 0;
    for (int a = 0; a < m.axisCount(); ++a) linear += m.axisLink(a).kind == AxisKind::Linear;
    const GridMap g = buildGridMap(m, r.deviations, options);
    for (size_t k = 0; k < m.deviations.size(); ++k) {
        if (!r.deviations.present[k]) continue;
        if (linear >= 3)
            out.compensated.push_back({m.deviations[k].name, fmt::format("tool-tip position through the grid map, within {:g} um "
                                                                         "(tool orientation not corrected)",
                                                                         g.tolerance / kUm)});
        else
            out.notCompensated.push_back({m.deviations[k].name, "listed in the files; the map needs three linear axes to act on"});
    }
    std::string grid;
    for (const GridMapAxis& ax : g.axes)
        grid += fmt::format("{}{} {} nodes {:.6g}..{:.6g} {}", grid.empty() ? "" : "; ", m.axisNames[ax.axis], ax.nodes.size(),
                            ax.nodes.front() / (ax.rotary ? kDeg : 1.0), ax.nodes.back() / (ax.rotary ? kDeg : 1.0), ax.rotary ? "deg" : "mm");
    std::vector<std::string> notes = {
        "grid map: " + grid + " (description commands)", frameNote(m),
        "map.csv / map.json axis columns: machine coordinates; errors absolute (what the machine does wrong there, tool "
        "relative to workpiece along the machine's X Y Z), not corrections",
        fmt::format("nodes chosen so that multilinear interpolation stays within {:g} um of the exact model for tool lengths "
                    "0..{:g} mm (checked midway between nodes)",
                    g.tolerance / kUm, options.toolLength),
        "apply model: multilinear interpolation of the map, linear axes moved against the tip error"};
    if (g.tolerance > options.tolerance)
        notes.push_back(fmt::format("the {:g} um asked for needs more than {} nodes: the map holds {:g} um", options.tolerance / kUm,
                                    options.maxNodes, g.tolerance / kUm));
    const HeaderInfo h = makeHeaderInfo(r, "generic controller (cnccomp CSV + JSON)", out, notes);
    const std::string text = formatHeader(h, "");
    out.files.push_back({kDevCsv, formatHeader(h, "# ") + formatDeviationCsv(r.deviations)});
    out.files.push_back({kDevJson, formatDeviationJson(r.deviations, headerLines(text), r.deviationSource, r.date)});
    out.files.push_back({kMapCsv, formatGridMapCsv(g, m, formatHeader(h, "# "))});
    out.files.push_back({kMapJson, formatGridMapJson(g, m, headerLines(text))});
    return out;
}

namespace {

class GenericBackend final : public Backend {
public:
    std::string_view name() const override { return "generic"; }
    std::string_view description() const override {
        return "generic CSV + JSON: the deviation set and a grid map of the tool-tip error over the workspace (machine frame, "
               "nodes for 0.05 um of multilinear interpolation)";
    }

    EmitResult emit(const EmitRequest& r) const override { return emitFiles(r, GridMapOptions{}); }
    /// The map holds the tip error of every deviation given; what it leaves is its interpolation (GridMapOptions).
    bool fitsDeviationValues() const override { return false; }

    std::vector<std::string> checks() const override {
        return {"the map's axis columns are the controller's machine coordinates: compare one node with the machine "
                "position display before feeding a lookup table with it",
                "the tip error is the machine's error (actual - nominal, along the machine's X Y Z); a controller table usually wants "
                "the correction, its negative"};
    }

    std::unique_ptr<AppliedCompensation> apply(const MachineModel& m, const std::vector<OutputFile>& files) const override {
        GridMap g = parseGridMapCsv(requireFile(files, kMapCsv, "generic").content, kMapCsv, m);
        return std::make_unique<GenericApplied>(m, std::move(g));
    }
};

const RegisterBackend reg(std::make_unique<GenericBackend>());

}  // namespace
}  // namespace cnccomp::controllers::generic

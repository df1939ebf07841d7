#include "controllers/siemens/compensation_tables.hpp"

#include <cmath>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/common/controller_model.hpp"
#include "controllers/siemens/siemens_syntax.hpp"

namespace cnccomp::controllers::siemens {
using namespace cnccomp::controllers::common;
namespace {

int valueDecimals(const Link& l) { return l.kind == AxisKind::Rotary ? 8 : 6; }

std::string sourcesText(const std::vector<std::string>& s) {
    std::string out;
    for (const auto& x : s) out += (out.empty() ? "" : ", ") + x;
    return out;
}

/// Table fields gathered from the assignments, before validation.
struct RawTable {
    int line = 0;
    std::map<int, std::pair<double, int>> points;  // n → (value, line)
    std::optional<double> step, min, max;
    std::optional<int> modulo, direction, mult;
    std::optional<int> input, output;  // machine axis indices
};

int flag(const AssignmentFile& f, const Assignment& a) {
    const double v = numberValue(f, a);
    if (v != 0.0 && v != 1.0) throw InputError(f.path, a.line, fmt::format("{} must be 0 or 1", a.variable));
    return static_cast<int>(v);
}

int machineAxis(const MachineModel& m, const AssignmentFile& f, const Assignment& a, std::string_view text) {
    const int n = axisNumber(f, a, text);
    const int axis = machineAxisOfNumber(m, n);
    if (axis < 0) throw InputError(f.path, a.line, fmt::format("machine '{}' has no axis AX{}", m.name, n));
    return axis;
}

EquidistantTable validate(const MachineModel& m, const std::string& path, const std::string& what, const RawTable& r,
                          int axis) {
    if (!r.step || !r.min || !r.max)
        throw InputError(path, r.line, fmt::format("{}: STEP, MIN and MAX are all needed", what));
    if (!(*r.step > 0)) throw InputError(path, r.line, fmt::format("{}: STEP must be positive", what));
    if (!(*r.max > *r.min)) throw InputError(path, r.line, fmt::format("{}: MAX must exceed MIN", what));
    const double intervals = (*r.max - *r.min) / *r.step;
    const long n = std::lround(intervals) + 1;
    if (std::abs(intervals - (n - 1)) > 1e-6 * std::max(1.0, intervals))
        throw InputError(path, r.line, fmt::format("{}: (MAX-MIN)/STEP = {} is not a whole number of intervals", what, intervals));
    if (static_cast<long>(r.points.size()) != n || r.points.begin()->first != 0 || r.points.rbegin()->first != n - 1)
        throw InputError(path, r.line, fmt::format("{}: (MAX-MIN)/STEP+1 = {} points expected, {} given (numbered 0..{})",
                                                   what, n, r.points.size(), n - 1));
    EquidistantTable t;
    t.min = *r.min;
    t.step = *r.step;
    t.modulo = r.modulo.value_or(0) == 1;
    for (const auto& [k, v] : r.points) t.values.push_back(v.first);
    if (t.modulo) {
        const Link& l = m.axisLink(axis);
        if (l.kind != AxisKind::Rotary || !l.modulo)
            throw InputError(path, r.line, fmt::format("{}: IS_MODULO=1 but axis {} is not a modulo rotary axis", what, l.name));
        if (std::abs(t.max() - t.min - 360.0) > 1e-6)
            throw InputError(path, r.line, fmt::format("{}: a modulo table must span one revolution (MAX-MIN = 360)", what));
        if (std::abs(t.values.front() - t.values.back()) > 1e-9)
            throw InputError(path, r.points.rbegin()->second.second,
                             fmt::format("{}: modulo table does not close on itself (last point {} differs from first {})",
                                         what, t.values.back(), t.values.front()));
    }
    return t;
}

}  // namespace

std::string formatCec(const MachineModel& m, const std::vector<CecTable>& tables, const std::string& header) {
    std::string s = fmt::format("%{}\n", kCecIdentifier);
    s += header;
    s += "CHANDATA(1)\n";
    for (size_t t = 0; t < tables.size(); ++t) {
        const CecTable& c = tables[t];
        const Link& in = m.axisLink(c.input);
        const Link& out = m.axisLink(c.output);
        s += fmt::format("; table {}: input {} ({}), output {} ({}): {}\n", t, axisName(m, c.input), in.name,
                         axisName(m, c.output), out.name, sourcesText(c.sources));
        for (size_t n = 0; n < c.table.values.size(); ++n)
            s += fmt::format("$AN_CEC[{},{}]={}\n", t, n, fixed(c.table.values[n], valueDecimals(out)));
        s += fmt::format("$AN_CEC_INPUT_AXIS[{}]=({})\n", t, axisName(m, c.input));
        s += fmt::format("$AN_CEC_OUTPUT_AXIS[{}]=({})\n", t, axisName(m, c.output));
        s += fmt::format("$AN_CEC_STEP[{}]={}\n", t, fixed(c.table.step, 6));
        s += fmt::format("$AN_CEC_MIN[{}]={}\n", t, fixed(c.table.min, 6));
        s += fmt::format("$AN_CEC_MAX[{}]={}\n", t, fixed(c.table.max(), 6));
        s += fmt::format("$AN_CEC_DIRECTION[{}]=0\n", t);
        s += fmt::format("$AN_CEC_MULT_BY_TABLE[{}]=0\n", t);
        s += fmt::format("$AN_CEC_IS_MODULO[{}]={}\n", t, c.table.modulo ? 1 : 0);
    }
    s += "M17\n";
    return s;
}

std::string formatEec(const MachineModel& m, const std::vector<EecTable>& tables, const std::string& header) {
    std::string s = fmt::format("%{}\n", kEecIdentifier);
    s += header;
    for (const EecTable& e : tables) {
        const Link& l = m.axisLink(e.axis);
        const std::string ax = axisName(m, e.axis);
        s += fmt::format("; {} ({}): positioning error in {}: {}\n", ax, l.name,
                         l.kind == AxisKind::Rotary ? "deg" : "mm", sourcesText(e.sources));
        for (size_t n = 0; n < e.table.values.size(); ++n)
            s += fmt::format("$AA_ENC_COMP[0,{},{}]={}\n", n, ax, fixed(e.table.values[n], valueDecimals(l)));
        s += fmt::format("$AA_ENC_COMP_STEP[0,{}]={}\n", ax, fixed(e.table.step, 6));
        s += fmt::format("$AA_ENC_COMP_MIN[0,{}]={}\n", ax, fixed(e.table.min, 6));
        s += fmt::format("$AA_ENC_COMP_MAX[0,{}]={}\n", ax, fixed(e.table.max(), 6));
        s += fmt::format("$AA_ENC_COMP_IS_MODULO[0,{}]={}\n", ax, e.table.modulo ? 1 : 0);
    }
    s += "M17\n";
    return s;
}

std::vector<CecTable> parseCec(const MachineModel& m, const std::string& path, std::string_view text) {
    const AssignmentFile f = parseAssignmentFile(path, text, kCecIdentifier);
    std::map<int, RawTable> raw;
    for (const Assignment& a : f.assignments) {
        const std::string& v = a.variable;
        if (!v.starts_with("$AN_CEC")) throw InputError(path, a.line, fmt::format("unknown variable {} in a CEC file", v));
        RawTable& r = raw[indexNumber(f, a, 0)];
        if (r.line == 0) r.line = a.line;
        if (v == "$AN_CEC") {
            const int n = indexNumber(f, a, 1);
            if (a.indices.size() != 2) throw InputError(path, a.line, "$AN_CEC takes [table,point]");
            if (!r.points.emplace(n, std::make_pair(numberValue(f, a), a.line)).second)
                throw InputError(path, a.line, fmt::format("point {} assigned twice", n));
        } else if (v == "$AN_CEC_INPUT_AXIS" || v == "$AN_CEC_OUTPUT_AXIS") {
            if (a.kind != Assignment::Kind::Axis) throw InputError(path, a.line, fmt::format("{} needs (AXn)", v));
            setOnce(v == "$AN_CEC_INPUT_AXIS" ? r.input : r.output, machineAxis(m, f, a, a.value), f, a);
        } else if (v == "$AN_CEC_STEP") setOnce(r.step, numberValue(f, a), f, a);
        else if (v == "$AN_CEC_MIN") setOnce(r.min, numberValue(f, a), f, a);
        else if (v == "$AN_CEC_MAX") setOnce(r.max, numberValue(f, a), f, a);
        else if (v == "$AN_CEC_IS_MODULO") setOnce(r.modulo, flag(f, a), f, a);
        else if (v == "$AN_CEC_DIRECTION") setOnce(r.direction, static_cast<int>(numberValue(f, a)), f, a);
        else if (v == "$AN_CEC_MULT_BY_TABLE") setOnce(r.mult, static_cast<int>(numberValue(f, a)), f, a);
        else throw InputError(path, a.line, fmt::format("unknown CEC variable {}", v));
    }
    std::vector<CecTable> out;
    for (const auto& [t, r] : raw) {
        const std::string what = fmt::format("CEC table {}", t);
        if (!r.input || !r.output) throw InputError(path, r.line, fmt::format("{}: INPUT_AXIS and OUTPUT_AXIS are needed", what));
        if (*r.input == *r.output) throw InputError(path, r.line, fmt::format("{}: input and output are the same axis", what));
        if (r.direction.value_or(0) != 0)
            throw InputError(path, r.line, fmt::format("{}: only DIRECTION=0 (both directions) is modelled", what));
        if (r.mult.value_or(0) != 0)
            throw InputError(path, r.line, fmt::format("{}: MULT_BY_TABLE (table products) is not modelled", what));
        if (r.points.empty()) throw InputError(path, r.line, fmt::format("{}: no points $AN_CEC[{},n]", what, t));
        CecTable c;
        c.input = *r.input;
        c.output = *r.output;
        c.table = validate(m, path, what, r, c.input);
        out.push_back(std::move(c));
    }
    return out;
}

std::vector<EecTable> parseEec(const MachineModel& m, const std::string& path, std::string_view text) {
    const AssignmentFile f = parseAssignmentFile(path, text, kEecIdentifier);
    std::map<int, RawTable> raw;  // by machine axis
    for (const Assignment& a : f.assignments) {
        const std::string& v = a.variable;
        if (!v.starts_with("$AA_ENC_COMP")) throw InputError(path, a.line, fmt::format("unknown variable {} in an EEC file", v));
        if (indexNumber(f, a, 0) != 0)
            throw InputError(path, a.line, "only the first measuring system (index 0) is written by cnccomp");
        const bool point = v == "$AA_ENC_COMP";
        const size_t axisAt = point ? 2 : 1;
        if (a.indices.size() != axisAt + 1)
            throw InputError(path, a.line, fmt::format("{} takes {} indices", v, axisAt + 1));
        const int axis = machineAxis(m, f, a, a.indices[axisAt]);
        RawTable& r = raw[axis];
        if (r.line == 0) r.line = a.line;
        if (point) {
            const int n = indexNumber(f, a, 1);
            if (!r.points.emplace(n, std::make_pair(numberValue(f, a), a.line)).second)
                throw InputError(path, a.line, fmt::format("point {} assigned twice", n));
        } else if (v == "$AA_ENC_COMP_STEP") setOnce(r.step, numberValue(f, a), f, a);
        else if (v == "$AA_ENC_COMP_MIN") setOnce(r.min, numberValue(f, a), f, a);
        else if (v == "$AA_ENC_COMP_MAX") setOnce(r.max, numberValue(f, a), f, a);
        else if (v == "$AA_ENC_COMP_IS_MODULO") setOnce(r.modulo, flag(f, a), f, a);
        else throw InputError(path, a.line, fmt::format("unknown EEC variable {}", v));
    }
    std::vector<EecTable> out;
    for (const auto& [axis, r] : raw) {
        const std::string what = fmt::format("EEC table of {}", axisName(m, axis));
        if (r.points.empty()) throw InputError(path, r.line, fmt::format("{}: no points", what));
        EecTable e;
        e.axis = axis;
        e.table = validate(m, path, what, r, axis);
        out.push_back(std::move(e));
    }
    return out;
}

}  // namespace cnccomp::controllers::siemens

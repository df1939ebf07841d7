#include "controllers/common/header.hpp"

#include "cnccomp/geometry.hpp"

#include "controllers/common/controller_model.hpp"

#include <algorithm>
#include <filesystem>

#include <fmt/format.h>

namespace cnccomp::controllers::common {
namespace {

void line(std::string& out, std::string_view prefix, std::string_view suffix, std::string_view eol, std::string text) {
    if (!suffix.empty() && suffix.front() == ')') {
        // Fanuc-style comments do not nest: parentheses inside become brackets.
        std::replace(text.begin(), text.end(), '(', '[');
        std::replace(text.begin(), text.end(), ')', ']');
    } else if (!suffix.empty()) {
        std::replace(text.begin(), text.end(), suffix.front(), '_');
    }
    // A comment must not hold a line break of its own.
    std::replace(text.begin(), text.end(), '\n', ' ');
    std::replace(text.begin(), text.end(), '\r', ' ');
    std::string l = std::string(prefix) + text + std::string(suffix);
    if (suffix.empty())
        while (!l.empty() && l.back() == ' ') l.pop_back();
    out += l;
    out += eol;
}

void list(std::string& out, std::string_view prefix, std::string_view suffix, std::string_view eol,
          const std::vector<Coverage>& items) {
    if (items.empty()) line(out, prefix, suffix, eol, "  (none)");
    size_t w = 0;
    for (const Coverage& c : items) w = std::max(w, c.deviation.size());
    for (const Coverage& c : items) line(out, prefix, suffix, eol, fmt::format("  {:<{}}  {}", c.deviation, w, c.note));
}

}  // namespace

std::vector<Coverage> reversalsNotHeld(const EmitRequest& request, const std::vector<Coverage>& compensated) {
    std::vector<Coverage> out;
    const MachineModel& m = request.machine;
    const DeviationSet& d = request.deviations;
    for (int a = 0; a < m.axisCount() && a < static_cast<int>(d.reversalPresent.size()); ++a) {
        if (!d.reversalPresent[static_cast<size_t>(a)]) continue;
        const std::string name = "B" + m.axisNames[static_cast<size_t>(a)];
        if (std::any_of(compensated.begin(), compensated.end(), [&](const Coverage& c) { return c.deviation == name; }))
            continue;
        out.push_back({name, fmt::format("reversal value {:.3f} um (ISO 230-2 mean reversal): these files hold no "
                                         "backlash; set backlash = {:.3f} um by hand or write it from the laser runs "
                                         "with cnccomp laser --controller (Fanuc 1851, Sinumerik MD32450, HEIDENHAIN "
                                         "MP710, ISG bilateral LSEC)",
                                         d.reversal[static_cast<size_t>(a)] / kUm, -d.reversal[static_cast<size_t>(a)] / kUm)});
    }
    return out;
}

HeaderInfo makeHeaderInfo(const EmitRequest& request, std::string_view controller, const EmitResult& coverage,
                          std::vector<std::string> notes) {
    HeaderInfo h;
    h.controller = std::string(controller);
    h.machine = request.machine.name;
    h.machineFile = request.machine.sourceFile;
    h.deviationSource = request.deviationSource;
    h.date = request.date;
    h.compensated = coverage.compensated;
    h.notCompensated = coverage.notCompensated;
    for (Coverage& c : reversalsNotHeld(request, coverage.compensated))
        if (std::none_of(h.notCompensated.begin(), h.notCompensated.end(),
                         [&](const Coverage& n) { return n.deviation == c.deviation; }))
            h.notCompensated.push_back(std::move(c));
    h.notes = std::move(notes);
    // What the caller says of the values themselves (e.g. fitted to this controller over which workspace).
    h.notes.insert(h.notes.end(), request.headerNotes.begin(), request.headerNotes.end());
    return h;
}

std::string formatHeader(const HeaderInfo& h, std::string_view prefix, std::string_view suffix, std::string_view eol) {
    std::string out;
    line(out, prefix, suffix, eol, fmt::format("cnccomp compensation for {}", h.controller));
    const std::string file = std::filesystem::path(h.machineFile).filename().string();
    line(out, prefix, suffix, eol, file.empty() ? fmt::format("machine: {}", h.machine)
                                                : fmt::format("machine: {} ({})", h.machine, file));
    line(out, prefix, suffix, eol, fmt::format("deviation set: {}", h.deviationSource.empty() ? "-" : h.deviationSource));
    line(out, prefix, suffix, eol, fmt::format("date: {}", h.date.empty() ? "-" : h.date));
    line(out, prefix, suffix, eol, "compensated:");
    list(out, prefix, suffix, eol, h.compensated);
    line(out, prefix, suffix, eol, "NOT compensated:");
    list(out, prefix, suffix, eol, h.notCompensated);
    for (const std::string& n : h.notes) line(out, prefix, suffix, eol, n);
    return out;
}

std::string frameNote(const MachineModel& m) {
    std::string zeros;
    for (int a : controllerAxisOrder(m)) {
        const Link& l = m.axisLink(a);
        if (l.machineZero == 0.0) continue;
        const bool rotary = l.kind == AxisKind::Rotary;
        zeros += fmt::format("{}{} {:g} {}", zeros.empty() ? "" : ", ", l.name, rotary ? l.machineZero / kDeg : l.machineZero,
                             rotary ? "deg" : "mm");
    }
    if (zeros.empty())
        return "frame: positions in the controller's machine coordinates; the machine description gives no machine-zero, "
               "so its commands are taken as the machine coordinates (check: its zeros are the control's)";
    return fmt::format("frame: positions in the controller's machine coordinates = description commands - machine-zero ({})",
                       zeros);
}

std::string formatCoverage(const EmitResult& r) {
    std::string out = "compensated:\n";
    const auto add = [&](const std::vector<Coverage>& items) {
        if (items.empty()) out += "  (none)\n";
        size_t w = 0;
        for (const Coverage& c : items) w = std::max(w, c.deviation.size());
        for (const Coverage& c : items) out += fmt::format("  {:<{}}  {}\n", c.deviation, w, c.note);
    };
    add(r.compensated);
    out += "NOT compensated:\n";
    add(r.notCompensated);
    return out;
}

}  // namespace cnccomp::controllers::common

#include "controllers/linuxcnc/config_files.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"
#include "controllers/common/files.hpp"

namespace cnccomp::controllers::linuxcnc {
using namespace cnccomp::controllers::common;
using namespace cnccomp::io;

IniFragment parseIni(const std::string& text, const std::string& name) {
    IniFragment ini;
    std::string section;
    for (const TextLine& l : splitLines(text)) {
        const std::string_view s = trim(l.text);
        if (s.empty() || s.front() == '#' || s.front() == ';') continue;
        if (s.front() == '[') {
            if (s.back() != ']') throw InputError(name, l.number, "expected [SECTION]");
            section = std::string(s.substr(1, s.size() - 2));
            continue;
        }
        const size_t eq = s.find('=');
        if (eq == std::string_view::npos || section.empty())
            throw InputError(name, l.number, "expected KEY = value inside a [SECTION]");
        const std::string key(trim(s.substr(0, eq)));
        const std::string value(trim(s.substr(eq + 1)));
        if (section == "KINS" && key == "KINEMATICS") {
            const auto tok = tokens(value);
            if (tok.empty()) throw InputError(name, l.number, "KINEMATICS needs a module name");
            ini.kinematics = std::string(tok[0]);
            for (size_t i = 1; i < tok.size(); ++i)
                if (tok[i].starts_with("coordinates=")) ini.coordinates = std::string(tok[i].substr(12));
        } else if (section == "KINS" && key == "JOINTS") {
            const auto n = parseNumber(value);
            if (!n || *n < 1 || *n > 16 || *n != static_cast<int>(*n)) throw InputError(name, l.number, "JOINTS must be a count 1..16");
            ini.joints = static_cast<int>(*n);
        } else if (section == "TRAJ" && key == "COORDINATES") {
            for (char c : value)
                if (c != ' ') ini.trajCoordinates += c;
        } else if (section.starts_with("JOINT_")) {
            const auto n = parseNumber(std::string_view(section).substr(6));
            if (!n || *n < 0 || *n != static_cast<int>(*n)) throw InputError(name, l.number, fmt::format("bad section [{}]", section));
            if (key == "COMP_FILE") {
                if (value.empty()) throw InputError(name, l.number, "COMP_FILE needs a file name");
                ini.compFile[static_cast<int>(*n)] = value;
            } else if (key == "COMP_FILE_TYPE") {
                if (value != "0" && value != "1") throw InputError(name, l.number, "COMP_FILE_TYPE must be 0 or 1");
                ini.compType[static_cast<int>(*n)] = value == "1" ? 1 : 0;
            } else if (key == "BACKLASH") {
                const auto b = parseNumber(value);
                if (!b || !std::isfinite(*b)) throw InputError(name, l.number, "BACKLASH must be a number (mm or deg)");
                ini.backlash[static_cast<int>(*n)] = *b;
            }
        }
    }
    if (ini.kinematics.empty()) throw InputError(name, 0, "no [KINS] KINEMATICS line");
    return ini;
}

std::optional<TrtPins> parseHal(const std::string& text, const std::string& name, const std::string& module) {
    TrtPins p;
    bool any = false;
    for (const TextLine& l : splitLines(text)) {
        const std::string_view s = trim(l.text);
        if (s.empty() || s.front() == '#') continue;
        const auto tok = tokens(s);
        if (tok[0] == "net" || tok[0] == "loadrt" || tok[0] == "addf") continue;
        if (tok[0] != "setp" || tok.size() != 3) throw InputError(name, l.number, "expected 'setp <pin> <value>'");
        const std::string pin(tok[1]);
        if (!pin.starts_with(module + "."))
            throw InputError(name, l.number, fmt::format("pin '{}' is not a pin of {}", pin, module));
        const std::string short_ = pin.substr(module.size() + 1);
        const double v = requireNumber(tok[2], name, l.number, "the pin value");
        double* target = short_ == "x-rot-point" ? &p.xRotPoint
                         : short_ == "y-rot-point" ? &p.yRotPoint
                         : short_ == "z-rot-point" ? &p.zRotPoint
                         : short_ == "x-offset"    ? &p.xOffset
                         : short_ == "y-offset"    ? &p.yOffset
                         : short_ == "z-offset"    ? &p.zOffset
                         : short_ == "tool-offset" ? &p.toolOffset
                                                   : nullptr;
        if (!target) throw InputError(name, l.number, fmt::format("unknown pin '{}' of {}", short_, module));
        *target = v;
        any = true;
    }
    if (!any) return std::nullopt;
    return p;
}

std::string wrapCommentLines(const std::string& text, const std::string& prefix, size_t width) {
    std::string out;
    for (const TextLine& l : splitLines(text)) {
        std::string_view rest = l.text;
        if (rest.size() <= width || !rest.starts_with(prefix)) {
            out += std::string(rest) + "\n";
            continue;
        }
        rest.remove_prefix(prefix.size());
        std::string lead = prefix;
        while (!rest.empty()) {
            const size_t room = width - lead.size();
            size_t cut = rest.size();
            if (cut > room) {
                cut = rest.rfind(' ', room);
                if (cut == std::string_view::npos || cut == 0) cut = room;  // one long word: cut it
            }
            std::string_view piece = rest.substr(0, cut);
            while (!piece.empty() && piece.back() == ' ') piece.remove_suffix(1);
            out += lead + std::string(piece) + "\n";
            rest.remove_prefix(cut);
            while (!rest.empty() && rest.front() == ' ') rest.remove_prefix(1);
            lead = prefix + "  ";
        }
    }
    return out;
}

std::array<double, 3> parseWorkOffset(const std::string& text, const std::string& name) {
    std::optional<std::array<double, 3>> g54;
    for (const TextLine& l : splitLines(text)) {
        std::string_view s = trim(l.text);
        if (const size_t semi = s.find(';'); semi != std::string_view::npos) s = trim(s.substr(0, semi));
        if (s.empty() || (s.front() == '(' && s.back() == ')') || s == "M2" || s == "M30") continue;
        const auto tok = tokens(s);
        if (tok.size() != 6 || tok[0] != "G10" || tok[1] != "L2" || tok[2] != "P1")
            throw InputError(name, l.number, "expected 'G10 L2 P1 X<mm> Y<mm> Z<mm>'");
        std::array<double, 3> v{};
        for (int k = 0; k < 3; ++k) {
            const std::string_view w = tok[3 + k];
            if (w.empty() || w.front() != "XYZ"[k]) throw InputError(name, l.number, fmt::format("expected the {} word", "XYZ"[k]));
            v[k] = requireNumber(w.substr(1), name, l.number, fmt::format("a number after {}", "XYZ"[k]));
        }
        g54 = v;
    }
    if (!g54) throw InputError(name, 0, "no 'G10 L2 P1 X Y Z' line (the G54 work offset)");
    return *g54;
}

}  // namespace cnccomp::controllers::linuxcnc

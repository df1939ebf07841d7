#include "controllers/generic/deviation_json.hpp"

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_range.hpp"
#include "controllers/generic/json_text.hpp"
#include "cnccomp/io/markup.hpp"
#include "cnccomp/io/json.hpp"

namespace cnccomp::controllers::generic {
using namespace cnccomp::io;
namespace {
const char* kComponents[] = {"x", "y", "z", "a", "b", "c"};
const char* basisName(ComponentBasis::Type t) {
    return t == ComponentBasis::Type::Polynomial ? "polynomial" : t == ComponentBasis::Type::Fourier ? "fourier" : "table";
}
}  // namespace

std::string formatDeviationJson(const DeviationSet& d, const std::vector<std::string>& header, const std::string& source,
                                const std::string& date) {
    const MachineModel& m = d.machine();
    std::string s = "{\n  \"format\": \"cnccomp-deviations\",\n  \"version\": 1,\n  \"header\": [\n";
    for (size_t i = 0; i < header.size(); ++i) s += "    " + jsonString(header[i]) + (i + 1 < header.size() ? ",\n" : "\n");
    s += fmt::format("  ],\n  \"machine\": {},\n  \"deviationSet\": {},\n  \"date\": {},\n", jsonString(m.name), jsonString(source),
                     jsonString(date));
    s += "  \"units\": {\"length\": \"mm\", \"angle\": \"rad\", \"tablePositions\": \"mm or rad\"},\n  \"deviations\": [";
    bool first = true;
    for (size_t k = 0; k < m.deviations.size(); ++k) {
        if (!d.present[k]) continue;
        const DeviationDef& def = m.deviations[k];
        s += first ? "\n" : ",\n";
        first = false;
        s += fmt::format("    {{\"name\": {}, \"alias\": {}, \"kind\": \"{}\", \"side\": \"{}\", \"link\": {}, \"component\": \"{}\"",
                         jsonString(def.name), jsonString(def.alias), def.kind == DeviationKind::Location ? "location" : "component",
                         def.side == Side::Tool ? "tool" : "workpiece", jsonString(m.chain(def.side).links[def.link].name),
                         kComponents[def.component]);
        if (def.kind == DeviationKind::Location) {
            s += fmt::format(", \"value\": {}}}", jsonNumber(d.values[def.offset]));
        } else {
            s += fmt::format(", \"basis\": \"{}\"", basisName(def.basis.type));
            if (def.basis.type == ComponentBasis::Type::Table) s += ", \"nodes\": " + jsonNumbers(def.basis.nodes);
            else s += fmt::format(", \"order\": {}", def.basis.order);
            std::vector<double> c(d.values.data() + def.offset, d.values.data() + def.offset + def.size());
            s += ", \"coefficients\": " + jsonNumbers(c) + "}";
        }
    }
    s += "\n  ]\n}\n";
    return s;
}

DeviationSet readDeviationJson(const std::string& text, const std::string& file, const MachineModel& m) {
    const Json root = parseJson(text, file);
    if (root.type != Json::Type::Object) throw InputError(file, root.line, "expected a JSON object");
    if (root.require("format", Json::Type::String, file).string != "cnccomp-deviations")
        throw InputError(file, root.line, "format must be cnccomp-deviations");
    DeviationSet d(m);
    for (const Json& e : root.require("deviations", Json::Type::Array, file).array) {
        if (e.type != Json::Type::Object) throw InputError(file, e.line, "expected a deviation object");
        const std::string& name = e.require("name", Json::Type::String, file).string;
        const int k = m.deviationIndex(name);
        if (k < 0) throw InputError(file, e.line, fmt::format("unknown deviation '{}' for machine '{}'", name, m.name));
        const DeviationDef& def = m.deviations[k];
        const bool location = e.require("kind", Json::Type::String, file).string == "location";
        if (location != (def.kind == DeviationKind::Location) ||
            e.require("link", Json::Type::String, file).string != m.chain(def.side).links[def.link].name ||
            e.require("component", Json::Type::String, file).string != kComponents[def.component])
            throw InputError(file, e.line, fmt::format("'{}': kind, link or component differ from machine '{}'", name, m.name));
        if (location) {
            d.values[def.offset] = e.require("value", Json::Type::Number, file).number;
            if (const std::string why = deviationRangeProblem(def, d.values[def.offset]); !why.empty())
                throw InputError(file, e.line, why);
        } else {
            const std::vector<double> c = e.require("coefficients", Json::Type::Array, file).numbers(file);
            if (static_cast<int>(c.size()) != def.size())
                throw InputError(file, e.line, fmt::format("'{}' needs {} coefficients, has {}", name, def.size(), c.size()));
            for (int i = 0; i < def.size(); ++i) {
                if (const std::string why = deviationRangeProblem(def, c[i]); !why.empty()) throw InputError(file, e.line, why);
                d.values[def.offset + i] = c[i];
            }
        }
        d.present[k] = 1;
    }
    return d;
}

}  // namespace cnccomp::controllers::generic

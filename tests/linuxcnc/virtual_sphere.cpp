#include "linuxcnc/virtual_sphere.hpp"

#include <cctype>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "test_support.hpp"

namespace cnccomp::test::virtual_sphere {

namespace {
const char* const kLengths[] = {"EY0A", "EZ0A", "EX0C", "EY0C"};
const char* const kAngles[] = {"EB0A", "EC0A", "EA0C", "EB0C"};

bool isLength(const std::string& n) {
    for (const char* k : kLengths)
        if (n == k) return true;
    return false;
}
bool isAngle(const std::string& n) {
    for (const char* k : kAngles)
        if (n == k) return true;
    return false;
}
std::string lower(std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}
}  // namespace

std::filesystem::path source() { return sourcePath("tests/linuxcnc/virtual_sphere.comp"); }

std::string parameterHal(const std::string& module, const Setup& s) {
    std::string h;
    const auto setp = [&](const std::string& name, double v) { h += fmt::format("setp {}.{} {:.17g}\n", module, name, v); };
    setp("tool-length", s.toolLength);
    setp("ball-radius", s.ballRadius);
    setp("sphere-radius", s.sphereRadius);
    setp("sphere-x", s.sphere.x());
    setp("sphere-y", s.sphere.y());
    setp("sphere-z", s.sphere.z());
    setp("trigger-travel", s.triggerTravel);
    for (const char* n : kLengths) setp(lower(n), 0.0);
    for (const char* n : kAngles) setp(lower(n), 0.0);
    for (const auto& [name, value] : s.truth) {
        if (!isLength(name) && !isAngle(name)) throw std::runtime_error("virtual sphere: no deviation " + name);
        setp(lower(name), value);
    }
    return h;
}

std::string hal(const std::string& module, const std::string& coordinates, const Setup& s) {
    std::string h = fmt::format("# cnccomp test harness: the virtual sphere (tests/linuxcnc/virtual_sphere.comp)\n"
                                "loadrt {0}\naddf {0} servo-thread\n", module);
    for (char letter : std::string("XYZAC")) {
        const size_t j = coordinates.find(letter);
        if (j == std::string::npos) throw std::runtime_error("virtual sphere: no joint " + std::string(1, letter) + " in " + coordinates);
        h += fmt::format("net j{} => {}.{}\n", j, module, static_cast<char>(std::tolower(static_cast<unsigned char>(letter))));
    }
    h += fmt::format("net cnccomp-probe {}.probe => motion.probe-input\n", module);
    return h + parameterHal(module, s);
}

std::string truthCsv(const Truth& t) {
    std::string csv = "name,alias,value,unit\n";
    for (const auto& [name, value] : t)
        csv += isLength(name) ? fmt::format("{},,{:.17g},um\n", name, value / kUm) : fmt::format("{},,{:.17g},arcsec\n", name, value / kArcsec);
    return csv;
}

std::vector<Touch> readTouches(const std::filesystem::path& log) {
    std::vector<Touch> out;
    std::istringstream in(readText(log.string()));
    std::string line;
    int n = 0;
    while (std::getline(in, line)) {
        ++n;
        std::istringstream ls(line);
        std::string tag;
        if (!(ls >> tag) || tag != "TOUCH") continue;
        Touch t;
        double ok = 0;
        ls >> t.pose >> t.touch >> ok >> t.x >> t.y >> t.z >> t.a >> t.b >> t.c;
        if (!ls) throw std::runtime_error(fmt::format("{}:{}: unreadable TOUCH line: {}", log.string(), n, line));
        t.ok = ok == 1;
        out.push_back(t);
    }
    return out;
}

std::string raceSuspect(const std::vector<std::filesystem::path>& logs) {
    for (const auto& log : logs) {
        if (!std::filesystem::exists(log)) return log.string() + " missing";
        for (const Touch& t : readTouches(log))
            if (!t.ok) return fmt::format("{}: pose {} touch {} logged without a trigger", log.string(), t.pose, t.touch);
    }
    return {};
}

}  // namespace cnccomp::test::virtual_sphere

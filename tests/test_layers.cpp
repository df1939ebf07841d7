// The layers point one way (docs/ARCHITECTURE.md, "The rule"): every #include of a file under src/, controllers/ and
// postproc/ names a file of its own layer or of a layer below it.
//   core (src/cnccomp)             may include core only
//   controllers/, postproc/         core and themselves (not each other, not app, not cli)
//   application (src/app)          everything but src/cli
//   the CLI (src/cli)              everything
// Tests and benchmarks (tests/) and tools/ are not scanned. An include is resolved as the compiler does (the including
// file's folder, then src/, then the repository root); one that resolves to no file of the tree is classed by its
// first folder ("cnccomp/", "app/", …) or, failing that, is a system or library header and not checked.
// Oracle: the rule as written above, applied by hand to a synthetic tree whose upward includes are known
// (Layers.TheScannerReportsEveryUpwardInclude), then to the real tree (Layers.NoFileIncludesUpward).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>
#include <utility>
#include <vector>

#include "test_support.hpp"

namespace cnccomp {
namespace {

namespace fs = std::filesystem;

enum class Layer { Core, Controllers, Postproc, App, Cli, Outside };
constexpr std::array<Layer, 5> kLayers{Layer::Core, Layer::Controllers, Layer::Postproc, Layer::App, Layer::Cli};

const char* layerName(Layer l) {
    switch (l) {
        case Layer::Core: return "core (src/cnccomp)";
        case Layer::Controllers: return "controllers/";
        case Layer::Postproc: return "postproc/";
        case Layer::App: return "application (src/app)";
        case Layer::Cli: return "CLI (src/cli)";
        case Layer::Outside: break;
    }
    return "outside the layers";
}

bool startsWith(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

/// The layer of a path relative to the repository root ("src/cnccomp/kinematics.hpp").
Layer layerOfPath(const std::string& rel) {
    if (startsWith(rel, "src/cnccomp/")) return Layer::Core;
    if (startsWith(rel, "src/app/")) return Layer::App;
    if (startsWith(rel, "src/cli/")) return Layer::Cli;
    if (startsWith(rel, "controllers/")) return Layer::Controllers;
    if (startsWith(rel, "postproc/")) return Layer::Postproc;
    return Layer::Outside;
}

/// The layer an include names by its first folder when it resolves to no file ("cnccomp/x.hpp" from src/).
Layer layerOfIncludeText(const std::string& text) {
    if (startsWith(text, "cnccomp/")) return Layer::Core;
    if (startsWith(text, "app/")) return Layer::App;
    if (startsWith(text, "cli/")) return Layer::Cli;
    return layerOfPath(text);  // "controllers/…", "postproc/…", "src/…"
}

bool mayInclude(Layer from, Layer to) {
    if (to == Layer::Outside || from == to) return true;
    switch (from) {
        case Layer::Core: return false;
        case Layer::Controllers:
        case Layer::Postproc: return to == Layer::Core;
        case Layer::App: return to != Layer::Cli;
        case Layer::Cli: return true;
        case Layer::Outside: return true;
    }
    return true;
}

struct UpwardInclude {
    std::string file;     ///< relative to the root
    int line = 0;         ///< 1-based
    std::string include;  ///< as written: "controllers/backend.hpp" or <postproc/dialect.hpp>
    Layer from = Layer::Outside, to = Layer::Outside;
};

struct LayerScan {
    std::array<int, kLayers.size()> files{};  ///< files scanned per layer (kLayers order)
    int includesChecked = 0;                  ///< includes that resolved to a layer
    std::vector<UpwardInclude> upward;        ///< sorted by file, then line
};

/// Scans every C/C++ file under root/src, root/controllers and root/postproc.
LayerScan scanLayers(const fs::path& tree) {
    const fs::path root = fs::canonical(tree);  // no trailing separator: paths relative to it start at src/, …
    static const std::regex includeLine(R"(^\s*#\s*include\s*([<"])([^>"]+)[>"])");
    static const std::array<std::string, 8> extensions{".cpp", ".hpp", ".h", ".c", ".cc", ".hh", ".inc", ".ipp"};
    LayerScan scan;
    for (const char* top : {"src", "controllers", "postproc"}) {
        if (!fs::is_directory(root / top)) continue;
        for (const auto& entry : fs::recursive_directory_iterator(root / top)) {
            if (!entry.is_regular_file()) continue;
            const std::string ext = entry.path().extension().string();
            if (std::find(extensions.begin(), extensions.end(), ext) == extensions.end()) continue;
            const std::string rel = entry.path().lexically_relative(root).generic_string();
            const Layer from = layerOfPath(rel);
            if (from == Layer::Outside) continue;
            ++scan.files[static_cast<size_t>(std::find(kLayers.begin(), kLayers.end(), from) - kLayers.begin())];
            std::ifstream in(entry.path(), std::ios::binary);
            std::string text;
            for (int lineNo = 1; std::getline(in, text); ++lineNo) {
                std::smatch m;
                if (!std::regex_search(text, m, includeLine)) continue;
                const bool quoted = m[1] == "\"";
                const std::string name = m[2];
                std::vector<fs::path> candidates;
                if (quoted) candidates.push_back(entry.path().parent_path() / name);
                candidates.push_back(root / "src" / name);
                candidates.push_back(root / name);
                Layer to = Layer::Outside;
                bool resolved = false;
                for (const auto& c : candidates) {
                    if (!fs::is_regular_file(c)) continue;
                    to = layerOfPath(c.lexically_normal().lexically_relative(root).generic_string());
                    resolved = true;
                    break;
                }
                if (!resolved) to = layerOfIncludeText(name);
                if (to == Layer::Outside) continue;
                ++scan.includesChecked;
                if (!mayInclude(from, to))
                    scan.upward.push_back({rel, lineNo, quoted ? "\"" + name + "\"" : "<" + name + ">", from, to});
            }
        }
    }
    std::sort(scan.upward.begin(), scan.upward.end(), [](const UpwardInclude& a, const UpwardInclude& b) {
        return a.file != b.file ? a.file < b.file : a.line < b.line;
    });
    return scan;
}

std::string describe(const UpwardInclude& u) {
    return u.file + ":" + std::to_string(u.line) + ": #include " + u.include + " (" + layerName(u.from) +
           " may not include " + layerName(u.to) + ")";
}

std::vector<std::string> describeAll(const LayerScan& scan) {
    std::vector<std::string> out;
    for (const auto& u : scan.upward) out.push_back(describe(u));
    return out;
}

void writeTree(const fs::path& root, const std::vector<std::pair<std::string, std::string>>& files) {
    for (const auto& [rel, text] : files) {
        fs::create_directories((root / rel).parent_path());
        test::writeText((root / rel).string(), text);
    }
}

TEST(Layers, TheScannerReportsEveryUpwardInclude) {
    test::ScratchDir dir("layers");
    writeTree(dir.path, {
        // Allowed: core includes core and system headers.
        {"src/cnccomp/error.hpp", "#pragma once\n"},
        {"src/cnccomp/model.hpp", "#pragma once\n#include <vector>\n#include \"cnccomp/error.hpp\"\n"},
        // Upward: core includes a backend (line 3); a commented-out include is no include.
        {"src/cnccomp/io/reader.cpp",
         "#include \"cnccomp/model.hpp\"\n// #include \"app/verify.hpp\"\n#include \"controllers/backend.hpp\"\n"},
        // Upward through a relative path: resolved from the file's folder to src/app/verify.hpp (line 1).
        {"src/cnccomp/deep/x.cpp", "#include \"../../app/verify.hpp\"\n#include \"../model.hpp\"\n"},
        // Upward to a file that does not exist: classed by its first folder (line 1).
        {"src/cnccomp/ghost.cpp", "#include \"app/missing.hpp\"\n#include \"no_such_library.h\"\n"},
        // Allowed: a backend includes core and its own layer; upward: a backend includes postproc (angle brackets,
        // spaces after '#', line 3).
        {"controllers/backend.hpp", "#pragma once\n#include \"cnccomp/model.hpp\"\n"},
        {"controllers/fanuc/fanuc.cpp", "#include \"../backend.hpp\"\n#include \"cnccomp/error.hpp\"\n#  include <postproc/dialect.hpp>\n"},
        // Upward: postproc includes controllers (line 2) and the application layer (line 1).
        {"postproc/dialect.hpp", "#pragma once\n#include \"controllers/backend.hpp\"\n"},
        {"postproc/modal.cpp", "#include \"app/verify.hpp\"\n#include \"postproc/dialect.hpp\"\n"},
        // Allowed: the application layer includes every layer below; upward: it includes the CLI (line 4).
        {"src/app/verify.hpp",
         "#pragma once\n#include \"controllers/backend.hpp\"\n#include \"postproc/dialect.hpp\"\n#include \"cli/command.hpp\"\n"},
        // Allowed: the CLI includes anything; tests are not scanned.
        {"src/cli/command.hpp", "#pragma once\n"},
        {"src/cli/main.cpp", "#include \"app/verify.hpp\"\n#include \"cli/command.hpp\"\n#include \"controllers/backend.hpp\"\n"},
        {"tests/test_x.cpp", "#include \"cli/command.hpp\"\n"},
    });
    const LayerScan scan = scanLayers(dir.path);
    const std::vector<std::string> expected{
        "controllers/fanuc/fanuc.cpp:3: #include <postproc/dialect.hpp> (controllers/ may not include postproc/)",
        "postproc/dialect.hpp:2: #include \"controllers/backend.hpp\" (postproc/ may not include controllers/)",
        "postproc/modal.cpp:1: #include \"app/verify.hpp\" (postproc/ may not include application (src/app))",
        "src/app/verify.hpp:4: #include \"cli/command.hpp\" (application (src/app) may not include CLI (src/cli))",
        "src/cnccomp/deep/x.cpp:1: #include \"../../app/verify.hpp\" (core (src/cnccomp) may not include "
        "application (src/app))",
        "src/cnccomp/ghost.cpp:1: #include \"app/missing.hpp\" (core (src/cnccomp) may not include application "
        "(src/app))",
        "src/cnccomp/io/reader.cpp:3: #include \"controllers/backend.hpp\" (core (src/cnccomp) may not include "
        "controllers/)",
    };
    EXPECT_EQ(describeAll(scan), expected);
    // Files per layer: core 5, controllers 2, postproc 2, app 1, cli 2 (tests/ not scanned).
    EXPECT_EQ(scan.files, (std::array<int, 5>{5, 2, 2, 1, 2}));
}

TEST(Layers, NoFileIncludesUpward) {
    const LayerScan scan = scanLayers(fs::path(test::sourcePath("")));
    // The scan saw the tree: every layer has files, and includes were checked (an empty scan would pass for nothing).
    for (size_t i = 0; i < kLayers.size(); ++i) EXPECT_GT(scan.files[i], 0) << layerName(kLayers[i]);
    EXPECT_GT(scan.includesChecked, 500);
    for (const auto& u : scan.upward) ADD_FAILURE() << describe(u);
    EXPECT_TRUE(scan.upward.empty()) << scan.upward.size() << " upward includes (docs/ARCHITECTURE.md, The rule)";
}

// Namespaces match folders (docs/ARCHITECTURE.md, "Namespaces"): the first named `namespace X {` of every .hpp/.cpp
// under src/, controllers/ and postproc/ is the namespace its folder names — src/cnccomp → cnccomp,
// src/cnccomp/io → cnccomp::io, src/app/report → cnccomp::app::report, src/cli → cnccomp::cli,
// controllers/fanuc → cnccomp::controllers::fanuc, postproc/testprog → cnccomp::postproc::testprog — or a namespace
// nested in it that is not a subfolder's (cnccomp::postproc::iso, cnccomp::io::xml). A file that opens no named
// namespace (main.cpp, a forwarding header) declares nothing in one and is not checked. The namespace is read from
// the source text (line comments, block comments and string literals do not count), written `namespace a::b {`.
// Oracle: the rule as written above, applied by hand to a synthetic tree (Layers.TheNamespaceScanReportsEveryMismatch),
// then to the real tree (Layers.EveryNamespaceMatchesItsFolder).

/// The namespace a file's folder names ("src/cnccomp/io/csv.cpp" → "cnccomp::io").
std::string folderNamespace(const std::string& rel) {
    std::string folder = fs::path(rel).parent_path().generic_string();
    if (startsWith(folder, "src/")) folder = folder.substr(4);
    if (folder != "cnccomp" && !startsWith(folder, "cnccomp/")) folder = "cnccomp/" + folder;
    std::string ns;
    for (char c : folder) ns += c == '/' ? std::string("::") : std::string(1, c);
    return ns;
}

/// The first named namespace a source text opens ("" if none), and its 1-based line.
std::pair<std::string, int> firstNamespace(const std::string& text) {
    std::string code = text;  // comments and string literals blanked, newlines kept
    for (size_t i = 0; i < code.size(); ++i) {
        if (code.compare(i, 2, "//") == 0) {
            while (i < code.size() && code[i] != '\n') code[i++] = ' ';
        } else if (code.compare(i, 2, "/*") == 0) {
            const size_t end = code.find("*/", i + 2);
            const size_t stop = end == std::string::npos ? code.size() : end + 2;
            for (; i < stop; ++i)
                if (code[i] != '\n') code[i] = ' ';
            --i;
        } else if (code[i] == '"' && (i == 0 || code[i - 1] != '\'')) {
            for (code[i++] = ' '; i < code.size() && code[i] != '"' && code[i] != '\n'; ++i) {
                if (code[i] == '\\' && i + 1 < code.size()) code[i++] = ' ';
                code[i] = ' ';
            }
            if (i < code.size() && code[i] == '"') code[i] = ' ';
        }
    }
    static const std::regex named(R"(\bnamespace\s+([A-Za-z_]\w*(?:::[A-Za-z_]\w*)*)\s*\{)");
    std::smatch m;
    if (!std::regex_search(code, m, named)) return {"", 0};
    const auto offset = static_cast<size_t>(m.position(0));
    return {m[1], 1 + static_cast<int>(std::count(code.begin(), code.begin() + static_cast<std::ptrdiff_t>(offset), '\n'))};
}

struct NamespaceScan {
    int filesChecked = 0;                ///< files that open a named namespace
    std::vector<std::string> mismatches;  ///< "file:line: namespace X (the folder names Y)", sorted
};

NamespaceScan scanNamespaces(const fs::path& tree) {
    const fs::path root = fs::canonical(tree);
    NamespaceScan scan;
    for (const char* top : {"src", "controllers", "postproc"}) {
        if (!fs::is_directory(root / top)) continue;
        for (const auto& entry : fs::recursive_directory_iterator(root / top)) {
            const std::string ext = entry.path().extension().string();
            if (!entry.is_regular_file() || (ext != ".hpp" && ext != ".cpp")) continue;
            const std::string rel = entry.path().lexically_relative(root).generic_string();
            std::ifstream in(entry.path(), std::ios::binary);
            const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
            const auto [declared, line] = firstNamespace(text);
            if (declared.empty()) continue;
            ++scan.filesChecked;
            const std::string expected = folderNamespace(rel);
            bool ok = declared == expected;
            if (!ok && startsWith(declared, expected + "::")) {
                // A nested namespace of the folder's own, unless it is a subfolder's namespace.
                const std::string rest = declared.substr(expected.size() + 2);
                ok = !fs::is_directory(entry.path().parent_path() / rest.substr(0, rest.find(':')));
            }
            if (!ok)
                scan.mismatches.push_back(rel + ":" + std::to_string(line) + ": namespace " + declared +
                                          " (the folder names " + expected + ")");
        }
    }
    std::sort(scan.mismatches.begin(), scan.mismatches.end());
    return scan;
}

TEST(Layers, TheNamespaceScanReportsEveryMismatch) {
    test::ScratchDir dir("layers-ns");
    writeTree(dir.path, {
        // Match: the core's top folder, a core subfolder, a nested namespace of the folder's own.
        {"src/cnccomp/model.hpp", "#pragma once\n// namespace cnccomp::io { in a comment\nnamespace cnccomp {\n}\n"},
        {"src/cnccomp/io/csv.cpp", "#include <x>\nnamespace {\n}\nnamespace cnccomp::io {\n}\n"},
        {"src/cnccomp/io/xml.hpp", "namespace cnccomp::io::xml {\n}\n"},
        // Mismatch: a core subfolder's file left in cnccomp (line 3: the string literal and the block comment do
        // not count).
        {"src/cnccomp/io/plan.cpp", "/* namespace cnccomp::io { */\nconst char* s = \"namespace cnccomp::io {\";\n"
                                    "namespace cnccomp {\n}\n"},
        // Mismatch: a top-level core file in a subfolder's namespace (io is a folder), and the nested form.
        {"src/cnccomp/units.hpp", "namespace cnccomp::io {\n}\n"},
        {"src/cnccomp/io/nested.hpp", "namespace cnccomp {\nnamespace io {\n}\n}\n"},
        // Match: the application layer, its report folder, the CLI, a backend, postproc and its testprog folder.
        {"src/app/verify.hpp", "namespace cnccomp::app {\n}\n"},
        {"src/app/report/html.cpp", "namespace cnccomp::app::report {\n}\n"},
        {"src/cli/command.cpp", "namespace cnccomp::cli {\n}\n"},
        {"src/cli/main.cpp", "int main() { return 0; }\n"},  // no named namespace: not checked
        {"controllers/backend.hpp", "namespace cnccomp::controllers {\n}\n"},
        {"controllers/fanuc/fanuc.cpp", "namespace cnccomp::controllers::fanuc {\n}\n"},
        {"postproc/dialect.hpp", "namespace cnccomp::postproc {\n}\n"},
        {"postproc/testprog/run.cpp", "namespace cnccomp::postproc::testprog {\n}\n"},
        // Mismatch: a backend in its parent's namespace, postproc under its old short name, testprog in postproc.
        {"controllers/common/fit.hpp", "namespace cnccomp::controllers {\n}\n"},
        {"postproc/modal.hpp", "namespace cnccomp::pp {\n}\n"},
        {"postproc/testprog/plan.hpp", "namespace cnccomp::postproc {\n}\n"},
        // Not scanned: tests/, and files that are neither .hpp nor .cpp.
        {"tests/test_x.cpp", "namespace cnccomp::wrong {\n}\n"},
        {"src/cnccomp/notes.txt", "namespace wrong {\n}\n"},
    });
    const NamespaceScan scan = scanNamespaces(dir.path);
    const std::vector<std::string> expected{
        "controllers/common/fit.hpp:1: namespace cnccomp::controllers (the folder names cnccomp::controllers::common)",
        "postproc/modal.hpp:1: namespace cnccomp::pp (the folder names cnccomp::postproc)",
        "postproc/testprog/plan.hpp:1: namespace cnccomp::postproc (the folder names cnccomp::postproc::testprog)",
        "src/cnccomp/io/nested.hpp:1: namespace cnccomp (the folder names cnccomp::io)",
        "src/cnccomp/io/plan.cpp:3: namespace cnccomp (the folder names cnccomp::io)",
        "src/cnccomp/units.hpp:1: namespace cnccomp::io (the folder names cnccomp)",
    };
    EXPECT_EQ(scan.mismatches, expected);
    EXPECT_EQ(scan.filesChecked, 16);
}

TEST(Layers, EveryNamespaceMatchesItsFolder) {
    const NamespaceScan scan = scanNamespaces(fs::path(test::sourcePath("")));
    EXPECT_GT(scan.filesChecked, 300);  // the scan saw the tree (350 files; an empty scan would pass for nothing)
    for (const auto& m : scan.mismatches) ADD_FAILURE() << m;
}

}  // namespace
}  // namespace cnccomp

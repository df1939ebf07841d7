#include "app/verify_sources.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/text_util.hpp"
#include "postproc/testprog/test_program.hpp"

namespace cnccomp::app {
using namespace cnccomp::io;
using namespace cnccomp::measurement;

std::vector<controllers::OutputFile> readFolder(const std::string& dir) {
    namespace fs = std::filesystem;
    std::vector<controllers::OutputFile> files;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
        if (!e.is_regular_file(ec)) continue;
        std::ifstream in(e.path(), std::ios::binary);
        if (!in) throw InputError(e.path().string(), 0, "cannot read the file");
        std::ostringstream s;
        s << in.rdbuf();
        files.push_back({e.path().filename().string(), s.str()});
    }
    if (ec) throw InputError(dir, 0, "cannot list the folder: " + ec.message());
    std::sort(files.begin(), files.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
    return files;
}

namespace {

/// The list under the header line `title` ("NOT compensated:" or "compensated:", the latter not preceded by "NOT ").
std::vector<controllers::Coverage> readCoverageList(const std::vector<controllers::OutputFile>& files, const std::string& title) {
    for (const controllers::OutputFile& f : files) {
        std::istringstream in(f.content);
        std::string line;
        std::string prefix, suffix;
        bool inList = false;
        std::vector<controllers::Coverage> out;
        while (std::getline(in, line)) {
            if (!line.empty() && line.back() == '\r') line.pop_back();
            if (!inList) {
                const size_t at = line.find(title);
                if (at == std::string::npos || (title == "compensated:" && at >= 4 && line.compare(at - 4, 4, "NOT ") == 0)) continue;
                prefix = line.substr(0, at);
                suffix = std::string(trim(line.substr(at + title.size())));
                inList = true;
                continue;
            }
            if (line.compare(0, prefix.size() + 2, prefix + "  ") != 0) break;
            std::string item = line.substr(prefix.size());
            if (!suffix.empty() && item.size() >= suffix.size() && item.compare(item.size() - suffix.size(), suffix.size(), suffix) == 0)
                item.resize(item.size() - suffix.size());
            const std::string_view t = trim(item);
            if (t == "(none)" || t == "[none]") break;
            // "NAME  reason": the name column is padded and followed by two blanks (header.hpp); a name may hold one blank.
            const size_t sp = t.find("  ");
            out.push_back({std::string(t.substr(0, sp)), sp == std::string_view::npos ? "" : std::string(trim(t.substr(sp)))});
        }
        if (inList) return out;
    }
    return {};
}

}  // namespace

std::vector<controllers::Coverage> readNotCompensated(const std::vector<controllers::OutputFile>& files) {
    return readCoverageList(files, "NOT compensated:");
}

std::vector<controllers::Coverage> readCompensated(const std::vector<controllers::OutputFile>& files) {
    return readCoverageList(files, "compensated:");
}

namespace {

std::optional<postproc::Dialect> dialectOfExtension(std::string ext) {
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    for (auto d : {postproc::Dialect::Rs274ngc, postproc::Dialect::Fanuc, postproc::Dialect::Sinumerik,
                   postproc::Dialect::Heidenhain})
        if (ext == postproc::testprog::programExtension(d)) return d;
    return std::nullopt;
}

}  // namespace

LoadedCompensation loadCompensation(const MachineModel& m, const MeasurementPlan& plan, const std::string& path,
                                    const std::string& controller) {
    namespace fs = std::filesystem;
    std::error_code ec;
    LoadedCompensation out;
    VerifyCompensation& c = out.compensation;
    if (fs::is_regular_file(path, ec)) {
        if (!controller.empty()) throw InputError(path, 0, "--controller needs a folder of controller files, not a file");
        out.identified = readDeviationCsv(path, m);
        c.kind = VerifyCompensation::Kind::Deviations;
        c.description = fmt::format("ideal compensation of {} (a perfect TCP controller)", fs::path(path).filename().string());
        c.model = idealCompensation(m, *out.identified);
        c.files = {path};
        return out;
    }
    if (!fs::is_directory(path, ec)) throw InputError(path, 0, "no such file or folder");
    const std::vector<controllers::OutputFile> files = readFolder(path);
    const controllers::Backend* b = controller.empty() ? controllers::recognizeBackend(files) : &controllers::backend(controller);
    if (b) {
        c.kind = VerifyCompensation::Kind::ControllerFiles;
        c.backend = std::string(b->name());
        c.description = fmt::format("{} files in {}", b->name(), path);
        c.model = std::shared_ptr<const controllers::AppliedCompensation>(b->apply(m, files));
        if (!c.model) throw ModelError(fmt::format("backend '{}' returned no compensation model", b->name()));
        const std::vector<controllers::OutputFile> own = b->ownFiles(files);  // the route verified, of a folder holding several
        c.notCompensated = readNotCompensated(own);
        c.compensated = readCompensated(own);
        for (const auto& f : files) c.files.push_back((fs::path(path) / f.name).string());
        return out;
    }
    // Corrected test programs: TP<nn>_<run>.<ext>, one per run.
    const std::vector<postproc::testprog::RunMotion> motions = postproc::testprog::planMotions(m, plan);
    std::vector<std::string> missing;
    std::optional<postproc::Dialect> dialect;
    for (size_t i = 0; i < motions.size(); ++i) {
        const std::string stem = postproc::testprog::programFileName(motions[i].name, static_cast<int>(i) + 1, postproc::Dialect::Rs274ngc);
        const std::string base = stem.substr(0, stem.rfind('.'));
        const controllers::OutputFile* found = nullptr;
        for (const auto& f : files)
            if (f.name.size() > base.size() && f.name.compare(0, base.size() + 1, base + ".") == 0) found = &f;
        if (!found) {
            missing.push_back(motions[i].name);
            continue;
        }
        const auto d = dialectOfExtension(found->name.substr(base.size()));
        if (!d) throw InputError(fs::path(path) / found->name, 0, "unknown program extension (.ngc .nc .mpf .h)");
        if (dialect && *dialect != *d) throw InputError(path, 0, "the corrected programs are in more than one dialect");
        dialect = d;
        c.programs.push_back({motions[i].name, {found->name, found->content}});
        c.files.push_back((fs::path(path) / found->name).string());
    }
    if (c.programs.empty())
        throw InputError(path, 0,
                         "neither controller files of a known backend (cnccomp.ini, volcomp.lis, deviations.json, *.TAB, "
                         "CNCCOMP.PRM, CNCCOMP_KINCHAIN.SPF: or name one with --controller) nor corrected test programs "
                         "TP<nn>_<run>.<ext> of this plan");
    if (!missing.empty()) {
        std::string list;
        for (const auto& r : missing) list += (list.empty() ? "" : ", ") + r;
        throw InputError(path, 0, fmt::format("no corrected program for run(s) {}", list));
    }
    c.kind = VerifyCompensation::Kind::CorrectedPrograms;
    c.programDialect = *dialect;
    c.description = fmt::format("corrected test programs in {}", path);
    c.notCompensated = {};
    return out;
}

}  // namespace cnccomp::app

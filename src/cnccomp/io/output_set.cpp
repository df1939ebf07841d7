#include "cnccomp/io/output_set.hpp"

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::io {
namespace fs = std::filesystem;

namespace {

/// Hidden name beside `target` for the old content kept during commit(), unique within this process.
fs::path sideName(const fs::path& target, const char* tag) {
    static unsigned counter = 0;
    return target.parent_path() / fmt::format(".{}.{}{}-{}", target.filename().string(), tag, ::getpid(), ++counter);
}

fs::path folderOf(const std::string& path) {
    const fs::path p(path);
    return p.has_parent_path() ? p.parent_path() : fs::path(".");
}

}  // namespace

OutputSet::OutputSet(std::vector<std::string> inputs) : inputs_(std::move(inputs)) {}

OutputSet::~OutputSet() { rollback(); }

std::string fileNameProblem(std::string_view name) {
    if (name.empty()) return "it is empty";
    if (name == "." || name == "..") return "it names a folder";
    if (name.front() == '.') return "it starts with '.'";
    for (const char c : name) {
        if (c == '/' || c == '\\') return "it contains a path separator";
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return "it contains a control character";
    }
    return {};
}

std::string OutputSet::fileIn(const std::string& dir, const std::string& name, const std::string& source) {
    if (const std::string why = fileNameProblem(name); !why.empty())
        throw InputError(source, 0, fmt::format("'{}' cannot name a file in the output folder: {}", name, why));
    return (fs::path(dir) / name).string();
}

void OutputSet::makeFolder(const std::string& dir) {
    std::error_code ec;
    if (fs::is_directory(dir, ec)) return;
    if (fs::exists(dir, ec)) throw InputError(dir, 0, "exists and is not a folder");
    std::vector<fs::path> missing;
    for (fs::path p = fs::absolute(dir, ec); !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
        missing.push_back(p);
        if (p == p.parent_path()) break;
    }
    for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
        if (!fs::create_directory(*it, ec) && !fs::is_directory(*it))
            throw InputError(dir, 0, fmt::format("cannot create the folder: {}", ec.message()));
        createdDirs_.push_back(it->string());
    }
}

void OutputSet::add(const std::string& path, std::string_view content) {
    add(path, [&](std::ostream& o) { o.write(content.data(), static_cast<std::streamsize>(content.size())); });
}

void OutputSet::add(const std::string& path, const std::function<void(std::ostream&)>& write) {
    std::error_code ec;
    const fs::path target(path);
    if (!fs::is_directory(folderOf(path), ec)) throw InputError(path, 0, "output folder does not exist");
    const fs::file_status st = fs::status(target, ec);
    if (fs::exists(st) && !fs::is_regular_file(st))
        throw InputError(path, 0, "exists and is not a regular file; refusing to replace it");
    refuseToOverwrite(path, inputs_);
    for (const std::string& t : targets_)
        if (fs::absolute(t, ec).lexically_normal() == fs::absolute(target, ec).lexically_normal())
            throw InputError(path, 0, "this command would write the same file twice");
    auto file = std::make_unique<AtomicFile>(path);  // refuses a target that is not a regular file
    write(file->stream());
    file->close();  // a failure removes its temporary file: this file is not part of the set
    staged_.push_back(std::move(file));
    targets_.push_back(path);
}

void OutputSet::commit() {
    std::error_code ec;
    // Keep the old content of every existing target under a hard link until all renames went through.
    std::vector<std::string> backups(targets_.size());
    const auto cleanBackups = [&] {
        for (const std::string& b : backups)
            if (!b.empty()) fs::remove(b, ec);
    };
    for (size_t i = 0; i < targets_.size(); ++i) {
        if (!fs::exists(targets_[i], ec)) continue;
        const fs::path b = sideName(targets_[i], "old");
        fs::create_hard_link(targets_[i], b, ec);
        if (ec) fs::copy_file(targets_[i], b, ec);
        if (ec) {
            cleanBackups();
            throw InputError(targets_[i], 0, fmt::format("cannot keep the old file while replacing it: {}", ec.message()));
        }
        backups[i] = b.string();
    }
    for (size_t i = 0; i < targets_.size(); ++i) {
        std::string why;
        try {
            staged_[i]->commit();
            continue;
        } catch (const InputError& e) {
            why = e.what();
        }
        for (size_t k = 0; k < i; ++k) {  // put back what was replaced
            if (backups[k].empty()) fs::remove(targets_[k], ec);
            else fs::rename(backups[k], targets_[k], ec);
            backups[k].clear();
        }
        cleanBackups();
        throw InputError(targets_[i], 0, fmt::format("{}; no output was changed", why));
    }
    cleanBackups();
    staged_.clear();
    targets_.clear();
    createdDirs_.clear();
}

void OutputSet::rollback() noexcept {
    std::error_code ec;
    staged_.clear();  // each AtomicFile not committed removes its temporary file
    targets_.clear();
    for (auto it = createdDirs_.rbegin(); it != createdDirs_.rend(); ++it) fs::remove(*it, ec);  // only if empty
    createdDirs_.clear();
}

}  // namespace cnccomp::io

#pragma once
// Small helpers shared by the backends' writers and readers: finding an emitted file, splitting text into
// numbered lines and blank-separated tokens. (Fixed-point text without "-0": fixed() in controller_model.hpp.)
#include <string>
#include <string_view>
#include <vector>

#include "controllers/backend.hpp"

namespace cnccomp::controllers::common {

/// The file of that name, or nullptr.
const OutputFile* findFile(const std::vector<OutputFile>& files, std::string_view name);
/// The file of that name; throws InputError(name, 0, "missing") naming the backend.
const OutputFile& requireFile(const std::vector<OutputFile>& files, std::string_view name, std::string_view backend);

struct TextLine {
    int number = 0;          ///< 1-based
    std::string_view text;   ///< without the line end (CR removed)
};
/// Lines of a text, numbered from 1.
std::vector<TextLine> splitLines(std::string_view text);
/// Blank/tab separated tokens.
std::vector<std::string_view> tokens(std::string_view line);

/// A finite number from a token; throws InputError(file, line, "... expected <what>").
double requireNumber(std::string_view token, const std::string& file, int line, std::string_view what);

}  // namespace cnccomp::controllers::common

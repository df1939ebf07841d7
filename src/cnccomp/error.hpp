#pragma once
// Typed errors. Bad input names the file, the line and what was expected.
#include <stdexcept>
#include <string>

namespace cnccomp {

/// Malformed or inconsistent input. what() reads "file:line: message" (line omitted when 0).
class InputError : public std::runtime_error {
public:
    InputError(std::string file, int line, const std::string& message)
        : std::runtime_error(format(file, line, message)), file_(std::move(file)), line_(line) {}
    const std::string& file() const { return file_; }
    int line() const { return line_; }

private:
    static std::string format(const std::string& file, int line, const std::string& message) {
        // append() rather than operator+ : g++ 12 raises a false -Wrestrict on the latter.
        std::string s;
        s.append(file.empty() ? std::string("<input>") : file);
        if (line > 0) s.append(":").append(std::to_string(line));
        s.append(": ").append(message);
        return s;
    }
    std::string file_;
    int line_;
};

/// A request the model cannot satisfy (impossible geometry, unknown names, missing runs).
class ModelError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace cnccomp

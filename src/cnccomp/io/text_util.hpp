#pragma once
// Strict number parsing and atomic file writing shared by every reader and writer.
#include <functional>
#include <iosfwd>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace cnccomp::io {

/// Whole-string number ("1.5", "-2e-3", "inf", "-inf"); no trailing junk. NaN text is rejected.
std::optional<double> parseNumber(std::string_view s);
/// Trim ASCII white space.
std::string_view trim(std::string_view s);
/// The first line of a text file without its UTF-8 byte-order mark (Excel's and LibreOffice's "CSV UTF-8", Notepad's
/// "UTF-8 with BOM" write one). Every reader of a text file passes its first line through it.
/// Inline: the G-code lexer's fuzz target is built from the lexer's own sources alone.
inline std::string_view withoutByteOrderMark(std::string_view firstLine) {
    if (firstLine.substr(0, 3) == "\xef\xbb\xbf") firstLine.remove_prefix(3);
    return firstLine;
}

/// Checks, before any work, that `path` can be written atomically: its folder exists and it is absent or a regular
/// file (a symbolic link is followed to its target). A directory, a device (/dev/null), a FIFO or a socket is refused
/// with an InputError naming the path: the atomic rename would replace the node itself. Returns the path the file will
/// really be written at (the target of a link).
std::string checkOutputPath(const std::string& path);

/// A file written atomically: the data go into a temporary file created exclusively (O_CREAT | O_EXCL, mode 0666
/// less the umask, an unpredictable name) in the target's folder, which commit() renames over the target. Without
/// commit() (an exception, an early return) the temporary file is removed: a failed run leaves no half file.
/// The target is checked with checkOutputPath() first.
class AtomicFile {
public:
    explicit AtomicFile(const std::string& path);
    ~AtomicFile();
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;
    std::ostream& stream();
    /// Flushes, checks for write errors, keeps an existing target's permission bits and closes the temporary file,
    /// without renaming it yet (io/output_set.hpp renames several files together). Throws InputError.
    void close();
    /// close(), then renames the temporary file over the target. Throws InputError.
    void commit();
    /// The file the temporary file replaces (the target of a symbolic link).
    const std::string& target() const { return target_; }
    /// The temporary file's path (for tests).
    const std::string& temporaryPath() const { return tmp_; }

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    std::string path_, target_, tmp_;
    bool closed_ = false, committed_ = false;
};

/// Writes through `write` into an AtomicFile at `path` and commits it.
/// A failure leaves no half file. Refuses non-regular targets before `write` runs.
void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);
/// Throws InputError if `output` names the same file as one of the inputs ("" entries match nothing).
void refuseToOverwrite(const std::string& output, std::span<const std::string> inputs);
inline void refuseToOverwrite(const std::string& output, std::initializer_list<std::string> inputs) {
    refuseToOverwrite(output, std::span<const std::string>(inputs.begin(), inputs.size()));
}

/// The items of a comma list (an option's value such as "X, Y,,Z"), each trimmed, empty items left out.
std::vector<std::string> commaItems(std::string_view text);

}  // namespace cnccomp::io

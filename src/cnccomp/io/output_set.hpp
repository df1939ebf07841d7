#pragma once
// All-or-nothing output for commands that write several files (traces of every run, a report with its pictures,
// controller files): a failed command leaves every target as it was.
//
//   OutputSet out({machinePath, planPath});          // inputs: never overwritten
//   out.makeFolder(dir);                             // created now, removed again if nothing is committed
//   for (run : runs) out.add(OutputSet::fileIn(dir, run.name + ".csv"), [&](std::ostream& o) { ... });
//   out.commit();                                    // only now do the targets change
//
// add() writes the whole file at once into a hidden temporary file beside its target (an AtomicFile, io/text_util.hpp:
// created exclusively under an unpredictable name, in the same folder so the final rename is atomic). commit() renames every staged file onto its target; if a rename fails half way, the targets
// already replaced get their old content back (kept as hard links until the end). Without commit() (an exception,
// an early return) the destructor removes the temporary files and the folders this set created.
#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace cnccomp::io {

class AtomicFile;

/// Why `name` is not a plain file name (empty, '/' or '\\', "." or "..", a leading '.', a control character),
/// or an empty string when it is one.
std::string fileNameProblem(std::string_view name);

class OutputSet {
public:
    /// `inputs`: files this command reads; a target naming one of them is refused (InputError).
    explicit OutputSet(std::vector<std::string> inputs = {});
    ~OutputSet();
    OutputSet(const OutputSet&) = delete;
    OutputSet& operator=(const OutputSet&) = delete;

    /// `dir`/`name` for a name that comes from an input (a run name, a controller file name). Throws InputError
    /// naming `source` unless `name` is a plain file name: not empty, no '/' or '\\', not "." or "..", no leading
    /// '.', no control characters. So `name="../x"` can never write outside `dir`.
    static std::string fileIn(const std::string& dir, const std::string& name, const std::string& source = "");

    /// Creates `dir` and missing parents now; those created are removed again when the set is not committed.
    void makeFolder(const std::string& dir);

    /// Stages one file (the whole content, written now). Throws InputError for a target that is an input, a target
    /// that exists and is not a regular file, a missing folder, a target given twice, or a failed write.
    void add(const std::string& path, const std::function<void(std::ostream&)>& write);
    void add(const std::string& path, std::string_view content);

    /// Renames every staged file onto its target. After commit() the set is empty (it can be used again).
    void commit();

    /// Targets staged so far, in order.
    const std::vector<std::string>& targets() const { return targets_; }

private:
    void rollback() noexcept;

    std::vector<std::string> inputs_;
    std::vector<std::string> targets_;
    std::vector<std::unique_ptr<AtomicFile>> staged_;  ///< closed, not yet renamed
    std::vector<std::string> createdDirs_;  ///< outermost first
};

}  // namespace cnccomp::io

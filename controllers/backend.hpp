#pragma once
// A controller backend writes compensation files in one controller's own syntax and can read them back into
// an "apply" model: how that controller moves once the files are loaded. Each backend lives in
// controllers/<family>/ and registers itself with a RegisterBackend object.
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "cnccomp/deviations.hpp"

namespace cnccomp::controllers {

namespace common {
struct FitWorkspace;  // controllers/common/fit.hpp
}  // namespace common

struct EmitRequest {
    const MachineModel& machine;
    const DeviationSet& deviations;
    std::string deviationSource;  ///< file name of the deviation set, for the header comment
    std::string date;             ///< ISO date for the header comment
    /// The workspace over which the values written were fitted to this controller (controllers/common/fit.hpp), or
    /// null. A backend with several routes (e.g. LinuxCNC: generated kinematics, or pins and tables) fits the routes
    /// that cannot hold every deviation over it itself.
    const common::FitWorkspace* fitWorkspace = nullptr;
    /// Lines every file's header carries besides the coverage lists (what was fitted over which workspace, …).
    std::vector<std::string> headerNotes{};
};

struct OutputFile {
    std::string name;     ///< file name inside the output folder
    std::string content;  ///< exact bytes
};

/// One line of the coverage report: a deviation and how it is compensated, or why it is not.
struct Coverage {
    std::string deviation;
    std::string note;
};

struct EmitResult {
    std::vector<OutputFile> files;
    std::vector<Coverage> compensated;
    std::vector<Coverage> notCompensated;  ///< never dropped silently: also listed in every file header
    /// Lines `cnccomp emit` prints after the file list (e.g. which route each file set is). May be empty.
    std::vector<std::string> summary{};
};

/// The controller with the files loaded. The program commands axis positions meant for the nominal machine;
/// the controller sends other positions to the drives (table trims added to the commands, or a TCP
/// transformation recomputed with corrected kinematic parameters).
class AppliedCompensation {
public:
    virtual ~AppliedCompensation() = default;
    virtual AxisVector driveCommands(const AxisVector& programmed) const = 0;
    /// The same with the active tool length (mm) known: controllers that compensate at the tool tip (TCP-based
    /// volumetric compensation) use it; table-based models need not override it. The evaluation harness calls this.
    virtual AxisVector driveCommandsForTool(const AxisVector& programmed, double toolLength) const {
        (void)toolLength;
        return driveCommands(programmed);
    }
};

class Backend {
public:
    virtual ~Backend() = default;
    virtual std::string_view name() const = 0;         ///< e.g. "linuxcnc", "siemens-840d"
    virtual std::string_view description() const = 0;
    /// Throws ModelError when a limit of the controller is exceeded (table points, value ranges).
    virtual EmitResult emit(const EmitRequest& request) const = 0;
    /// Parses the files (InputError with file:line on syntax errors) and models how the controller uses them.
    virtual std::unique_ptr<AppliedCompensation> apply(const MachineModel& machine,
                                                       const std::vector<OutputFile>& files) const = 0;
    /// Conventions no vendor document confirmed (marked [G] in the files), each as what the user must check on the
    /// control before loading the files. `cnccomp emit --help` lists them. Default: none.
    virtual std::vector<std::string> checks() const { return {}; }
    /// Whether a folder's files are this backend's output, by the file names its emit() writes (registry.cpp keeps
    /// the table; a backend may override).
    virtual bool recognizes(const std::vector<OutputFile>& files) const;
    /// The files of a folder that are this backend's (a folder may hold several routes of one controller, e.g.
    /// LinuxCNC's component and pins-and-tables routes): verify reads the coverage lists from these. Default: all.
    virtual std::vector<OutputFile> ownFiles(const std::vector<OutputFile>& files) const { return files; }
    /// Whether fitting the deviation values to this controller (controllers/common/fit.hpp) can leave less than copying
    /// them. False where the files hold the error itself, sampled (the generic grid map): what the copy leaves there is
    /// the sampling's (the node budget), and moving deviation values only bends the sampled error elsewhere. Default: true.
    virtual bool fitsDeviationValues() const { return true; }
};

/// All registered backends, sorted by name.
std::vector<const Backend*> backends();
/// Backend by name; throws ModelError listing the known names.
const Backend& backend(std::string_view name);
/// The one backend that recognizes `files` (Backend::recognizes); nullptr when none does. Throws ModelError naming the
/// candidates when several do.
const Backend* recognizeBackend(const std::vector<OutputFile>& files);

struct RegisterBackend {
    explicit RegisterBackend(std::unique_ptr<Backend> b);
};

}  // namespace cnccomp::controllers

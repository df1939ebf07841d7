#pragma once
// Harness that runs the real LinuxCNC 2.9 (Debian 12 package linuxcnc-uspace) headless in simulation as a test
// oracle: a sim configuration built from the files `cnccomp emit --controller linuxcnc` wrote, merged the way their
// README.txt tells a user to, ideal drives (motor-pos-cmd looped back as feedback), and driver.py as the "display"
// that executes MDI blocks and records joint pins.
//
// Facts it relies on (observed on 2.9, see ../shared/linuxcnc-sim/README.md): rtapi_app refuses to run as root
// unless RTAPI_UID names another user and RTAPI_FIFO_PATH a fifo that user can create; `[EMC] VERSION = 1.1` keeps
// the INI updater (a GUI) away; the INI folder must be writable; one LinuxCNC per machine (/tmp/linuxcnc.lock, fixed
// shared-memory keys), so the tests that start it share a ctest RESOURCE_LOCK; a comp value is ramped in by a
// filter whose residual is bounded by 0.5·a·SERVO_PERIOD², a being the joint's acceleration limit, which control.c caps
// at [TRAJ] DEFAULT_LINEAR_ACCELERATION after homing (free mode; measured: tests/linuxcnc/test_linuxcnc_backlash.cpp),
// hence a 50 µs servo period here; on a
// loaded machine (ctest -j, POSIX non-realtime threads) motion answers task late: [EMCMOT] COMM_TIMEOUT = 30 s, since
// a timed-out command is sent again and the comp-table loader then refuses the repeated line ("compensation values
// must increase"); a move is over when the commanded position has reached the block's words (driver.py).
#include <array>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "cnccomp/machine.hpp"

namespace cnccomp::test::linuxcnc_sim {

/// Empty when the real LinuxCNC can run here, otherwise why not (for GTEST_SKIP).
std::string unavailableReason();

/// Merges an INI fragment into an INI text as the emitted README.txt tells a user: every `KEY = value` of a
/// section of the fragment replaces the key of the same name in the same section of the base, or is added at the
/// end of that section; sections the base lacks are appended. Comments of the fragment are dropped.
std::string mergeIni(const std::string& base, const std::string& fragment);

struct Tool {
    int number = 1;
    double length = 0;  ///< mm, tool table Z
};

/// A sim configuration folder: the machine's own INI (joint travel in LinuxCNC's coordinates from the machine
/// description, BACKLASH on every joint, ideal drives) merged with the route's INI fragment; base.hal, then the route's
/// HAL fragment as a second HALFILE (its setp lines set the pins); the route's files; a tool table; driver.py.
/// base.hal also nets motion.analog-out-03 to motion.switchkins-type (README.txt: M68 E3 Qn + M66 E0 L0 switches the
/// kinematics mode) and, with `sampled`, a `sampler` on the servo thread that records every joint's
/// joint.N.motor-pos-cmd, then every axis' axis.L.pos-cmd, motion.tooloffset.z, motion.program-line and the
/// SimOptions::sampledSignals each servo cycle (driver.py runs halsampler).
struct SimConfig {
    std::filesystem::path dir, ini;
    int joints = 0;
    std::string coordinates;  ///< joint letters in joint order
    size_t sampledSignals = 0;  ///< SimOptions::sampledSignals.size()
};

enum class Route { Pins, Component };

struct SimOptions {
    Route route = Route::Pins;
    int servoPeriodNs = 50000;  ///< 50 us for the joint tables' comp filter (see above); the component route needs none
    bool sampled = false;
    double taskCycle = 0.001;  ///< [TASK] CYCLE_TIME, s (the probing tests take 0.01: see run())
    /// Joint limits of ±100000 instead of the description's travel: a world-straight move in tool-tip mode that turns
    /// a rotary axis takes the joints far out of the travel on the way (LinuxCNC would stop it at the limit).
    bool wideJointLimits = false;
    /// Net motion.switchkins-type (M68 E3): false for a kinematics module without switchable kinematics (trivkins has
    /// no such pin in 2.9: "Pin 'motion.switchkins-type' does not exist").
    bool switchkins = true;
    /// Component route: the module name the component was installed under (installComponent); the emitted files'
    /// cnccomp_kins is renamed to it.
    std::string module;
    /// A third HAL file (`harness.hal`, loaded after the route's), made from the joint letters in joint order: the
    /// test's own components, e.g. the virtual sphere. None when empty.
    std::function<std::string(const std::string& coordinates)> extraHal;
    /// With `sampled`: HAL signals recorded as further float columns after the program line (Sample::extra), one per
    /// name: base.hal nets each to a sampler pin; the test's extraHal gives the signal its writer. halsampler prints
    /// floats with %f (1e-6 of the unit): a quantity wanted finer is sampled scaled (e.g. a sum2 with gains ±1e6).
    std::vector<std::string> sampledSignals;
    /// With `sampled`: the sampler's FIFO in servo cycles. halsampler, a user process, drains it; on a loaded machine it
    /// can fall behind by seconds, and a full FIFO loses samples (RunResult::overruns): a run at 50 us wants more.
    int samplerDepth = 20000;
};

/// Builds the configuration in `dir` from the folder `emitted` (what `cnccomp emit` wrote, read as it is).
/// `backlash` is the BACKLASH (mm or deg) the machine's own INI gives every joint.
SimConfig buildSimConfig(const MachineModel& m, const std::filesystem::path& emitted, const std::filesystem::path& dir,
                         const std::vector<Tool>& tools, double backlash, const SimOptions& options = {});

/// Empty when halcompile can build and install a component here (root, linuxcnc-uspace-dev), otherwise why not.
std::string componentUnavailableReason();
/// Compiles and installs the emitted component (`emitted`/cnccomp_kins.comp) under the name `module` (its text with
/// cnccomp_kins renamed: one installed module per test, never a stale one) with `halcompile --install`, in `work`.
/// Throws std::runtime_error with halcompile's output on failure. Returns the seconds it took.
double installComponent(const std::filesystem::path& emitted, const std::string& module, const std::filesystem::path& work);
/// Compiles and installs the halcompile source `source`, whose component is called `name`, under the name `module`
/// (every `name` in its text renamed) with `halcompile --install`, in `work`. Throws std::runtime_error with
/// halcompile's output on failure. Returns the seconds it took.
double installComp(const std::filesystem::path& source, const std::string& name, const std::string& module,
                   const std::filesystem::path& work);
/// Removes an installed module (its .so in LinuxCNC's module folder).
void uninstallComponent(const std::string& module);
/// Uninstalls a module when it goes out of scope.
struct InstalledModule {
    std::string module;
    explicit InstalledModule(std::string name) : module(std::move(name)) {}
    InstalledModule(const InstalledModule&) = delete;
    InstalledModule& operator=(const InstalledModule&) = delete;
    ~InstalledModule() { uninstallComponent(module); }
};

/// One `record` of the job: the joint pins after a move.
struct Record {
    std::string label;
    bool settled = false;  ///< every joint's comp filter had reached its target
    double toolOffset = 0; ///< motion.tooloffset.z
    std::vector<double> posCmd, motorPosCmd, backlashCorr, backlashFilt;
    std::array<double, 9> g5x{};  ///< stat.g5x_offset (the active work offset, XYZABCUVW)
};

/// One servo cycle of a `sample` job line: joint.N.motor-pos-cmd per joint, then axis.L.pos-cmd per coordinate letter.
struct Sample {
    long cycle = 0;
    std::vector<double> motor, axis;  ///< joint.N.motor-pos-cmd, axis.L.pos-cmd (joint order)
    double toolOffset = 0;            ///< motion.tooloffset.z
    long programLine = 0;             ///< motion.program-line (the executing motion's line of the program, 1-based)
    std::vector<double> extra;        ///< SimOptions::sampledSignals, in their order
};

struct RunResult {
    std::vector<Record> records;
    std::vector<Sample> samples;
    double seconds = 0;
    long overruns = 0;  ///< samples lost by the sampler's FIFO (must be 0)
    int retries = 0;    ///< runs started again after one of LinuxCNC's probing races (run())
};

/// Runs LinuxCNC on the configuration with a job (lines `mdi <G-code>` / `record <label>` / `auto <program file>` /
/// `sample <program file>` / `setp <pin or parameter> <value>`, see driver.py) and returns the records. Throws std::runtime_error with the end of
/// LinuxCNC's log when the run fails; a run that LinuxCNC aborted with "Queue is not empty after probing" (an upstream
/// race after probe moves, see run()) or with "Probe is already tripped when starting G38.2" (its stale DONE before a
/// probe move, postproc/testprog/probe_program.hpp) starts again, at most 12 times in all (RunResult::retries). With the environment variable CNCCOMP_LINUXCNC_KEEP=<folder> the run's folder
/// (INI, HAL, job, log) is copied there.
/// `suspect`, when given, is asked after a run that succeeded: a non-empty answer (why) marks the run as hit by that race
/// all the same (its silent form: the read-ahead passes the queue test with the stale status and the LOG line after the
/// probe gets the untripped probe, #5070 = 0) and it starts again like the others.
RunResult run(const SimConfig& c, const std::vector<std::string>& job, const std::function<std::string()>& suspect = {});
/// The records of run() (the MDI tests).
std::vector<Record> runJob(const SimConfig& c, const std::vector<std::string>& job, double* seconds = nullptr);

}  // namespace cnccomp::test::linuxcnc_sim

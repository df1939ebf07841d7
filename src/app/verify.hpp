#pragma once
// Verification through what the user loads (DESIGN data flow, step 5): the plan's test programs
// (postproc/testprog, generated in memory and read back through the post-processor, never recomputed) go through a
// compensation to a machine, and the simulated instrument readings are analysed exactly like measured ones.
//   compensation: a deviation set (ideal: what a perfect TCP controller or `cnccomp correct` does with it), the
//   files of `cnccomp emit` (read back by the backend: Backend::apply), or test programs corrected by `cnccomp correct`
//   (read back by the post-processor and run as they are);
//   machine: the true one (simulation with --truth) or the identified one (the prediction of what the compensation
//   leaves on the machine that was measured, given what the controller can hold).
// Per run and pass (CW, CCW): the ΔL trace before and after, ISO 230-4 circular deviation G and radial deviation F
// (evaluateCircularTest), eccentricity ([MultiTasking] eq. (14), Table 5 convention), ΔL span; R-test runs: the ball
// displacement ([Moravek2019]). The volumetric tool-tip error over the plan's workspace before and after, and the deviations
// the compensation leaves, with the backend's reason. A plain struct, for the terminal, --json and the HTML report.
#include <memory>
#include <string>
#include <vector>

#include "cnccomp/ballbar.hpp"
#include "cnccomp/deviations.hpp"
#include "cnccomp/identification/dbb5_circular.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "controllers/backend.hpp"
#include "postproc/dialect.hpp"
#include "postproc/testprog/program_syntax.hpp"
#include "postproc/testprog/run_motion.hpp"

namespace cnccomp::app {

/// What the test programs' commands go through before they reach the drives.
struct VerifyCompensation {
    enum class Kind { None, Deviations, ControllerFiles, CorrectedPrograms };
    Kind kind = Kind::None;
    std::string description;  ///< e.g. "ideal compensation of deviations.csv", "siemens-840d files in DIR"
    std::string backend;      ///< ControllerFiles: the backend's name
    /// Deviations / ControllerFiles: the controller with the compensation loaded (drive = model(programmed, tool length)).
    std::shared_ptr<const controllers::AppliedCompensation> model;
    /// CorrectedPrograms: run name → (file name, program text), read in `programDialect`.
    std::vector<std::pair<std::string, std::pair<std::string, std::string>>> programs;
    postproc::Dialect programDialect = postproc::Dialect::Rs274ngc;
    /// What the compensation leaves, and why (the backend's NOT-compensated list).
    std::vector<controllers::Coverage> notCompensated;
    /// What it takes, and how (the backend's compensated list from the files' header; empty when they carry none).
    std::vector<controllers::Coverage> compensated;
    /// The files it was read from (paths), for reports.
    std::vector<std::string> files;
};

/// The ideal compensation of an identified set: drive commands that put the tool of the identified machine where the
/// nominal machine would have it, solved on the exact model (inverse_kinematics.hpp); unconverged poses pass unchanged.
std::shared_ptr<const controllers::AppliedCompensation> idealCompensation(const MachineModel& machine,
                                                                          const DeviationSet& identified);

struct VerifyOptions {
    postproc::Dialect dialect = postproc::Dialect::Rs274ngc;  ///< the in-memory test programs
    int volumetricPerAxis = 5;  ///< grid over the plan's workspace: samples per axis
};

/// The plan's workspace, over which verify takes its volumetric figure: `options.volumetricPerAxis` samples per axis over
/// the box of the commands of the plan's runs (as its test programs write them), at the runs' tool lengths.
struct PlanWorkspace {
    std::vector<AxisVector> poses;
    std::vector<double> toolLengths;  ///< mm, each once, in the order of the runs
    std::string note;                 ///< "5 per axis over the commands of the plan's runs (X=…), tool lengths 100 mm"
};
PlanWorkspace planWorkspace(const MachineModel& machine, const measurement::MeasurementPlan& plan, const VerifyOptions& options = {});

/// One pass (direction) of a run, before and after compensation.
struct VerifyPass {
    std::string label;                  ///< "CW", "CCW", "forward", "reverse"
    BallbarTrace before, after;         ///< angle_deg = sweep parameter; dL in mm (R-test: |d| in mm)
    std::vector<Vec3> displacementBefore, displacementAfter;  ///< R-test: ball − nest, sensor frame, mm
    bool circular = false;              ///< ISO values below are filled (ball-bar kinds with ≥ 5 samples)
    CircularTestResult isoBefore, isoAfter;
    Vec3 eccentricityBefore = Vec3::Constant(NAN), eccentricityAfter = Vec3::Constant(NAN);  ///< mm, machine X Y Z
    double spanBefore = 0, spanAfter = 0;  ///< mm: max − min ΔL; R-test: largest span of a displacement component
    /// Non-empty when the compensated commands leave an axis' travel (a real control would stop with a limit alarm);
    /// the readings are still simulated there.
    std::string outsideTravel;
};

struct VerifyRun {
    std::string name;
    postproc::testprog::RunKind kind = postproc::testprog::RunKind::Ballbar;
    std::string type;      ///< "B-X", "DBB5 XY circle", "R-test", …
    double LB = 0;         ///< bar length, mm (0 for R-test)
    std::string program;   ///< the test program's file name
    std::vector<VerifyPass> passes;
    double spanBefore() const;
    double spanAfter() const;
};

struct VerifyVolumetric {
    bool available = false;
    std::string note;           ///< why not, or what the grid was
    long points = 0;
    std::vector<double> toolLengths;  ///< mm
    double maxBefore = 0, rmsBefore = 0, maxAfter = 0, rmsAfter = 0;  ///< tool-tip error, mm
    double tiltBefore = 0, tiltAfter = 0;                             ///< largest tool-axis error, rad
};

/// A deviation the compensation leaves, named and valued the way an engineer adjusts it by hand: under its ISO 230-1
/// name its ISO value (DeviationSet::isoValue: the standard's reference axis and sign, iso_names.hpp), and under the
/// paper alias the alias' own value (DeviationSet::aliasValue), never the link value of the kinematic chain. Units as
/// the deviation CSV writer writes them (µm, arcsec). A component error (EXX …) shows its largest coefficient.
struct VerifyRemaining {
    std::string deviation;      ///< name as the backend lists it (e.g. "EC0Y", "EBB (constant part)")
    std::string reason;
    bool valueKnown = false;    ///< the name is a deviation of the machine
    std::string isoName;        ///< the machine's ISO name of that deviation (valueKnown)
    double value = 0;           ///< under the ISO name, in the simulated machine, display units
    std::string unit;           ///< "um" or "arcsec"
    std::string alias;          ///< the paper alias, empty when the machine has none (or a component error)
    double aliasValue = 0;      ///< under the alias (alias non-empty), same unit
};

/// verify's own gate, which holds whatever the options say: a compensation that leaves the machine worse than none.
/// "Worse" = the largest span after exceeds the one before by more than the allowance, or the volumetric tool-tip
/// error (max) after exceeds the one before by more than its allowance. Allowance = max(0.1 µm, 1 % of before).
/// Why: verify simulates the readings without noise, so after and before differ only by what the compensation does
/// and by the rounding of the values in its files; 0.1 µm is what the closed loop holds every backend to for what it
/// claims (tests/app/test_verify_loop.cpp, README "Test programs and verification"), and below the 0.2–0.5 µm reading noise
/// the samples simulate for a ball bar. The 1 % leaves alone a compensation that changes a large error by less than
/// an engineer would act on ([G] a judgement, not a figure of a standard).
struct VerifyWorse {
    bool span = false;          ///< the largest span grew beyond its allowance
    bool volumetric = false;    ///< the volumetric tool-tip error grew beyond its allowance
    double spanAllowance = 0, volumetricAllowance = 0;  ///< mm
    /// Runs whose own largest span grew beyond the allowance of their own before, "zx 1.660 -> 3.973 um", while the
    /// largest span over the plan did not (a compensation can help one circle and hurt another, e.g. a backlash value
    /// on a slide without lost motion): said by verify, not gated (the gate is the largest span).
    std::vector<std::string> runs{};
    bool any() const { return span || volumetric; }
};
inline constexpr double kWorseFloorMm = 1e-4;    ///< 0.1 µm
inline constexpr double kWorseRelative = 0.01;   ///< 1 % of before

struct VerifyResult {
    std::string machine;
    std::string simulated;      ///< "true machine (T.csv)" / "identified machine (D.csv)"
    std::string compensation;   ///< VerifyCompensation::description
    std::vector<VerifyRun> runs;
    VerifyVolumetric volumetric;
    std::vector<VerifyRemaining> remaining;
    double residualBefore = 0;  ///< largest span of any run before compensation, mm
    double residual = 0;        ///< largest span of any run after compensation, mm (what --max-residual-um gates)
    VerifyWorse worse;          ///< the compensation leaves the machine worse than none (exit status 1 in any case)
};

/// Whether after exceeds before by more than max(kWorseFloorMm, kWorseRelative · before) (VerifyWorse).
VerifyWorse compensationWorse(const VerifyResult& result);
/// The banner of a compensation that makes the machine worse: "COMPENSATION MAKES THE MACHINE WORSE: largest ΔL span
/// 70.250 -> 86.300 um (allowance 0.703 um); …"; empty when it does not.
std::string worseBanner(const VerifyResult& result);

/// Runs the loop. `simulated` is the machine the commands reach (truth or identified); `simulatedName` says which.
/// Throws ModelError / InputError (a corrected program missing or malformed, commands outside the travel …).
VerifyResult verify(const MachineModel& machine, const measurement::MeasurementPlan& plan, const DeviationSet& simulated,
                    const std::string& simulatedName, const VerifyCompensation& compensation, const VerifyOptions& options = {});

}  // namespace cnccomp::app

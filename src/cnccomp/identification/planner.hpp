#pragma once
// Test planner: proposes a small set of ball-bar runs, chosen from candidate run types ([MultiTasking]
// Table 2) × geometries, that makes a list of deviations identifiable by the least-squares engine with a good
// condition number, and explains which deviation needs which run.
//
// Every candidate is simulated on the nominal machine and differentiated (the first-order, structural
// identifiability of ObservableSubspace); its mounting offsets, when estimated, are eliminated (Schur
// complement). Selection is greedy D-optimal: each step adds the candidate that most increases
// (rank, Σ log sᵢ) of the stacked scaled Jacobian; once every requested deviation is identifiable, runs are added
// while the condition number exceeds the target, then runs whose removal keeps the request identifiable within
// the target are pruned.
#include <string>
#include <vector>

#include "cnccomp/io/plan_xml.hpp"

namespace cnccomp::identification {

struct PlannerOptions {
    std::vector<int> identify;          ///< deviation indices (required)
    std::vector<BallbarTest> types;     ///< candidate run types; empty = every type the machine allows
    std::vector<double> LB{100.0}, RB{360.0, 410.0}, RC{50.0}, ZC{300.0, 340.0};  ///< candidate geometries, mm
    double evaluationStepDeg = 10.0;    ///< sample spacing used to rate the candidates
    double planStepDeg = 1.0;           ///< angle step written into the plan
    std::string mounting = "none";      ///< estimate-mounting of every run: none, tool, work, both
    /// What identification will use: "traces" (raw ΔL samples, BallbarObservation) or "eccentricity" (circle
    /// centres only, as [MultiTasking]'s closed form; EccentricityObservation).
    std::string observe = "traces";
    int maxRuns = 10;
    double targetCondition = 300.0;     ///< of the scaled Jacobian (µm, arcsec)
    double rankTolerance = 1e-7;
};

/// Why a requested deviation is identified: runs it cannot do without, runs that see it, predicted uncertainty.
struct DeviationNeed {
    int deviation = -1;
    std::string name, alias;
    bool identified = false;
    std::vector<std::string> needs;    ///< runs of the plan without which it is no longer identifiable
    std::vector<std::string> seenBy;   ///< runs of the plan whose ΔL it changes (≥ 5 % of its strongest run)
    double sigmaPerUm = 0;             ///< predicted standard deviation (µm or arcsec) per 1 µm of ΔL noise
    std::vector<std::string> confoundedWith;  ///< when not identified: the unknowns it is confounded with
};

/// For a deviation of the machine that was not requested: does the plan identify it too, and what would.
struct ExtraAdvice {
    int deviation = -1;
    std::string name, alias;
    bool identifiedByPlan = false;     ///< the plan identifies it along with the request
    std::vector<std::string> needs;    ///< when identified: runs it needs
    double sigmaPerUm = 0;             ///< when identified
    /// Candidate run types whose measurement it changes at all (≥ 5 % of the most sensitive candidate), e.g. only
    /// "C-Y" for γXY seen through eccentricities ([MultiTasking] Table 3).
    std::vector<std::string> seenByTypes;
    /// Candidate runs that, added to the plan, identify it along with the request; best (smallest σ) first.
    std::vector<std::string> extraRuns;
    std::vector<double> extraSigmaPerUm;
};

struct PlanProposal {
    measurement::MeasurementPlan plan;
    bool complete = false;             ///< every requested deviation is identifiable
    int rank = 0, unknowns = 0;
    double conditionNumber = 0;
    std::vector<DeviationNeed> needs;  ///< one per requested deviation (coefficient rows merged)
    std::vector<ExtraAdvice> others;   ///< one per machine deviation not requested
    std::vector<std::string> steps;    ///< how the runs were chosen
    std::vector<std::string> rejected; ///< candidates that could not run (travel, geometry) and why
    int candidates = 0;
};

/// Throws ModelError for an empty request, bad options, or a machine that allows no candidate run.
PlanProposal proposePlan(const MachineModel& machine, const PlannerOptions& options);

/// Candidate run name: the test name plus the geometry, e.g. "C-radial_RB410_ZC340" (file-name safe).
std::string candidateName(const BallbarRun& r);

}  // namespace cnccomp::identification

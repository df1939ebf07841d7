#pragma once
// The outcome of an identification, as a report object (in the spirit of Ceres' Summary): termination, cost,
// residuals per run, singular values, identifiable combinations of confounded deviations, covariance and
// 95 % intervals. Written to JSON by io/report_json.hpp.
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace cnccomp::identification {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// One unknown (deviation, component-error coefficient or nuisance parameter). Values in internal units.
struct ParameterEstimate {
    std::string name, alias;
    bool nuisance = false;
    bool angle = false;              ///< display unit arcsec, else um
    bool identified = true;          ///< false: lies in an unobservable direction, value meaningless (left at start)
    double start = 0, value = 0;     ///< mm / rad; ISO value of a location error (iso_names.hpp)
    double aliasValue = kNaN;        ///< value under the paper alias (deviations with an alias), mm / rad
    double stddev = kNaN;            ///< from the residuals (linearised covariance), mm / rad
    double lower95 = kNaN, upper95 = kNaN;
    double mcStddev = kNaN, mcLower95 = kNaN, mcUpper95 = kNaN;  ///< Monte Carlo (when requested)
    double displayScale() const;     ///< internal units per display unit
    const char* unit() const { return angle ? "arcsec" : "um"; }
};

/// A linear combination Σ coef_i · parameter_i (internal units: the coefficient of an angle in a length
/// combination is a length in mm, and so on). Used for identifiable combinations of confounded deviations
/// and for unobservable directions.
struct Combination {
    std::vector<std::string> names;
    std::vector<double> coefficients;  ///< first one is 1
    std::string text;                  ///< "EX0C + 360·EB0B"
    bool angle = false;                ///< unit of the value (that of the first parameter)
    double value = kNaN, stddev = kNaN;  ///< internal units of the first parameter (identifiable combinations)
};

struct RunResidual {
    std::string run, kind;
    int samples = 0;
    double rmsBefore = 0, rmsAfter = 0;  ///< unweighted residual RMS, mm
    double maxAfter = 0;                 ///< largest |residual| after, mm
};

/// Model adequacy of one run (identification/adequacy.hpp): its residual against the noise its data can have.
struct RunAdequacy {
    std::string run;
    std::string noiseSource;          ///< "passes", "stated", "successive differences" (see adequacy.hpp)
    double noise = kNaN;              ///< one sample's noise standard deviation, mm
    double statistic = kNaN;          ///< F = (Σ r² / dof) / noise²
    double dof = 0, noiseDof = 0;     ///< degrees of freedom of the residual share and of the noise estimate
    double threshold = kNaN;          ///< F quantile at the run's confidence
    bool fits = true;
    double harmonicShare = kNaN;      ///< share of Σ (r − mean)² carried by orders 1–6 of the sweep angle (NaN: no sweep)
    std::vector<double> harmonics;    ///< amplitude of orders 1..6 of the residual over the sweep angle, mm
    std::vector<std::string> turningAxes;
};

/// Does the model fit the data? A χ²/F test of the residual against the noise, per run and overall, with the residual's
/// harmonics as the signature of what is missing.
struct Adequacy {
    bool tested = false;              ///< false: no run carries a noise estimate
    bool fits = true;
    double confidence = 0.999;        ///< overall; each run at 1 − (1 − confidence) / runs (Bonferroni)
    double statistic = kNaN, threshold = kNaN, dof = 0, noiseDof = 0;  ///< overall F test
    double inflation = 1;             ///< factor applied to stddev and 95 % intervals (1 when the model fits)
    std::string inflationRule;        ///< how `inflation` was found
    std::vector<std::string> suspected;  ///< "component errors of C (EXC EYC EZC EAC EBC ECC)", …
    std::string option;               ///< the option that adds them, e.g. "--params all"
    std::string message;              ///< the warning line (empty when the model fits)
    std::vector<RunAdequacy> runs;
};

struct IdentificationReport {
    std::string machine;
    std::string method = "least-squares";
    std::string solver;                  ///< "levenberg-marquardt" or "nlopt:<algorithm>"
    std::string termination;             ///< why the solver stopped
    bool converged = false;
    int iterations = 0;
    int evaluations = 0;                 ///< residual evaluations
    double costBefore = 0, costAfter = 0;  ///< ½ Σ r², r in µm (weighted)
    int observations = 0, unknowns = 0, rank = 0, dof = 0;
    double sigma = kNaN;                 ///< residual standard deviation estimate, mm (weighted units)
    double conditionNumber = kNaN;       ///< of the scaled Jacobian, over its identifiable part
    double rankTolerance = 0;            ///< relative singular value threshold
    std::vector<double> singularValues;  ///< of the scaled Jacobian (µm of residual per µm / arcsec)
    std::vector<ParameterEstimate> parameters;
    std::vector<RunResidual> runs;
    std::vector<Combination> identifiable;  ///< identifiable combinations of unidentified parameters
    std::vector<Combination> unobservable;  ///< directions the measurements cannot see
    std::vector<std::string> unidentified;  ///< names of the unidentified parameters
    int monteCarloSamples = 0;
    Eigen::MatrixXd covariance;          ///< internal units, parameter order; NaN rows for unidentified ones
    std::vector<std::string> warnings;
    Adequacy adequacy;                   ///< the residual against the noise (warnings[0] when the model does not fit)
    std::string stages;                  ///< how a staged fit went (staged_fit.hpp); empty for one fit of every run

    /// Index of a parameter by name or alias, or -1.
    int find(const std::string& nameOrAlias) const;
};

}  // namespace cnccomp::identification

#pragma once
// ISO 230-2:2014 evaluation of the bidirectional positioning runs of one linear axis (laser interferometer):
// "Test code for machine tools — Part 2: Determination of accuracy and repeatability of positioning of numerically
// controlled axes", clause 2 (terms and definitions) and clause 4 (test procedure). Definitions as implemented
// (i = target, j = run, ↑ = approach in the positive direction, ↓ = negative):
//  - positional deviation x_ij = P_ij − P_i (actual reached minus target position);
//  - mean unidirectional positional deviation x̄_i↑ = (1/n) Σ_j x_ij↑ (and ↓);
//  - mean bidirectional positional deviation x̄_i = (x̄_i↑ + x̄_i↓) / 2;
//  - reversal value B_i = x̄_i↑ − x̄_i↓; axis reversal value B = max |B_i|; mean reversal value B̄ = (1/m) Σ B_i;
//  - estimator of the unidirectional standard uncertainty s_i↑ = √(Σ_j (x_ij↑ − x̄_i↑)² / (n − 1)) (and ↓);
//  - unidirectional repeatability R_i↑ = 4 s_i↑ (and ↓); bidirectional repeatability
//    R_i = max(2 s_i↑ + 2 s_i↓ + |B_i|; R_i↑; R_i↓); R↑ = max R_i↑, R↓ = max R_i↓, R = max R_i;
//  - unidirectional systematic positional deviation E↑ = max x̄_i↑ − min x̄_i↑ (and ↓); bidirectional
//    E = max(x̄_i↑, x̄_i↓) − min(x̄_i↑, x̄_i↓);
//  - range of the mean bidirectional positional deviation M = max x̄_i − min x̄_i;
//  - unidirectional accuracy A↑ = max(x̄_i↑ + 2 s_i↑) − min(x̄_i↑ − 2 s_i↑) (and ↓); bidirectional accuracy
//    A = max(x̄_i↑ + 2 s_i↑; x̄_i↓ + 2 s_i↓) − min(x̄_i↑ − 2 s_i↑; x̄_i↓ − 2 s_i↓).
// Minimum test: ISO 230-2 4.3.2 asks for five runs in each direction at every target and at least five targets
// per metre of travel with a minimum of five; fewer are refused here (runs, targets; the per-metre density is
// reported as a warning, since short axes and the first-metre rule are common). The expanded uncertainty of
// ISO 230-2 clause 5 / ISO/TR 230-9 is not computed.
// The positioning error as a function of position: x̄↑(P) and x̄↓(P), piecewise linear through the target means
// (constant beyond the end targets) — the form pitch-error compensation tables take (the LinuxCNC one:
// controllers/linuxcnc/laser_comp.hpp).
#include <string>
#include <vector>

namespace cnccomp {

/// Bidirectional runs of one axis: targets (mm, strictly increasing) × runs × direction, deviations in µm.
struct LaserPositioningRuns {
    std::string axis = "X";
    std::string source;                    ///< file the runs came from (for messages), may be empty
    std::vector<double> targets;           ///< P_i, mm, strictly increasing
    /// x_ij, µm: forward[j][i] = deviation of run j at target i approached in the positive direction; reverse
    /// likewise for the negative direction. Runs in the order measured.
    std::vector<std::vector<double>> forward, reverse;
    bool environmentCompensated = false;   ///< the laser's air/material compensation was applied (stated in the report)
    int minimumRuns = 5;                   ///< ISO 230-2 4.3.2: 5; lower only for a stated non-standard test (≥ 2)
};

struct LaserTargetResult {
    double target = 0;                           ///< mm
    double meanForward = 0, meanReverse = 0;     ///< x̄_i↑, x̄_i↓, µm
    double mean = 0;                             ///< x̄_i, µm
    double reversal = 0;                         ///< B_i, µm
    double sForward = 0, sReverse = 0;           ///< s_i↑, s_i↓, µm
    double repeatabilityForward = 0, repeatabilityReverse = 0, repeatability = 0;  ///< R_i↑, R_i↓, R_i, µm
};

struct LaserPositioningResult {
    std::string axis;
    bool environmentCompensated = false;
    int runs = 0;
    std::vector<LaserTargetResult> targets;
    double E = 0, EForward = 0, EReverse = 0;    ///< µm
    double M = 0;                                ///< µm
    double A = 0, AForward = 0, AReverse = 0;    ///< µm
    double B = 0, meanReversal = 0;              ///< B = max |B_i|, B̄ = mean B_i, µm
    double R = 0, RForward = 0, RReverse = 0;    ///< µm
    std::vector<std::string> warnings;

    /// Positioning error (µm) at position `mm`, approached in the positive (forward = true) or negative direction:
    /// linear between the target means, constant beyond the end targets.
    double errorAt(double mm, bool forward) const;
};

/// Throws InputError (file = runs.source) for: no runs in one direction ("one direction only"), unequal run counts
/// between the directions, a run whose length differs from the number of targets, fewer than minimumRuns runs or
/// fewer than five targets, targets not strictly increasing, non-finite values.
LaserPositioningResult evaluateLaserPositioning(const LaserPositioningRuns& runs);

}  // namespace cnccomp

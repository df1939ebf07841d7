#include "cnccomp/io/trace_import.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/csv.hpp"
#include "cnccomp/io/output_set.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::io {
namespace {

/// One sample (24 bytes: a 1 kHz file has millions of them).
struct Row {
    int line = 0;
    int label = -1;               ///< index of the pass label in the file's list of labels (-1 without a pass column)
    double x = 0;                 ///< angle (deg) or time (s)
    double dL = 0;                ///< mm (rows without a value are counted missing and not kept)
};

std::string lower(std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

int findColumn(const CsvRow& header, const std::string& name) {
    for (size_t i = 0; i < header.cells.size(); ++i)
        if (header.cells[i] == name) return static_cast<int>(i);
    for (size_t i = 0; i < header.cells.size(); ++i)
        if (lower(header.cells[i]) == lower(name)) return static_cast<int>(i);
    return -1;
}

/// An empty cell is a missing sample; "nan" and other text are errors (a number was expected).
bool isMissing(const std::string& cell) { return cell.empty(); }

/// A number cell with the capture's decimal rules; InputError naming the column otherwise.
double parseCell(const std::string& path, int line, const std::string& column, const std::string& cell, char sep,
                 char decimal) {
    std::string s = cell;
    const bool comma = s.find(',') != std::string::npos;
    if (comma) {
        if (sep == ',' || decimal == '.' || s.find('.') != std::string::npos)
            throw InputError(path, line, fmt::format("column '{}': '{}' is not a number (decimal {})", column, cell,
                                                     decimal == '.' ? "point expected" : "comma and point mixed"));
        std::replace(s.begin(), s.end(), ',', '.');
    } else if (decimal == ',' && s.find('.') != std::string::npos) {
        throw InputError(path, line, fmt::format("column '{}': '{}' has a decimal point; the plan says decimal comma",
                                                 column, cell));
    }
    const auto v = parseNumber(s);
    if (!v || !std::isfinite(*v))
        throw InputError(path, line, fmt::format("column '{}': expected a finite number, found '{}'", column, cell));
    return *v;
}

struct Pass {
    int direction = +1;
    std::vector<Row> rows;
};

constexpr double kUmInMm = 1e-3;
/// Spans below this (mm) are numerically zero (a run no deviation of a simulated truth shows).
constexpr double kNumericalZero = 1e-8;
/// A span this many times the other runs' (or less) is taken for a unit mistake.
constexpr double kUnitRatio = 200.0;
/// The smallest step a ball bar resolves, mm: 0.1 µm, the resolution quoted for the Renishaw QC20-W [G: not read from
/// the vendor's data sheet here].
constexpr double kBallbarResolution = 1e-4;
/// The largest |ΔL| a ball bar records: ±1 mm (Renishaw QC20-W measuring range [G]) or 1% of a long bar's length.
double maxBallbarTravel(double barLength) { return std::max(1.0, 0.01 * barLength); }

double peakToPeak(const std::vector<double>& v) {
    if (v.empty()) return 0.0;
    const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
    return *hi - *lo;
}

std::string lengthUnitText(double unit) {
    return unit == 1.0 ? "mm" : unit == 1e-3 ? "um" : unit == 1e-6 ? "nm" : unit == 25.4 ? "in" : fmt::format("{:g} mm", unit);
}

bool near(double a, double b) { return std::abs(a - b) <= 1e-6 * std::max(1.0, std::abs(b)); }

/// Checks the `# key: value` comments from index `from` on.
void checkMetadata(const std::string& path, const std::vector<CsvComment>& comments, size_t from, const BallbarRun& run,
                   const std::string& machine, TraceImportSummary& summary) {
    for (size_t i = from; i < comments.size(); ++i) {
        const CsvComment& m = comments[i];
        const std::string key = lower(m.key);
        const auto mismatch = [&](const std::string& planned) {
            throw InputError(path, m.line, fmt::format("the file says {} '{}', but run '{}' of the plan has {}: this file "
                                                       "belongs to another run or setup",
                                                       m.key, m.value, run.name, planned));
        };
        const auto number = [&](double planned) {
            const auto v = parseNumber(m.value);
            if (!v) throw InputError(path, m.line, fmt::format("'{}: {}' is not a number", m.key, m.value));
            if (!near(*v, planned)) mismatch(fmt::format("{:g}", planned));
        };
        if (key == "run") {
            if (m.value != run.name) mismatch(fmt::format("the name '{}'", run.name));
        } else if (key == "test") {
            if (m.value != testName(run.test)) mismatch(std::string(testName(run.test)));
        } else if (key == "machine") {
            if (!machine.empty() && m.value != machine) mismatch(fmt::format("machine '{}'", machine));
            if (machine.empty()) continue;
        } else if (key == "lb") number(run.LB);
        else if (key == "rb") number(run.RB);
        else if (key == "rc") number(run.RC);
        else if (key == "zc") number(run.ZC);
        else if (key == "start") number(run.startDeg);
        else if (key == "end") number(run.endDeg);
        else if (key == "step") number(run.stepDeg);
        else if (key == "feed") {
            if (run.capture.feed == 0) continue;
            number(run.capture.feed);
        } else continue;
        ++summary.metadataChecked;
    }
}

/// Pass label → direction (+1/−1), or 0 for a pass number (resolved from the plan's order).
int labelDirection(const std::string& label) {
    const std::string l = lower(label);
    if (l == "ccw" || l == "+" || l == "+1") return +1;
    if (l == "cw" || l == "-" || l == "-1") return -1;
    return 0;
}

/// ΔL and τ of a pass interpolated at `angle` (clamped to the pass's ends).
void sampleAt(const std::vector<double>& angle, const std::vector<double>& value, const std::vector<double>& tau,
              double at, double& v, double& t) {
    size_t best = 0;
    for (size_t i = 1; i < angle.size(); ++i)
        if (std::abs(angle[i] - at) < std::abs(angle[best] - at)) best = i;
    v = value[best];
    t = tau[best];
    for (size_t i = 0; i + 1 < angle.size(); ++i) {
        const double a0 = angle[i], a1 = angle[i + 1];
        if (a0 == a1 || (at - a0) * (at - a1) > 0) continue;
        const double f = (at - a0) / (a1 - a0);
        v = value[i] + f * (value[i + 1] - value[i]);
        t = tau[i] + f * (tau[i + 1] - tau[i]);
        return;
    }
}

}  // namespace

double linearPathRadius(const BallbarRun& r) {
    switch (r.test) {  // [MultiTasking] Table 2, the (X, Y, Z) circle of runCommands()
        case BallbarTest::BRadial: return r.LB + r.RB;
        case BallbarTest::BTangential: return std::hypot(r.RB, r.LB);
        case BallbarTest::CRadial: return std::abs(r.RC - r.LB);
        case BallbarTest::CTangential: return std::hypot(r.RC, r.LB);
        case BallbarTest::BAxial:
        case BallbarTest::BX:
        case BallbarTest::BY:
        case BallbarTest::BZ: return r.RB;
        case BallbarTest::CAxial:
        case BallbarTest::CX:
        case BallbarTest::CY:
        case BallbarTest::CZ: return r.RC;
    }
    return 0.0;
}

namespace {

/// Samples per plan step above which a pass is averaged into bins of the step.
constexpr double kBinFactor = 4.0;

/// Mean angle and ΔL of the rows nearest each sweep angle origin + k·step (the rows in sweep order; a bin's line is
/// its first row's). Adds the rows averaged to `sum.binnedFrom` and the bins to `sum.binnedInto`.
std::vector<Row> binnedRows(const std::vector<Row>& rows, double origin, double step, TraceImportSummary& sum) {
    std::vector<Row> out;
    long current = 0;
    double angle = 0, value = 0;
    int n = 0, firstLine = 0;
    const auto flush = [&] {
        Row b;
        b.line = firstLine;
        b.x = angle / n;
        b.dL = value / n;
        out.push_back(std::move(b));
        angle = value = 0;
        n = 0;
    };
    for (const Row& r : rows) {
        const long k = std::lround((r.x - origin) / step);
        if (n > 0 && k != current) flush();
        if (n == 0) current = k, firstLine = r.line;
        angle += r.x;
        value += r.dL;
        ++n;
    }
    if (n > 0) flush();
    sum.binnedFrom += static_cast<int>(rows.size());
    sum.binnedInto += static_cast<int>(out.size());
    return out;
}

/// The file's columns, as the header names them.
struct Columns {
    int headerLine = 0;
    char separator = ',';
    int x = -1, dL = -1, pass = -1;  ///< angle or time; ΔL; pass label (-1: none)
    bool timeSampled = false;
    std::string nameX, nameL, namePass;
};

Columns findColumns(const std::string& path, const CsvRow& header, char separator, const RunCapture& cap) {
    Columns c;
    c.headerLine = header.line;
    c.separator = separator;
    c.dL = findColumn(header, cap.lengthColumn);
    if (c.dL < 0)
        throw InputError(path, c.headerLine, fmt::format("missing column '{}' (ΔL) in the header", cap.lengthColumn));
    c.x = findColumn(header, cap.angleColumn);
    c.timeSampled = c.x < 0;
    if (c.timeSampled) c.x = findColumn(header, cap.timeColumn);
    if (c.x < 0)
        throw InputError(path, c.headerLine, fmt::format("missing column '{}' (angle) or '{}' (time) in the header (found {} "
                                                         "column(s) separated by '{}')",
                                                         cap.angleColumn, cap.timeColumn, header.cells.size(),
                                                         separatorName(separator)));
    c.pass = findColumn(header, cap.passColumn);
    c.nameX = header.cells[c.x];
    c.nameL = header.cells[c.dL];
    c.namePass = c.pass >= 0 ? header.cells[c.pass] : "";
    return c;
}

/// Rows → samples, one row at a time (a large file streams); `labels` gets the pass labels, one entry per change of
/// label down the file.
std::vector<Row> readRows(const std::string& path, CsvReader& reader, const Columns& col, const RunCapture& cap,
                          std::vector<std::string>& labels, TraceImportSummary& sum) {
    const double xUnit = col.timeSampled ? cap.timeUnit : cap.angleUnit;
    std::vector<Row> rows;
    CsvRow csvRow;
    while (reader.next(csvRow)) {
        ++sum.rows;
        const int line = csvRow.line;
        const auto& cells = csvRow.cells;
        const auto cell = [&](int c) -> const std::string& {
            static const std::string empty;
            return c < static_cast<int>(cells.size()) ? cells[c] : empty;
        };
        if (isMissing(cell(col.x)) || isMissing(cell(col.dL))) {
            ++sum.missing;
            continue;
        }
        Row r;
        r.line = line;
        r.x = parseCell(path, line, col.nameX, cell(col.x), col.separator, cap.decimal) * xUnit;
        r.dL = parseCell(path, line, col.nameL, cell(col.dL), col.separator, cap.decimal) * cap.lengthUnit;
        if (col.pass >= 0) {
            const std::string& label = cell(col.pass);
            if (label.empty()) throw InputError(path, line, fmt::format("column '{}' is empty", col.namePass));
            if (labels.empty() || labels.back() != label) labels.push_back(label);
            r.label = static_cast<int>(labels.size()) - 1;
        }
        rows.push_back(std::move(r));
    }
    return rows;
}

/// Against the bar length: a ball bar records at most ±1 mm (or 1% of a long bar); more is a unit mistake (a µm export
/// read under length-unit="mm").
void checkBarTravel(const std::string& path, const std::vector<Row>& rows, const BallbarRun& run, const RunCapture& cap) {
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    const Row* worst = &rows.front();
    for (const Row& r : rows) {
        lo = std::min(lo, r.dL);
        hi = std::max(hi, r.dL);
        if (std::abs(r.dL) > std::abs(worst->dL)) worst = &r;
    }
    const double size = cap.relativeLength ? hi - lo : std::abs(worst->dL);
    const double limit = maxBallbarTravel(run.LB);
    if (size > limit)
        throw InputError(path, worst->line,
                         fmt::format("ΔL {} {:.4g} mm, more than a ball bar of {:g} mm records (±{:g} mm): the file is "
                                     "likely in {} while the plan reads it in {} (length-unit of <instrument> or of run "
                                     "'{}')",
                                     cap.relativeLength ? "spans" : "reaches", size, run.LB, limit,
                                     cap.lengthUnit == 1.0 ? "um" : cap.lengthUnit == 1e-3 ? "nm" : "a smaller unit",
                                     lengthUnitText(cap.lengthUnit), run.name));
}

/// The rows split into passes: by the pass column, by time going back (time-sampled), or where the angle turns back;
/// directions from the labels or the plan (`planned`).
std::vector<Pass> splitPasses(const std::string& path, std::vector<Row>& rows, const std::vector<std::string>& labels,
                              const Columns& col, const std::vector<int>& planned) {
    std::vector<Pass> passes;
    if (col.pass >= 0) {
        std::vector<std::string> seen;
        for (const Row& r : rows) {
            const std::string& label = labels[static_cast<size_t>(r.label)];
            if (passes.empty() || label != seen.back()) {
                if (std::find(seen.begin(), seen.end(), label) != seen.end())
                    throw InputError(path, r.line, fmt::format("pass '{}' starts again after another pass; the rows of a "
                                                               "pass must follow each other", label));
                seen.push_back(label);
                Pass p;
                const int d = labelDirection(label);
                if (d != 0) {
                    p.direction = d;
                } else {
                    const auto k = parseNumber(label);
                    if (!k || *k != std::floor(*k) || *k < 1 || *k > static_cast<double>(planned.size()))
                        throw InputError(path, r.line,
                                         fmt::format("pass '{}': expected ccw, cw, +, - or a pass number 1..{} (the "
                                                     "plan's directions)", label, planned.size()));
                    p.direction = planned[static_cast<size_t>(*k) - 1];
                }
                passes.push_back(std::move(p));
            }
            passes.back().rows.push_back(r);
        }
    } else if (col.timeSampled) {
        for (const Row& r : rows) {
            if (passes.empty() || r.x < passes.back().rows.back().x) passes.emplace_back();
            passes.back().rows.push_back(r);
        }
        for (size_t i = 0; i < passes.size() && i < planned.size(); ++i) passes[i].direction = planned[i];
    } else {
        // Angle-sampled without a pass column: unwrap, then split where the angle turns back (the extreme angle).
        for (size_t i = 1; i < rows.size(); ++i) {
            const double d = rows[i].x - rows[i - 1].x;
            if (std::abs(d) > 180.0) rows[i].x -= 360.0 * std::round(d / 360.0);
        }
        if (planned.size() == 2) {
            const auto cmp = [](const Row& a, const Row& b) { return a.x < b.x; };
            const auto turn = planned[0] > 0 ? std::max_element(rows.begin(), rows.end(), cmp)
                                             : std::min_element(rows.begin(), rows.end(), cmp);
            passes.resize(2);
            passes[0].rows.assign(rows.begin(), turn + 1);
            passes[1].rows.assign(turn + 1, rows.end());
            if (passes[1].rows.empty()) passes.pop_back();
        } else {
            passes.resize(1);
            passes[0].rows = std::move(rows);
        }
        for (size_t i = 0; i < passes.size(); ++i) passes[i].direction = planned[std::min(i, planned.size() - 1)];
    }
    return passes;
}

/// The passes against the run: as many, in the plan's directions.
void checkPassesAgainstPlan(const std::string& path, const std::vector<Pass>& passes, const BallbarRun& run,
                            const std::vector<int>& planned, int headerLine) {
    if (passes.size() != planned.size())
        throw InputError(path, passes.size() > planned.size() ? passes[planned.size()].rows.front().line : headerLine,
                         fmt::format("the file has {} pass(es), but run '{}' of the plan records {} ({})", passes.size(),
                                     run.name, planned.size(), planned.size() == 2 ? "a CCW and a CW pass" : "one pass"));
    for (size_t i = 0; i < passes.size(); ++i)
        if (passes[i].direction != planned[i])
            throw InputError(path, passes[i].rows.front().line,
                             fmt::format("pass {} is {}, but the plan's run '{}' records {} first", i + 1,
                                         passes[i].direction > 0 ? "CCW" : "CW", run.name,
                                         planned[0] > 0 ? "CCW" : "CW"));
}

/// Time → angle for a time-sampled file (the run's feed on its radius, from the overshoot's start), with the feed
/// checked against the data; returns each sample's time (s) or, angle-sampled, its row order, for the drift.
std::vector<std::vector<double>> timeToAngle(const std::string& path, std::vector<Pass>& passes, const BallbarRun* run,
                                             const Columns& col, double lo, double hi, TraceImportSummary& sum) {
    const bool timeSampled = col.timeSampled;
    const int headerLine = col.headerLine;
    std::vector<std::vector<double>> tau(passes.size());
    for (size_t p = 0; p < passes.size(); ++p) {
        Pass& ps = passes[p];
        for (const Row& r : ps.rows) tau[p].push_back(timeSampled ? r.x : static_cast<double>(r.line));
        if (!timeSampled) continue;
        if (!run) throw InputError(path, headerLine, "a time-sampled file needs its run (feed, radius, start angle)");
        if (!(run->capture.feed > 0))
            throw InputError(path, headerLine,
                             fmt::format("time-sampled file: run '{}' of the plan needs feed=\"F\" (mm/min) to turn time "
                                         "into angle", run->name));
        const double radius = run->capture.feedRadius > 0 ? run->capture.feedRadius : linearPathRadius(*run);
        if (!(radius > 0))
            throw InputError(path, headerLine, fmt::format("run '{}': the feed radius is 0; give feed-radius in the plan", run->name));
        const double omegaDeg = run->capture.feed / 60.0 / radius * 180.0 / M_PI;  // deg/s
        const double a0 = (ps.direction > 0 ? lo : hi) - ps.direction * run->capture.overshootDeg;
        const double t0 = ps.rows.front().x;
        // The feed from the data: a pass runs the sweep and both overshoot arcs, from its first to its last sample.
        // A plan feed 1 % off the real one turns into a stretched angle scale that moves the pattern between the CW
        // and CCW passes (EC0Y off by 1.8″ on the multi-tasking sample, 0.9″ at 0.5 %); refused beyond 0.1 %
        // plus one sample period of the pass's duration (where the first and last samples may fall) [G].
        if (ps.rows.size() >= 3) {
            const double duration = ps.rows.back().x - t0;
            const double travel = (hi - lo) + 2.0 * run->capture.overshootDeg;
            if (duration > 0) {
                const double feed = travel / duration * M_PI / 180.0 * radius * 60.0;
                const double dt = duration / static_cast<double>(ps.rows.size() - 1);
                const double tol = 0.001 + dt / duration;
                sum.feedEstimate = p == 0 ? feed : 0.5 * (sum.feedEstimate + feed);
                sum.feedTolerance = tol;
                const double off = feed / run->capture.feed - 1.0;
                if (std::abs(off) > tol)
                    throw InputError(
                        path, ps.rows.back().line,
                        fmt::format("{}lasts {:.3f} s from its first to its last sample; at the plan's feed {:g} mm/min on "
                                    "the radius {:g} mm, the {:g}° of the run (sweep and both overshoot arcs) take {:.3f} s. "
                                    "The data give a feed of {:.1f} mm/min ({:+.2f} % from the plan, more than the {:.2f} % "
                                    "allowed): the angles would be stretched. Give the real feed in the plan (feed=\"{:.1f}\" "
                                    "on run '{}'), or record angle-sampled files",
                                    passes.size() > 1 ? fmt::format("pass {} ({}) ", p + 1, ps.direction > 0 ? "CCW" : "CW")
                                                      : std::string("the pass "),
                                    duration, run->capture.feed, radius, travel, travel / omegaDeg, feed, 100 * off,
                                    100 * tol, feed, run->name));
            }
        }
        for (Row& r : ps.rows) r.x = a0 + ps.direction * omegaDeg * (r.x - t0);
    }
    return tau;
}

/// Linear drift in time, from two samples at the same angle, taken out of every sample.
void removeDrift(const std::string& path, std::vector<Pass>& passes, const std::vector<std::vector<double>>& tau,
                 const BallbarRun& run, double lo, double hi, int headerLine, TraceImportSummary& sum) {
    const bool fullTurn = hi - lo >= 360.0 - 1e-9;
    std::vector<std::vector<double>> ang(passes.size()), val(passes.size());
    for (size_t p = 0; p < passes.size(); ++p)
        for (const Row& r : passes[p].rows) ang[p].push_back(r.x), val[p].push_back(r.dL);
    double v1 = 0, t1 = 0, v2 = 0, t2 = 0;
    if (passes.size() == 2) {
        // Both ends of the sweep are seen by both passes: at the first pass's start long apart, at its end just
        // apart. The difference of the two differences is drift alone (a constant CCW/CW hysteresis cancels).
        const double s = passes[0].direction > 0 ? lo : hi, e = passes[0].direction > 0 ? hi : lo;
        double v3 = 0, t3 = 0, v4 = 0, t4 = 0;
        sampleAt(ang[0], val[0], tau[0], s, v1, t1);
        sampleAt(ang[1], val[1], tau[1], s, v2, t2);
        sampleAt(ang[0], val[0], tau[0], e, v3, t3);
        sampleAt(ang[1], val[1], tau[1], e, v4, t4);
        v2 -= v4 - v3;
        t2 -= t4 - t3;
    } else if (fullTurn) {
        const double s = passes[0].direction > 0 ? lo : hi, e = passes[0].direction > 0 ? hi : lo;
        sampleAt(ang[0], val[0], tau[0], s, v1, t1);
        sampleAt(ang[0], val[0], tau[0], e, v2, t2);
    } else {
        throw InputError(path, headerLine, fmt::format("drift removal needs a full turn or a CCW and a CW pass; run "
                                                         "'{}' sweeps {:g}° in one pass", run.name, hi - lo));
    }
    if (!(t2 > t1 + 1e-12))
        throw InputError(path, headerLine, "drift removal: the samples at the sweep's ends are not apart in time");
    const double rate = (v2 - v1) / (t2 - t1);
    const double tFirst = tau[0].front();
    double tLast = tFirst;
    for (size_t p = 0; p < passes.size(); ++p)
        for (size_t i = 0; i < passes[p].rows.size(); ++i) {
            passes[p].rows[i].dL -= rate * (tau[p][i] - tFirst);
            tLast = std::max(tLast, tau[p][i]);
        }
    sum.driftRemoved = rate * (tLast - tFirst);
}

/// One pass trimmed to the sweep [lo, hi] and checked against the run (direction, gaps, coverage, sample count);
/// binned to the plan's step when densely sampled.
std::vector<Row> trimAndCheckPass(const std::string& path, const Pass& ps, size_t p, size_t passCount,
                                  const BallbarRun* run, double lo, double hi, int headerLine, TraceImportSummary& sum) {
    const double eps = 1e-9 * std::max(1.0, std::max(std::abs(lo), std::abs(hi)));
    const double step = run ? std::abs(run->stepDeg) : 0.0;
    const double gapLimit = std::max(4.0 * step, 2.0);
    std::vector<Row> kept;
    for (const Row& r : ps.rows) {
        if (r.x < lo - eps || r.x > hi + eps) {
            ++sum.trimmed;
            continue;
        }
        kept.push_back(r);
    }
    const int d = ps.direction;
    const std::string which = passCount > 1 ? fmt::format(" pass {} ({})", p + 1, d > 0 ? "CCW" : "CW") : "";
    if (run) {
        if (kept.empty())
            throw InputError(path, ps.rows.front().line,
                             fmt::format("no sample of{} lies in run '{}''s sweep {:g}..{:g}°: is this the file of "
                                         "another run?", which, run->name, run->startDeg, run->endDeg));
        for (size_t i = 1; i < kept.size(); ++i) {
            const double da = (kept[i].x - kept[i - 1].x) * d;
            if (da < -1e-6)
                throw InputError(path, kept[i].line,
                                 fmt::format("angle goes back from {:g} to {:g}°, but{} runs {}", kept[i - 1].x, kept[i].x,
                                             which.empty() ? " the run" : which, d > 0 ? "CCW (increasing)" : "CW (decreasing)"));
            if (da > gapLimit + 1e-9)
                throw InputError(path, kept[i].line,
                                 fmt::format("no samples between {:g} and {:g}°{}: at most {:g}° may be missing "
                                             "(4 steps of the plan)", kept[i - 1].x, kept[i].x, which, gapLimit));
        }
        const double first = d > 0 ? lo : hi, last = d > 0 ? hi : lo;
        if ((kept.front().x - first) * d > gapLimit + 1e-9 || (last - kept.back().x) * d > gapLimit + 1e-9)
            throw InputError(path, kept.front().line,
                             fmt::format("{}covers {:g}..{:g}°, but run '{}' sweeps {:g}..{:g}° (at most {:g}° may be "
                                         "missing at either end): a partial trace or the file of another run",
                                         which.empty() ? "the trace " : which.substr(1) + " ", kept.front().x,
                                         kept.back().x, run->name, first, last, gapLimit));
        const double expected = std::floor((hi - lo) / step + 1e-9) + 1;
        if (static_cast<double>(kept.size()) < 0.75 * expected)
            throw InputError(path, kept.back().line,
                             fmt::format("{}has {} samples in the sweep, but the plan's step of {:g}° gives {:g}: "
                                         "too many are missing, or the file was recorded with another step",
                                         which.empty() ? "the trace " : which.substr(1) + " ", kept.size(),
                                         run->stepDeg, expected));
    }
    const size_t minimum = run ? 5 : 3;
    if (kept.size() < minimum)
        throw InputError(path, kept.empty() ? headerLine : kept.back().line,
                         fmt::format("{} sample(s){}; at least {} are needed to fit the trace", kept.size(), which,
                                     minimum));
    // A densely sampled file (a 1 kHz instrument: thousands of samples a degree) is averaged into bins of the plan's
    // step, centred on its sweep angles: the fit sees the step the plan asked for, with each bin's mean angle and
    // mean ΔL (the noise of a bin drops by √n; the harmonics a step can carry are unchanged). Only beyond
    // kBinFactor samples a step, so files recorded at the plan's step are fitted sample by sample.
    if (run && step > 0 && static_cast<double>(kept.size()) > kBinFactor * (std::floor((hi - lo) / step + 1e-9) + 1))
        kept = binnedRows(kept, run->startDeg, step, sum);
    return kept;
}

MeasuredTrace importImpl(const std::string& path, const BallbarRun* run, const RunCapture& cap, const std::string& machine) {
    CsvReader reader(path);
    const CsvRow& header = reader.header();  // read first: it settles the separator
    const char separator = reader.separator();
    MeasuredTrace out;
    out.path = path;
    TraceImportSummary& sum = out.summary;
    if (run) checkMetadata(path, reader.comments(), 0, *run, machine, sum);
    const size_t commentsChecked = reader.comments().size();
    const Columns col = findColumns(path, header, separator, cap);
    sum.layout = col.timeSampled ? "time" : "angle";

    std::vector<std::string> labels;
    std::vector<Row> rows = readRows(path, reader, col, cap, labels, sum);
    if (run) checkMetadata(path, reader.comments(), commentsChecked, *run, machine, sum);
    if (rows.empty()) throw InputError(path, col.headerLine, "no samples: every row lacks a value");
    if (run) checkBarTravel(path, rows, *run, cap);

    const std::vector<int> planned = run && !run->capture.passes.empty() ? run->capture.passes
                                     : std::vector<int>{run && run->stepDeg < 0 ? -1 : +1};
    std::vector<Pass> passes = splitPasses(path, rows, labels, col, planned);
    if (run) checkPassesAgainstPlan(path, passes, *run, planned, col.headerLine);

    const double lo = run ? std::min(run->startDeg, run->endDeg) : -HUGE_VAL;
    const double hi = run ? std::max(run->startDeg, run->endDeg) : HUGE_VAL;
    const std::vector<std::vector<double>> tau = timeToAngle(path, passes, run, col, lo, hi, sum);
    if (run && run->capture.removeDrift) removeDrift(path, passes, tau, *run, lo, hi, col.headerLine, sum);

    for (size_t p = 0; p < passes.size(); ++p) {
        const std::vector<Row> kept = trimAndCheckPass(path, passes[p], p, passes.size(), run, lo, hi, col.headerLine, sum);
        DirectedTrace dt;
        dt.direction = passes[p].direction;
        for (const Row& r : kept) {
            dt.trace.angleDeg.push_back(r.x);
            dt.trace.dL.push_back(r.dL);
            out.trace.angleDeg.push_back(r.x);
            out.trace.dL.push_back(r.dL);
        }
        out.passes.push_back(std::move(dt));
    }
    return out;
}

}  // namespace

MeasuredTrace importRunTrace(const std::string& path, const BallbarRun& run, const std::string& machine) {
    return importImpl(path, &run, run.capture, machine);
}

std::vector<MeasuredTrace> importRunTraces(const std::string& dir, const std::vector<BallbarRun>& runs,
                                           const std::string& machine) {
    std::vector<MeasuredTrace> out;
    out.reserve(runs.size());
    for (const BallbarRun& r : runs) out.push_back(importRunTrace(OutputSet::fileIn(dir, r.name + ".csv"), r, machine));
    // The whole set in a unit 1000x larger than the plan says (an mm export read under the default µm): every run
    // spans less than a ball bar resolves (kBallbarResolution); a real machine's run shows at least the instrument's
    // noise. A set whose runs are all numerically zero (a simulated perfect machine) is left alone.
    std::vector<double> spans;  // ΔL peak to peak of each run, mm
    for (const MeasuredTrace& t : out) spans.push_back(peakToPeak(t.trace.dL));
    double largest = 0;
    size_t largestAt = 0;
    for (size_t i = 0; i < spans.size(); ++i)
        if (spans[i] > largest) largest = spans[i], largestAt = i;
    if (!out.empty() && largest > kNumericalZero && largest < kBallbarResolution) {
        const double unit = runs[largestAt].capture.lengthUnit;
        throw InputError(out[largestAt].path, 0,
                         fmt::format("ΔL spans at most {:.4g} um over all {} run(s) (largest in this file), below the {:g} um "
                                     "a ball bar resolves: the files are likely in {} while the plan reads them in {} "
                                     "(length-unit of <instrument> or of each run)",
                                     largest / kUmInMm, out.size(), kBallbarResolution / kUmInMm,
                                     unit == 1e-3 ? "mm" : unit == 1e-6 ? "um" : "a larger unit", lengthUnitText(unit)));
    }
    // Against the other runs: one file in another unit than the plan says (an mm export under a dL_um header) spans
    // 1000x less (or more) than the rest. Runs of one machine differ by a few times, not by hundreds.
    if (out.size() >= 3) {
        for (size_t i = 0; i < out.size(); ++i) {
            std::vector<double> others;
            for (size_t k = 0; k < out.size(); ++k)
                if (k != i && spans[k] > kNumericalZero) others.push_back(spans[k]);
            if (others.size() < 2 || !(spans[i] > kNumericalZero)) continue;
            std::nth_element(others.begin(), others.begin() + static_cast<long>(others.size() / 2), others.end());
            const double median = others[others.size() / 2];
            const double ratio = spans[i] / median;
            if (ratio > 1.0 / kUnitRatio && ratio < kUnitRatio) continue;
            const double unit = runs[i].capture.lengthUnit;
            const bool small = ratio < 1;
            const std::string likely = small ? (unit == 1e-3 ? "mm" : unit == 1e-6 ? "um" : "a larger unit")
                                             : (unit == 1.0 ? "um" : unit == 1e-3 ? "nm" : "a smaller unit");
            throw InputError(out[i].path, 0,
                             fmt::format("ΔL spans {:.4g} um, {:.0f} times {} than the median of the other runs ({:.4g} um): "
                                         "this file is likely in {} while the plan reads it in {} (length-unit of "
                                         "<instrument> or of run '{}')",
                                         spans[i] / kUmInMm, small ? 1 / ratio : ratio, small ? "less" : "more",
                                         median / kUmInMm, likely, lengthUnitText(unit), runs[i].name));
        }
    }
    return out;
}

MeasuredTrace importTrace(const std::string& path) { return importImpl(path, nullptr, RunCapture{}, ""); }

}  // namespace cnccomp::io

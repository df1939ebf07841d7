#include "cnccomp/io/report_json.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "cnccomp/io/markup.hpp"

#include "cnccomp/error.hpp"
#include "cnccomp/geometry.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::io {
using namespace cnccomp::identification;

namespace {

std::string quote(const std::string& s) { return jsonString(s); }

std::string num(double v) { return jsonNumber(v, 17); }

class Writer {
public:
    std::ostringstream o;
    int depth = 0;
    bool first = true;

    void newline() { o << '\n' << std::string(2 * depth, ' '); }
    void key(const std::string& k) {
        if (!first) o << ',';
        first = false;
        newline();
        o << quote(k) << ": ";
    }
    void open(char c) {
        o << c;
        ++depth;
        first = true;
    }
    void close(char c) {
        --depth;
        if (!first) newline();
        o << c;
        first = false;
    }
    void element() {
        if (!first) o << ',';
        first = false;
        newline();
    }
    template <class T>
    void field(const std::string& k, const T& v) {
        key(k);
        value(v);
    }
    void value(const std::string& s) { o << quote(s); }
    void value(const char* s) { o << quote(s); }
    void value(double v) { o << num(v); }
    void value(int v) { o << v; }
    void value(bool v) { o << (v ? "true" : "false"); }
    void numbers(const std::string& k, const std::vector<double>& v) {
        key(k);
        o << '[';
        for (size_t i = 0; i < v.size(); ++i) o << (i ? ", " : "") << num(v[i]);
        o << ']';
    }
    void strings(const std::string& k, const std::vector<std::string>& v) {
        key(k);
        o << '[';
        for (size_t i = 0; i < v.size(); ++i) o << (i ? ", " : "") << quote(v[i]);
        o << ']';
    }
};

void combinations(Writer& w, const std::string& k, const std::vector<Combination>& list, bool values) {
    w.key(k);
    w.open('[');
    for (const Combination& c : list) {
        w.element();
        w.open('{');
        w.field("text", c.text);
        w.strings("names", c.names);
        w.numbers("coefficients", c.coefficients);
        if (values) {
            const double s = c.angle ? kArcsec : kUm;
            w.field("unit", c.angle ? "arcsec" : "um");
            w.field("value", c.value / s);
            w.field("stddev", c.stddev / s);
        }
        w.close('}');
    }
    w.close(']');
}

/// Model adequacy (identification/adequacy.hpp): verdict, statistic, threshold, suspected missing terms, per run.
void adequacy(Writer& w, const Adequacy& a) {
    w.key("adequacy");
    w.open('{');
    w.field("tested", a.tested);
    w.field("fits", a.fits);
    w.field("verdict", !a.tested ? "not tested" : a.fits ? "the model fits the data" : "the model does not fit the data");
    w.field("test", "F = (sum r^2 / dof) / noise^2 per run and overall; noise from passes, the plan's noise-um, or "
                    "successive differences");
    w.field("confidence", a.confidence);
    w.field("statistic", a.statistic);
    w.field("threshold", a.threshold);
    w.field("dof", a.dof);
    w.field("inflation", a.inflation);
    w.field("inflation_rule", a.inflationRule);
    w.strings("suspected_missing", a.suspected);
    w.field("option", a.option);
    w.field("message", a.message);
    w.key("runs");
    w.open('[');
    for (const RunAdequacy& ra : a.runs) {
        w.element();
        w.open('{');
        w.field("run", ra.run);
        w.field("noise_source", ra.noiseSource);
        w.field("noise_um", ra.noise / kUm);
        w.field("statistic", ra.statistic);
        w.field("dof", ra.dof);
        w.field("noise_dof", ra.noiseDof);
        w.field("threshold", ra.threshold);
        w.field("fits", ra.fits);
        w.field("harmonic_share_1_6", ra.harmonicShare);
        std::vector<double> um;
        for (double h : ra.harmonics) um.push_back(h / kUm);
        w.numbers("harmonics_um", um);
        w.strings("turning_axes", ra.turningAxes);
        w.close('}');
    }
    w.close(']');
    w.close('}');
}

}  // namespace

std::string formatReportJson(const IdentificationReport& r) {
    Writer w;
    w.open('{');
    w.field("schema", "cnccomp-identification-report/1");
    adequacy(w, r.adequacy);  // first: whether the numbers below can be believed
    w.field("machine", r.machine);
    w.field("method", r.method);
    w.field("solver", r.solver);
    w.field("termination", r.termination);
    w.field("converged", r.converged);
    w.field("iterations", r.iterations);
    w.field("evaluations", r.evaluations);
    w.field("cost_before_um2", r.costBefore);
    w.field("cost_after_um2", r.costAfter);
    w.field("observations", r.observations);
    w.field("unknowns", r.unknowns);
    w.field("rank", r.rank);
    w.field("dof", r.dof);
    w.field("rank_tolerance", r.rankTolerance);
    w.field("sigma_um", r.sigma / kUm);
    w.field("condition_number", r.conditionNumber);
    w.numbers("singular_values", r.singularValues);
    w.key("runs");
    w.open('[');
    for (const RunResidual& rr : r.runs) {
        w.element();
        w.open('{');
        w.field("run", rr.run);
        w.field("kind", rr.kind);
        w.field("samples", rr.samples);
        w.field("rms_before_um", rr.rmsBefore / kUm);
        w.field("rms_after_um", rr.rmsAfter / kUm);
        w.field("max_after_um", rr.maxAfter / kUm);
        w.close('}');
    }
    w.close(']');
    w.key("parameters");
    w.open('[');
    for (const ParameterEstimate& p : r.parameters) {
        const double s = p.displayScale();
        w.element();
        w.open('{');
        w.field("name", p.name);
        w.field("alias", p.alias);
        w.field("nuisance", p.nuisance);
        w.field("unit", p.unit());
        w.field("identified", p.identified);
        w.field("start", p.start / s);
        w.field("value", p.identified ? p.value / s : kNaN);
        if (!p.alias.empty()) w.field("alias_value", p.identified ? p.aliasValue / s : kNaN);
        w.field("stddev", p.stddev / s);
        w.field("lower95", p.lower95 / s);
        w.field("upper95", p.upper95 / s);
        if (r.monteCarloSamples > 0) {
            w.field("mc_stddev", p.mcStddev / s);
            w.field("mc_lower95", p.mcLower95 / s);
            w.field("mc_upper95", p.mcUpper95 / s);
        }
        w.close('}');
    }
    w.close(']');
    w.strings("unidentified", r.unidentified);
    combinations(w, "identifiable_combinations", r.identifiable, true);
    combinations(w, "unobservable_directions", r.unobservable, false);
    w.field("monte_carlo_samples", r.monteCarloSamples);
    w.key("covariance");
    w.open('[');
    for (Eigen::Index i = 0; i < r.covariance.rows(); ++i) {
        w.element();
        std::vector<double> row(r.covariance.cols());
        for (Eigen::Index j = 0; j < r.covariance.cols(); ++j) row[j] = r.covariance(i, j);
        w.o << '[';
        for (size_t j = 0; j < row.size(); ++j) w.o << (j ? ", " : "") << num(row[j]);
        w.o << ']';
    }
    w.close(']');
    if (!r.stages.empty()) w.field("stages", r.stages);
    w.strings("warnings", r.warnings);
    w.close('}');
    w.o << '\n';
    return w.o.str();
}

void writeReportJson(const std::string& path, const IdentificationReport& report) {
    const std::string text = formatReportJson(report);
    writeFileAtomically(path, [&](std::ostream& o) { o << text; });
}

}  // namespace cnccomp::io

#include "cnccomp/volumetric_map.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <thread>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/inverse_kinematics.hpp"
#include "cnccomp/kinematics_engine.hpp"

namespace cnccomp {
namespace {

constexpr int kMaxGridAxes = 16;

/// Everything a worker needs, prepared once (the per-point kernel only reads it).
struct Plan {
    const MapRequest* request = nullptr;
    /// The nominal machine (orientation mode: the inverse solver's) and the erroneous one. Each worker evaluates their
    /// engine models (Kinematics::model, the exact model's arithmetic) with workspaces of its own: the map's numbers
    /// are those of toolPose(Kinematics) to the bit, its repeated frames and angles found in the workspace.
    Kinematics nominal, actual;
    Vec3 tipInTool = Vec3::Zero();
    AxisVector base;
    std::array<int, kMaxGridAxes> target{};  ///< axes mode: machine axis index; orientation mode: 0..2 = x y z
    std::array<double, kMaxGridAxes> scale{};
    AxisVector start;  ///< orientation mode: IK start (solved once at the grid centre)

    Plan(const MapRequest& r)
        : request(&r),
          nominal(r.machine),
          actual(r.machine, r.deviations) {}
};

void prepare(Plan& p) {
    const MapRequest& r = *p.request;
    const MachineModel& m = r.machine;
    if (!std::isfinite(r.toolLength)) throw ModelError("tool length must be a finite number");
    if (static_cast<int>(r.grid.axes.size()) > kMaxGridAxes) throw InputError("--grid", 0, "too many grid axes");
    p.tipInTool = p.nominal.toolPoint(r.toolLength);
    p.base = AxisVector::Zero(m.axisCount());
    if (!r.toolOrientation) {
        for (size_t i = 0; i < r.grid.axes.size(); ++i) {
            const GridAxis& g = r.grid.axes[i];
            const int a = m.axisIndex(g.name);
            if (a < 0)
                throw InputError("--grid", 0,
                                 fmt::format("machine '{}' has no axis '{}' (axes: {})", m.name, g.name,
                                             fmt::join(m.axisNames, " ")));
            const Link& l = m.axisLink(a);
            p.target[i] = a;
            p.scale[i] = l.kind == AxisKind::Rotary ? kDeg : 1.0;
            for (double v : {g.from, g.to})
                if (v * p.scale[i] < l.min - 1e-9 || v * p.scale[i] > l.max + 1e-9)
                    throw ModelError(fmt::format("grid axis {} value {:g} is outside its travel [{:g}, {:g}] {}", g.name, v,
                                                 l.min / p.scale[i], l.max / p.scale[i],
                                                 l.kind == AxisKind::Rotary ? "deg" : "mm"));
        }
        for (int a = 0; a < m.axisCount(); ++a) {
            if (r.grid.find(m.axisNames[a]) >= 0) continue;
            const Link& l = m.axisLink(a);
            if (0.0 < l.min || 0.0 > l.max)
                throw ModelError(fmt::format("axis {} is held at 0, outside its travel; give {}=value in the grid",
                                             l.name, l.name));
        }
        return;
    }
    // Orientation mode: grid names the tool-tip coordinates.
    const Vec3 k = *r.toolOrientation;
    if (!k.allFinite() || k.norm() < 1e-12) throw InputError("--orientation", 0, "tool orientation must be a non-zero vector");
    for (size_t i = 0; i < r.grid.axes.size(); ++i) {
        const std::string& n = r.grid.axes[i].name;
        if (n != "X" && n != "Y" && n != "Z")
            throw InputError("--grid", 0,
                             fmt::format("with a fixed tool orientation the grid names the tip coordinates X, Y, Z, not '{}'", n));
        p.target[i] = n[0] - 'X';
        p.scale[i] = 1.0;
    }
    // A start for Newton: the nominal IK at the grid's centre from a few rotary starts; keep the converged solution
    // with the smallest rotary angles (the one a post-processor would normally pick).
    ToolPose centre;
    centre.axis = k.normalized();
    for (size_t i = 0; i < r.grid.axes.size(); ++i) {
        const GridAxis& g = r.grid.axes[i];
        centre.tip[p.target[i]] = 0.5 * (g.from + g.to);
    }
    std::vector<int> rotary;
    for (int a = 0; a < m.axisCount(); ++a)
        if (m.axisLink(a).kind == AxisKind::Rotary) rotary.push_back(a);
    const int starts = 8;
    long combos = 1;
    for (size_t i = 0; i < rotary.size(); ++i) combos *= starts;
    double best = HUGE_VAL;
    for (long c = 0; c < combos; ++c) {
        AxisVector q0 = AxisVector::Zero(m.axisCount());
        long cc = c;
        for (int a : rotary) {
            q0[a] = (cc % starts) * (2 * kPi / starts) - (cc % starts >= starts / 2 ? 2 * kPi : 0.0);
            cc /= starts;
        }
        const IkResult s = solveToolPose(p.nominal, centre, p.tipInTool, q0);
        const ToolPose got = toolPose(p.nominal, s.q, p.tipInTool);
        if (!s.converged || (got.tip - centre.tip).norm() > 1e-6 || (got.axis - centre.axis).norm() > 1e-8) continue;
        bool inside = true;
        for (int a = 0; a < m.axisCount(); ++a) {
            const Link& l = m.axisLink(a);
            if (s.q[a] < l.min - 1e-9 || s.q[a] > l.max + 1e-9) inside = false;
        }
        if (!inside) continue;
        double size = 0;
        for (int a : rotary) size += std::abs(s.q[a]);
        if (size < best - 1e-9) {
            best = size;
            p.start = s.q;
        }
    }
    if (!std::isfinite(best))
        throw ModelError(fmt::format("machine '{}' cannot reach tool orientation ({:g}, {:g}, {:g}) at the grid centre",
                                     m.name, centre.axis.x(), centre.axis.y(), centre.axis.z()));
}

/// One worker's workspaces of the nominal and the actual model: each keeps a table of each chain's frames (a grid
/// varies its last axes fastest, so one chain's axes, often the longer tool chain's, stay put over many points and its
/// frame is reused), each chain's last walk (resumed where its axes changed) and the cosines and sines of the rotary
/// axes' last angles (a grid's rotary axis takes few values): kinematics_engine.hpp.
struct Scratch {
    KinematicsData nominal, actual;
    AxisVector q;  ///< the commands of the point (axes mode: the axes not in the grid stay at the plan's base)
    explicit Scratch(const Plan& p)
        : nominal(p.nominal.model().createData()), actual(p.actual.model().createData()), q(p.base) {}
};

/// Axes mode: grid axis i at its index `index`, in the workspace's commands.
void setGridAxis(const Plan& p, Scratch& ws, size_t i, long index) {
    if (!p.request->toolOrientation) ws.q[p.target[i]] = p.request->grid.axes[i].value(index) * p.scale[i];
}

/// The per-point kernel at per-axis grid indices `idx` (axes mode: the commands already in ws.q, setGridAxis): no
/// allocation.
void evaluate(const Plan& p, const long* idx, MapPoint& out, Scratch& ws) {
    const MapRequest& r = *p.request;
    AxisVector& q = ws.q;
    out.ok = true;
    if (r.toolOrientation) {
        ToolPose t;
        t.axis = r.toolOrientation->normalized();
        for (size_t i = 0; i < r.grid.axes.size(); ++i) t.tip[p.target[i]] = r.grid.axes[i].value(idx[i]);
        // Modulo axes are brought back to the turn of the start (the same pose); one retry from there when Newton
        // wandered off.
        const auto unwrap = [&](AxisVector& x) {
            for (int a = 0; a < x.size(); ++a)
                if (r.machine.axisLink(a).modulo) x[a] -= 2 * kPi * std::round((x[a] - p.start[a]) / (2 * kPi));
        };
        IkResult s = solveToolPose(p.nominal, t, p.tipInTool, p.start);
        unwrap(s.q);
        if (!s.converged) {
            s = solveToolPose(p.nominal, t, p.tipInTool, s.q);
            unwrap(s.q);
        }
        q = s.q;
        // Accept only a pose that is met (the solver's "converged" means the iteration settled).
        Vec3 gotTip, gotAxis;
        p.nominal.model().toolPose(ws.nominal, q, r.toolLength, gotTip, gotAxis);
        if (!s.converged || (gotTip - t.tip).norm() > 1e-6 || (gotAxis - t.axis).norm() > 1e-8) out.ok = false;
        for (int a = 0; a < q.size() && out.ok; ++a) {
            const Link& l = r.machine.axisLink(a);
            if (q[a] < l.min - 1e-9 || q[a] > l.max + 1e-9) out.ok = false;
        }
    }
    out.q.fill(0.0);
    for (int a = 0; a < q.size(); ++a) out.q[a] = q[a];
    ToolPose n, a;
    p.nominal.model().toolPose(ws.nominal, q, r.toolLength, n.tip, n.axis);
    p.actual.model().toolPose(ws.actual, q, r.toolLength, a.tip, a.axis);
    out.tip = n.tip;
    out.error = a.tip - n.tip;
    const Vec3 cr = n.axis.cross(a.axis);
    const double s = cr.norm();
    out.tilt = std::atan2(s, n.axis.dot(a.axis));
    out.rotation = s > 0 ? Vec3(cr * (out.tilt / s)) : Vec3::Zero();
}

/// Running statistics of one worker.
struct Accumulator {
    long points = 0, failed = 0;
    std::array<double, 5> sumSq{}, maxAbs{};
    long worstIndex = -1, worstTiltIndex = -1;
    MapPoint worst, worstTilt;

    void add(long index, const MapPoint& pt) {
        if (!pt.ok) {
            ++failed;
            return;
        }
        ++points;
        const std::array<double, 5> v{pt.error.x(), pt.error.y(), pt.error.z(), pt.error.norm(), pt.tilt};
        for (int i = 0; i < 5; ++i) {
            sumSq[i] += v[i] * v[i];
            maxAbs[i] = std::max(maxAbs[i], std::abs(v[i]));
        }
        if (worstIndex < 0 || v[3] > worst.error.norm()) worstIndex = index, worst = pt;
        if (worstTiltIndex < 0 || v[4] > worstTilt.tilt) worstTiltIndex = index, worstTilt = pt;
    }
    /// Merge a later chunk (higher indices): ties keep the earlier index, as a serial run would.
    void merge(const Accumulator& o) {
        points += o.points;
        failed += o.failed;
        for (int i = 0; i < 5; ++i) sumSq[i] += o.sumSq[i], maxAbs[i] = std::max(maxAbs[i], o.maxAbs[i]);
        if (o.worstIndex >= 0 && (worstIndex < 0 || o.worst.error.norm() > worst.error.norm()))
            worstIndex = o.worstIndex, worst = o.worst;
        if (o.worstTiltIndex >= 0 && (worstTiltIndex < 0 || o.worstTilt.tilt > worstTilt.tilt))
            worstTiltIndex = o.worstTiltIndex, worstTilt = o.worstTilt;
    }
    MapStatistics finish() const {
        MapStatistics s;
        s.points = points;
        s.failed = failed;
        ComponentStats* c[5] = {&s.dx, &s.dy, &s.dz, &s.norm, &s.tilt};
        for (int i = 0; i < 5; ++i) {
            c[i]->maxAbs = maxAbs[i];
            c[i]->rms = points > 0 ? std::sqrt(sumSq[i] / points) : 0.0;
        }
        s.worstIndex = worstIndex;
        s.worstTiltIndex = worstTiltIndex;
        s.worst = worst;
        s.worstTilt = worstTilt;
        return s;
    }
};

/// Grid points per block: fixed by the grid's size alone, so that the statistics (summed block by block, blocks
/// merged in order) do not depend on the thread count.
long blockPoints(long n) { return std::clamp<long>((n + 15) / 16, 64, 8192); }

/// The streaming engine. Worker w evaluates the blocks w, w + threads, w + 2·threads, … in turn, each into the next
/// of its own kRing slots, and calls sink.evaluated there; the calling thread takes the blocks in flat-index order as
/// they are ready, merges their statistics, calls sink.inOrder and frees their slots. A worker waits only when the
/// block kRing places back in its ring is not yet handed on, the calling thread only for the next block: a slow write
/// (the page cache flushing) or a worker that lost its core for a while holds nobody else up until the rings are full.
/// It used to run in rounds separated by a barrier, every round waiting for the slowest worker and the write: the
/// streamed million-point CSV on two threads, the two builds in turn, 5 pairs: 2.31–2.60 M rows/s then, 2.46–2.97 now
/// (BM_MapCsvStreamed1M/threads:2); mapStatistics 10.4–13.7 M poses/s then, 12.9–13.7 now.
MapStatistics run(const Plan& plan, MapSink& sink) {
    const MapRequest& r = *plan.request;
    const long n = r.grid.size();
    const long block = blockPoints(n);
    const long blocks = (n + block - 1) / block;
    int threads = r.threads > 0 ? r.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    threads = static_cast<int>(std::clamp<long>(blocks, 1, threads));
    constexpr int kRing = 3;
    const int slots = kRing * threads;
    sink.begin(slots, block);
    std::vector<std::vector<MapPoint>> buffers(slots);
    std::vector<Accumulator> acc(slots);
    std::vector<std::exception_ptr> errors(slots);
    std::vector<MapPoint*> where(slots, nullptr);
    // Blocks handed to sink.inOrder (their slots are free again), or kStopped: the stream ends (an error).
    constexpr long kStopped = std::numeric_limits<long>::max();
    std::atomic<long> delivered{0};
    std::vector<std::atomic<long>> ready(static_cast<size_t>(slots));  // the block a slot holds evaluated (−1: none)
    for (auto& x : ready) x.store(-1);
    const auto slotOf = [&](long b) { return static_cast<int>((b / threads) % kRing) * threads + static_cast<int>(b % threads); };
    const auto stopAll = [&] {
        delivered = kStopped;  // also wakes the workers waiting for a slot
        delivered.notify_all();
    };

    const auto worker = [&](int w) {
        Scratch ws(plan);
        std::array<long, kMaxGridAxes> idx{};
        for (long b = w; b < blocks; b += threads) {
            const long previous = b - static_cast<long>(kRing) * threads;  // the block this slot held before
            for (long got = delivered.load(); got <= previous; got = delivered.load()) delivered.wait(got);
            if (delivered.load() == kStopped) return;
            const int slot = slotOf(b);
            try {
                const long lo = b * block, count = std::min(block, n - lo);
                MapPoint* pts = sink.storage(lo, count);
                if (!pts) {
                    buffers[slot].resize(static_cast<size_t>(block));
                    pts = buffers[slot].data();
                }
                where[slot] = pts;
                // Summed on this thread's stack and stored once per block: the slots' accumulators lie side by side,
                // and updating one per point made the two workers fight over a shared cache line (two threads took
                // 1.45× the CPU time of one; now 1.05×, BM_MapStatistics1M).
                Accumulator sum;
                r.grid.unflatten(lo, idx.data());
                for (size_t i = 0; i < r.grid.axes.size(); ++i) setGridAxis(plan, ws, i, idx[i]);
                for (long k = 0; k < count; ++k) {
                    evaluate(plan, idx.data(), pts[k], ws);
                    sum.add(lo + k, pts[k]);
                    for (size_t i = r.grid.axes.size(); i-- > 0;) {  // next grid point: the axes that step
                        const bool carry = ++idx[i] == r.grid.axes[i].count;
                        if (carry) idx[i] = 0;
                        setGridAxis(plan, ws, i, idx[i]);
                        if (!carry) break;
                    }
                }
                acc[slot] = sum;
                sink.evaluated(slot, lo, std::span<const MapPoint>(pts, static_cast<size_t>(count)));
            } catch (...) {
                errors[slot] = std::current_exception();
            }
            ready[slot].store(b);  // publishes the block (and its error) to the calling thread
            ready[slot].notify_one();
        }
    };

    std::vector<std::thread> pool;
    pool.reserve(static_cast<size_t>(threads));
    std::exception_ptr failure;
    try {
        for (int w = 0; w < threads; ++w) pool.emplace_back(worker, w);
    } catch (...) {  // a thread could not start: stop the ones that did
        failure = std::current_exception();
    }
    Accumulator total;
    for (long b = 0; b < blocks && !failure; ++b) {
        const int slot = slotOf(b);
        for (long got = ready[slot].load(); got != b; got = ready[slot].load()) ready[slot].wait(got);
        if (errors[slot]) {
            failure = errors[slot];
            break;
        }
        try {
            const long lo = b * block, count = std::min(block, n - lo);
            total.merge(acc[slot]);
            sink.inOrder(slot, lo, std::span<const MapPoint>(where[slot], static_cast<size_t>(count)));
        } catch (...) {
            failure = std::current_exception();
            break;
        }
        delivered = b + 1;
        delivered.notify_all();
    }
    if (failure) stopAll();
    for (auto& t : pool) t.join();
    if (failure) std::rethrow_exception(failure);
    return total.finish();
}

/// A sink that keeps nothing (statistics only).
class NullSink : public MapSink {};

/// A sink whose blocks are evaluated straight into a whole map's points.
class StoreSink : public MapSink {
public:
    explicit StoreSink(std::vector<MapPoint>& points) : points_(points) {}
    MapPoint* storage(long first, long) override { return points_.data() + first; }

private:
    std::vector<MapPoint>& points_;
};

}  // namespace

VolumetricMap describeMap(const MapRequest& request) {
    VolumetricMap map;
    map.grid = request.grid;
    map.axisNames = request.machine.axisNames;
    map.toolLength = request.toolLength;
    map.toolOrientation = request.toolOrientation;
    if (map.toolOrientation) *map.toolOrientation = map.toolOrientation->normalized();
    return map;
}

VolumetricMap computeMap(const MapRequest& request) {
    Plan plan(request);
    prepare(plan);
    VolumetricMap map = describeMap(request);
    map.points.resize(static_cast<size_t>(request.grid.size()));
    StoreSink sink(map.points);
    map.stats = run(plan, sink);
    return map;
}

MapStatistics mapStatistics(const MapRequest& request) {
    Plan plan(request);
    prepare(plan);
    NullSink sink;
    return run(plan, sink);
}

MapStatistics streamMap(const MapRequest& request, MapSink& sink) {
    Plan plan(request);
    prepare(plan);
    return run(plan, sink);
}

}  // namespace cnccomp

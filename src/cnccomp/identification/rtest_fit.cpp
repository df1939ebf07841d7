#include "cnccomp/identification/rtest_fit.hpp"

#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "cnccomp/circle_fit.hpp"
#include "cnccomp/error.hpp"

namespace cnccomp::identification {

using Vec2 = Eigen::Vector2d;

namespace {

Eigen::Matrix2d rotation2(double a) {
    Eigen::Matrix2d q;
    q << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
    return q;
}

double wrapHalfTurn(double a) {
    a = std::remainder(a, kPi);  // (−π/2, π/2]
    return a <= -kPi / 2 ? a + kPi : a;
}

/// Puts a ≥ b ≥ 0 and the angle of the a-axis in (−π/2, π/2]; phases follow.
void normalize(EllipseFit& e, std::vector<double>* phases) {
    if (e.a < 0) {
        e.a = -e.a;
        if (phases) for (double& p : *phases) p = kPi - p;
    }
    if (e.b < 0) {
        e.b = -e.b;
        if (phases) for (double& p : *phases) p = -p;
    }
    if (e.a < e.b) {
        std::swap(e.a, e.b);
        e.angle += kPi / 2;
        if (phases) for (double& p : *phases) p -= kPi / 2;
    }
    const double w = wrapHalfTurn(e.angle);
    if (phases && std::abs(w - e.angle) > 1e-12)
        for (double& p : *phases) p += (e.angle - w > 0 ? kPi : -kPi);
    e.angle = w;
}

Vec2 ellipsePoint(const EllipseFit& e, double phi) {
    return e.center + rotation2(e.angle) * Vec2(e.a * std::cos(phi), e.b * std::sin(phi));
}

}  // namespace

PlaneFit fitPlane(const std::vector<Vec3>& points, const Vec3& normalHint) {
    if (points.size() < 3) throw ModelError("a plane fit needs at least three points");
    PlaneFit f;
    for (const Vec3& p : points) f.centroid += p;
    f.centroid /= static_cast<double>(points.size());
    Mat3 c = Mat3::Zero();
    for (const Vec3& p : points) c += (p - f.centroid) * (p - f.centroid).transpose();
    Eigen::SelfAdjointEigenSolver<Mat3> es(c);
    const Eigen::Vector3d ev = es.eigenvalues();  // ascending
    if (!(ev[1] > 1e-12 * ev[2]) || !(ev[2] > 0)) throw ModelError("a plane fit needs points that are not collinear");
    f.normal = es.eigenvectors().col(0).normalized();
    if (f.normal.dot(normalHint) < 0) f.normal = -f.normal;
    f.rms = std::sqrt(std::max(ev[0], 0.0) / static_cast<double>(points.size()));
    return f;
}

Circle3Fit fitCircle3(const std::vector<Vec3>& points, const Vec3& normalHint) {
    const PlaneFit pf = fitPlane(points, normalHint);
    const Vec3 n = pf.normal;
    int k = 0;
    n.cwiseAbs().minCoeff(&k);
    const Vec3 u = (Vec3::Unit(k) - Vec3::Unit(k).dot(n) * n).normalized();
    const Vec3 v = n.cross(u);
    std::vector<Vec2> p2;
    p2.reserve(points.size());
    for (const Vec3& p : points) p2.emplace_back((p - pf.centroid).dot(u), (p - pf.centroid).dot(v));
    const CircleFit cf = fitCircle(p2);
    Circle3Fit out;
    out.normal = n;
    out.center = pf.centroid + cf.center.x() * u + cf.center.y() * v;
    out.radius = cf.radius;
    out.rms = cf.rms;
    return out;
}

EllipseFit fitEllipseAlgebraic(const std::vector<Vec2>& points) {
    const Eigen::Index n = static_cast<Eigen::Index>(points.size());
    if (n < 5) throw ModelError("an ellipse fit needs at least five points");
    Vec2 m = Vec2::Zero();
    for (const Vec2& p : points) m += p;
    m /= static_cast<double>(n);
    double s = 0;
    for (const Vec2& p : points) s += (p - m).squaredNorm();
    s = std::sqrt(s / static_cast<double>(n));
    if (!(s > 0) || !std::isfinite(s)) throw ModelError("an ellipse fit needs distinct finite points");
    Eigen::MatrixXd D(n, 6);
    for (Eigen::Index i = 0; i < n; ++i) {
        const Vec2 q = (points[static_cast<size_t>(i)] - m) / s;
        D.row(i) << q.x() * q.x(), q.x() * q.y(), q.y() * q.y(), q.x(), q.y(), 1.0;
    }
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(D, Eigen::ComputeFullV);  // full: five points give a 5 × 6 matrix
    const Eigen::VectorXd u = svd.matrixV().col(5);
    const double A = u[0], B = u[1], C = u[2], Dx = u[3], Ey = u[4], F = u[5];
    Eigen::Matrix2d M;
    M << A, B / 2, B / 2, C;
    if (!(M.determinant() > 0)) throw ModelError("the best-fitting conic is not an ellipse");
    const Vec2 g(Dx, Ey);
    const Vec2 c0 = -0.5 * M.inverse() * g;
    const double F0 = F + 0.5 * g.dot(c0);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(M);
    const Vec2 lam = es.eigenvalues();  // ascending: the first belongs to the longer axis
    const double a2 = -F0 / lam[0], b2 = -F0 / lam[1];
    if (!(a2 > 0 && b2 > 0)) throw ModelError("the best-fitting conic is an imaginary ellipse");
    EllipseFit e;
    e.center = m + s * c0;
    e.a = s * std::sqrt(a2);
    e.b = s * std::sqrt(b2);
    const Vec2 dir = es.eigenvectors().col(0);
    e.angle = std::atan2(dir.y(), dir.x());
    normalize(e, nullptr);
    double ss = 0;
    for (const Vec2& p : points) ss += std::pow(ellipseDistance(e, p), 2);
    e.rms = std::sqrt(ss / static_cast<double>(n));
    return e;
}

EllipseFit fitEllipse(const std::vector<Vec2>& points) {
    EllipseFit e = fitEllipseAlgebraic(points);
    const size_t n = points.size();
    std::vector<double> phi(n);
    for (size_t i = 0; i < n; ++i) ellipseDistance(e, points[i], &phi[i]);
    using Vec5 = Eigen::Matrix<double, 5, 1>;
    using Mat5 = Eigen::Matrix<double, 5, 5>;
    const auto costOf = [&](const EllipseFit& f, const std::vector<double>& ph) {
        double c = 0;
        for (size_t i = 0; i < n; ++i) c += (points[i] - ellipsePoint(f, ph[i])).squaredNorm();
        return c;
    };
    double cost = costOf(e, phi);
    int it = 0;
    for (; it < 100; ++it) {
        // Gauss–Newton on (cx, cy, a, b, α, φ_1..φ_n); the phases are eliminated by the Schur complement.
        Mat5 N = Mat5::Zero();
        Vec5 rhs = Vec5::Zero();
        const Eigen::Matrix2d Q = rotation2(e.angle);
        Eigen::Matrix2d dQ;
        dQ << -std::sin(e.angle), -std::cos(e.angle), std::cos(e.angle), -std::sin(e.angle);
        std::vector<Eigen::Matrix<double, 2, 5>> Jp(n);
        std::vector<Vec2> G(n), R(n);
        for (size_t i = 0; i < n; ++i) {
            const double c = std::cos(phi[i]), s = std::sin(phi[i]);
            Eigen::Matrix<double, 2, 5> J;
            J.col(0) = Vec2(1, 0);
            J.col(1) = Vec2(0, 1);
            J.col(2) = Q * Vec2(c, 0);
            J.col(3) = Q * Vec2(0, s);
            J.col(4) = dQ * Vec2(e.a * c, e.b * s);
            const Vec2 g = Q * Vec2(-e.a * s, e.b * c);
            const Vec2 r = points[i] - ellipsePoint(e, phi[i]);
            const double gg = g.squaredNorm();
            const Vec5 jg = J.transpose() * g;
            N += J.transpose() * J;
            rhs += J.transpose() * r;
            if (gg > 0) {
                N -= jg * jg.transpose() / gg;
                rhs -= jg * (g.dot(r) / gg);
            }
            Jp[i] = J;
            G[i] = g;
            R[i] = r;
        }
        const Vec5 dp = N.ldlt().solve(rhs);
        if (!dp.allFinite()) break;
        std::vector<double> dphi(n);
        for (size_t i = 0; i < n; ++i) {
            const double gg = G[i].squaredNorm();
            dphi[i] = gg > 0 ? G[i].dot(R[i] - Jp[i] * dp) / gg : 0.0;
        }
        double t = 1.0;
        bool accepted = false;
        for (int h = 0; h < 30; ++h, t *= 0.5) {
            EllipseFit f = e;
            f.center += t * dp.head<2>();
            f.a += t * dp[2];
            f.b += t * dp[3];
            f.angle += t * dp[4];
            std::vector<double> ph = phi;
            for (size_t i = 0; i < n; ++i) ph[i] += t * dphi[i];
            const double c = costOf(f, ph);
            if (c <= cost) {
                accepted = true;
                const bool small = t * dp.norm() <= 1e-14 * (e.center.norm() + e.a + 1.0) || cost - c <= 1e-30;
                e = f;
                phi = ph;
                cost = c;
                if (small) it = 1000;
                break;
            }
        }
        if (!accepted) break;
    }
    normalize(e, &phi);
    e.iterations = std::min(it, 100);
    e.rms = std::sqrt(cost / static_cast<double>(n));
    return e;
}

EllipseFit fitEllipsePhases(const std::vector<Vec2>& points, const std::vector<double>& phases) {
    const Eigen::Index n = static_cast<Eigen::Index>(points.size());
    if (n < 3 || phases.size() != points.size()) throw ModelError("an ellipse fit with phases needs ≥ 3 points, one phase each");
    Eigen::MatrixXd A(n, 3);
    Eigen::MatrixXd b(n, 2);
    for (Eigen::Index i = 0; i < n; ++i) {
        A.row(i) << 1.0, std::cos(phases[static_cast<size_t>(i)]), std::sin(phases[static_cast<size_t>(i)]);
        b.row(i) = points[static_cast<size_t>(i)].transpose();
    }
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
    if (qr.rank() < 3) throw ModelError("the phases do not span a circle (need three distinct angles)");
    const Eigen::MatrixXd x = qr.solve(b);  // rows: centre, U, V; columns: x, y
    Eigen::Matrix2d M;
    M.col(0) = x.row(1).transpose();
    M.col(1) = x.row(2).transpose();
    Eigen::JacobiSVD<Eigen::Matrix2d> svd(M, Eigen::ComputeFullU);
    EllipseFit e;
    e.center = x.row(0).transpose();
    e.a = svd.singularValues()[0];
    e.b = svd.singularValues()[1];
    e.angle = std::atan2(svd.matrixU()(1, 0), svd.matrixU()(0, 0));
    normalize(e, nullptr);
    e.rms = std::sqrt((A * x - b).squaredNorm() / static_cast<double>(n));
    return e;
}

double ellipseDiameter(const EllipseFit& e, double angle) {
    const Vec2 u = rotation2(-e.angle) * Vec2(std::cos(angle), std::sin(angle));
    if (!(e.b > 0)) return std::abs(u.y()) < 1e-15 ? 2 * e.a : 0.0;
    return 2.0 / std::sqrt(u.x() * u.x() / (e.a * e.a) + u.y() * u.y() / (e.b * e.b));
}

double ellipseDistance(const EllipseFit& e, const Vec2& p, double* phase) {
    const Vec2 q = rotation2(-e.angle) * (p - e.center);  // ellipse frame
    double phi = std::atan2(e.a * q.y(), e.b * q.x());
    if (e.a > 0 && e.b > 0) phi = std::atan2(q.y() / e.b, q.x() / e.a);
    for (int it = 0; it < 50; ++it) {
        // f(φ) = (x(φ) − q)·x'(φ) = 0
        const double c = std::cos(phi), s = std::sin(phi);
        const Vec2 x(e.a * c, e.b * s), d1(-e.a * s, e.b * c), d2(-e.a * c, -e.b * s);
        const double f = (x - q).dot(d1), df = d1.dot(d1) + (x - q).dot(d2);
        if (!(std::abs(df) > 0)) break;
        double step = f / df;
        if (df < 0) step = f / (d1.dot(d1) + 1e-300);  // keep descending away from maxima
        phi -= step;
        if (std::abs(step) < 1e-15) break;
    }
    if (phase) *phase = phi;
    return (Vec2(e.a * std::cos(phi), e.b * std::sin(phi)) - q).norm();
}

}  // namespace cnccomp::identification

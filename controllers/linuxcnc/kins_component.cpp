#include "controllers/linuxcnc/kins_component.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <set>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/kinematics.hpp"

namespace cnccomp::controllers::linuxcnc {
namespace {

// Full precision: the generated C must reproduce the model to the last bit the doubles carry.
std::string num(double v) { return fmt::format("{:.17g}", v); }

std::string lowerName(const std::string& s) {
    std::string out;
    for (char c : s) {
        const auto u = static_cast<unsigned char>(c);
        out += std::isalnum(u) ? static_cast<char>(std::tolower(u)) : (c == '-' ? '-' : '_');
    }
    return out;
}

/// EmcPose slot of a coordinate letter: X Y Z A B C U V W = 0..8 (kinematics.h / emcpos.h field order).
int poseSlot(const std::string& axis) {
    static const std::string letters = "XYZABCUVW";
    if (axis.size() != 1) return -1;
    const auto p = letters.find(static_cast<char>(std::toupper(static_cast<unsigned char>(axis[0]))));
    return p == std::string::npos ? -1 : static_cast<int>(p);
}

/// A pose as the 12 numbers of ck_link_t::P: rotation row-major, then the translation.
std::string flatPose(const Pose& p) {
    std::string s;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) s += num(p.linear()(r, c)) + ", ";
    s += num(p.translation().x()) + ", " + num(p.translation().y()) + ", " + num(p.translation().z());
    return s;
}

// The C part (after ";;") that does not depend on the machine. Written from the model of src/cnccomp/kinematics.cpp
// (link i = placement · E_location · motion(q) · E_component(q), errorTransform = translation then the exact rotation
// of the rotation vector) and the solver of src/cnccomp/inverse_kinematics.cpp (Gauss–Newton on
// |tip error|² + w²|axis error|² + (rotary − anchor)ᵀ D (rotary − anchor), D the singular-pose policy's damping of
// src/cnccomp/pose_solver.hpp, screw Jacobian, then ≤ 4 polish steps without the damping when CK_POLISH).
constexpr const char* kBody = R"C(
/* ---------------------------------------------------------------------------------------------------------------
 * Machine-independent part: pose algebra, the two chains, the solver, the LinuxCNC entry points.
 * Realtime-safe: no allocation, fixed-size arrays, only rtapi_math.h.
 * ------------------------------------------------------------------------------------------------------------- */
#define CK_DEG (3.14159265358979323846 / 180.0)

static struct ck_hal_t {
    hal_float_t *tool_offset;
    hal_float_t *dev[CK_NDEV];
    hal_bit_t *kinstype_is_0;
    hal_bit_t *kinstype_is_1;
    hal_bit_t *fail;
    hal_s32_t *iterations;
    hal_float_t *residual;
} *ck_hal;

static int ck_type = 0;                        /* 0 joint mode, 1 tool-tip mode */
static double ck_placed[CK_NLINKS][12];        /* placement · E_location, from the dev pins (R row-major, t) */
static double ck_loc_cache[CK_NDEV];           /* dev pin values ck_placed was built from */
static int ck_placed_ok = 0;
static int ck_last_iterations = 0;
static double ck_last_residual = 0.0;
static int ck_last_fail = 0;

static double ck_dev(int i) { return ck_hal ? *ck_hal->dev[i] : ck_dev_init[i]; }
static double ck_tool_length(void) { return ck_hal ? *ck_hal->tool_offset : 0.0; }

/* R (row-major 3x3) and t as one array of 12: a pose x -> R x + t. */
static void ck_identity(double *P) {
    int i;
    for (i = 0; i < 12; ++i) P[i] = 0.0;
    P[0] = P[4] = P[8] = 1.0;
}

static void ck_compose(const double *A, const double *B, double *out) {
    double r[12];
    int i, j;
    for (i = 0; i < 3; ++i) {
        for (j = 0; j < 3; ++j)
            r[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
        r[9 + i] = A[3 * i] * B[9] + A[3 * i + 1] * B[10] + A[3 * i + 2] * B[11] + A[9 + i];
    }
    for (i = 0; i < 12; ++i) out[i] = r[i];
}

/* Rotation by angle about unit axis k (Rodrigues), into the R part of P. */
static void ck_axis_rotation(const double *k, double angle, double *R) {
    const double c = cos(angle), s = sin(angle), v = 1.0 - c;
    R[0] = c + k[0] * k[0] * v;        R[1] = k[0] * k[1] * v - k[2] * s; R[2] = k[0] * k[2] * v + k[1] * s;
    R[3] = k[1] * k[0] * v + k[2] * s; R[4] = c + k[1] * k[1] * v;        R[5] = k[1] * k[2] * v - k[0] * s;
    R[6] = k[2] * k[0] * v - k[1] * s; R[7] = k[2] * k[1] * v + k[0] * s; R[8] = c + k[2] * k[2] * v;
}

/* Error transform of (dx dy dz a b c): translation, then the exact rotation of the rotation vector (a b c). */
static void ck_error_transform(const double *e, double *P) {
    const double a = sqrt(e[3] * e[3] + e[4] * e[4] + e[5] * e[5]);
    ck_identity(P);
    if (a >= 1e-300) {
        double k[3];
        k[0] = e[3] / a; k[1] = e[4] / a; k[2] = e[5] / a;
        ck_axis_rotation(k, a, P);
    }
    P[9] = e[0]; P[10] = e[1]; P[11] = e[2];
}

/* e(q) of one component deviation (src/cnccomp/machine.cpp, ComponentBasis::evaluate). */
static double ck_basis(const ck_cmp_t *c, double q, int modulo) {
    int k;
    double s = 0.0;
    if (c->type == 0) {
        double p = q;
        for (k = 0; k < c->order; ++k, p *= q) s += ck_dev(c->dev + k) * p;
        return s;
    }
    if (c->type == 1) {
        for (k = 1; k <= c->order; ++k)
            s += ck_dev(c->dev + 2 * k - 2) * cos(k * q) + ck_dev(c->dev + 2 * k - 1) * sin(k * q);
        return s;
    }
#if CK_NNODES > 0
    {
        const double *x = ck_nodes + c->node0;
        const int n = c->order;
        int i;
        if (n <= 0) return 0.0;
        if (modulo) {
            const double period = 2.0 * 3.14159265358979323846;
            double u = fmod(q - x[0], period), x1, y1;
            if (u < 0) u += period;
            u += x[0];
            for (i = 0; i + 1 < n && x[i + 1] <= u; ++i) {}
            x1 = (i + 1 < n) ? x[i + 1] : x[0] + period;
            y1 = (i + 1 < n) ? ck_dev(c->dev + i + 1) : ck_dev(c->dev);
            return ck_dev(c->dev + i) + (y1 - ck_dev(c->dev + i)) * (u - x[i]) / (x1 - x[i]);
        }
        if (q <= x[0]) return ck_dev(c->dev);
        if (q >= x[n - 1]) return ck_dev(c->dev + n - 1);
        for (i = 0; i + 1 < n && x[i + 1] <= q; ++i) {}
        return ck_dev(c->dev + i) + (ck_dev(c->dev + i + 1) - ck_dev(c->dev + i)) * (q - x[i]) / (x[i + 1] - x[i]);
    }
#else
    (void)modulo;
    return 0.0; /* no table-type component error on this machine */
#endif
}

/* placement · E_location of every link, rebuilt when a location pin changed. */
static void ck_refresh(void) {
    int li, k, changed = !ck_placed_ok;
    for (k = 0; k < CK_NLOC && !changed; ++k)
        if (ck_dev(ck_loc[k].dev) != ck_loc_cache[ck_loc[k].dev]) changed = 1;
    if (!changed) return;
    for (li = 0; li < CK_NLINKS; ++li) {
        double e[6] = {0, 0, 0, 0, 0, 0}, E[12];
        for (k = ck_links[li].loc0; k < ck_links[li].loc0 + ck_links[li].nloc; ++k) {
            e[ck_loc[k].comp] += ck_dev(ck_loc[k].dev);
            ck_loc_cache[ck_loc[k].dev] = ck_dev(ck_loc[k].dev);
        }
        ck_error_transform(e, E);
        ck_compose(ck_links[li].P, E, ck_placed[li]);
    }
    ck_placed_ok = 1;
}

typedef struct { double dir[3], point[3]; int axis, rotary; double sign; } ck_frame_t;

/* Pose of the end of links [first, first+count) at commands q (mm, rad); err: with the deviations. */
static void ck_chain(int first, int count, const double *q, int err, double *M, ck_frame_t *frames, int *nf,
                     double sign) {
    int li, k;
    ck_identity(M);
    for (li = first; li < first + count; ++li) {
        const ck_link_t *l = &ck_links[li];
        ck_compose(M, err ? ck_placed[li] : l->P, M);
        if (l->kind == 0) continue;
        if (frames) {
            ck_frame_t *f = &frames[(*nf)++];
            for (k = 0; k < 3; ++k) {
                f->dir[k] = M[3 * k] * l->dir[0] + M[3 * k + 1] * l->dir[1] + M[3 * k + 2] * l->dir[2];
                f->point[k] = M[9 + k];
            }
            f->axis = l->axis;
            f->rotary = l->kind == 2;
            f->sign = sign;
        }
        if (l->kind == 1) {
            const double d = q[l->axis];
            for (k = 0; k < 3; ++k)
                M[9 + k] += (M[3 * k] * l->dir[0] + M[3 * k + 1] * l->dir[1] + M[3 * k + 2] * l->dir[2]) * d;
        } else {
            double Rm[12];
            ck_identity(Rm);
            ck_axis_rotation(l->dir, q[l->axis], Rm);
            ck_compose(M, Rm, M);
        }
        if (err && l->ncmp > 0) {
            double e[6] = {0, 0, 0, 0, 0, 0}, E[12];
            for (k = l->cmp0; k < l->cmp0 + l->ncmp; ++k)
                e[ck_cmp[k].comp] += ck_basis(&ck_cmp[k], q[l->axis], l->modulo);
            ck_error_transform(e, E);
            ck_compose(M, E, M);
        }
    }
}

/* Tool tip (at tool length L along the tool direction) and tool axis in the workpiece frame; with J, the screw
 * Jacobian d(tip, axis)/dq (src/cnccomp/inverse_kinematics.cpp, toolPoseJacobian). */
static void ck_tool(const double *q, double L, int err, double *tip, double *axis, double J[6][CK_NAX]) {
    double W[12], T[12], tipB[3], axB[3], d[3];
    ck_frame_t frames[CK_NLINKS];
    int nf = 0, i, k;
    ck_chain(0, CK_NW, q, err, W, J ? frames : 0, &nf, -1.0);
    ck_chain(CK_NW, CK_NLINKS - CK_NW, q, err, T, J ? frames : 0, &nf, 1.0);
    for (k = 0; k < 3; ++k) {
        axB[k] = T[3 * k] * ck_tool_dir[0] + T[3 * k + 1] * ck_tool_dir[1] + T[3 * k + 2] * ck_tool_dir[2];
        tipB[k] = axB[k] * L + T[9 + k];
    }
    for (k = 0; k < 3; ++k) {
        tip[k] = W[k] * (tipB[0] - W[9]) + W[3 + k] * (tipB[1] - W[10]) + W[6 + k] * (tipB[2] - W[11]);
        axis[k] = W[k] * axB[0] + W[3 + k] * axB[1] + W[6 + k] * axB[2];
    }
    if (!J) return;
    for (i = 0; i < 6; ++i)
        for (k = 0; k < CK_NAX; ++k) J[i][k] = 0.0;
    for (i = 0; i < nf; ++i) {
        const ck_frame_t *f = &frames[i];
        double dt[3], da[3];
        if (f->rotary) {
            for (k = 0; k < 3; ++k) d[k] = tipB[k] - f->point[k];
            dt[0] = f->dir[1] * d[2] - f->dir[2] * d[1];
            dt[1] = f->dir[2] * d[0] - f->dir[0] * d[2];
            dt[2] = f->dir[0] * d[1] - f->dir[1] * d[0];
            da[0] = f->dir[1] * axB[2] - f->dir[2] * axB[1];
            da[1] = f->dir[2] * axB[0] - f->dir[0] * axB[2];
            da[2] = f->dir[0] * axB[1] - f->dir[1] * axB[0];
        } else {
            for (k = 0; k < 3; ++k) { dt[k] = f->dir[k]; da[k] = 0.0; }
        }
        for (k = 0; k < 3; ++k) {
            J[k][f->axis] = f->sign * (W[k] * dt[0] + W[3 + k] * dt[1] + W[6 + k] * dt[2]);
            J[3 + k][f->axis] = f->sign * (W[k] * da[0] + W[3 + k] * da[1] + W[6 + k] * da[2]);
        }
    }
}

/* Solves N x = g (N symmetric positive definite, n x n) by Cholesky; 0 on success. A pivot is refused when it is
 * below 1e-12 of its own diagonal entry (scale-free: joints in mm and rad, long arms): a singular direction. */
static int ck_cholesky_solve(double N[CK_NAX][CK_NAX], const double *g, double *x) {
    double Lm[CK_NAX][CK_NAX], y[CK_NAX];
    int i, j, k;
    for (i = 0; i < CK_NAX; ++i) {
        for (j = 0; j <= i; ++j) {
            double s = N[i][j];
            for (k = 0; k < j; ++k) s -= Lm[i][k] * Lm[j][k];
            if (i == j) {
                if (!(s > 1e-12 * N[i][i])) return -1;
                Lm[i][i] = sqrt(s);
            } else {
                Lm[i][j] = s / Lm[j][j];
            }
        }
    }
    for (i = 0; i < CK_NAX; ++i) {
        double s = g[i];
        for (k = 0; k < i; ++k) s -= Lm[i][k] * y[k];
        y[i] = s / Lm[i][i];
    }
    for (i = CK_NAX - 1; i >= 0; --i) {
        double s = y[i];
        for (k = i + 1; k < CK_NAX; ++k) s -= Lm[k][i] * x[k];
        x[i] = s / Lm[i][i];
    }
    return 0;
}

/* The singular-pose policy (cnccomp::SingularPosePolicy, src/cnccomp/pose_solver.hpp) at this Jacobian: the damping
 * D = CK_REG^2 sum_i phi(sigma_i) v_i v_i^T of the rotary joints (rows and columns of the rotary joints, 0 elsewhere),
 * sigma_i^2 and v_i the eigenvalues and unit eigenvectors of G = Ja^T Ja, Ja the tool axis' derivatives by the rotary
 * joints (rows 3..5 of J, unweighted: sigma in rad/rad), phi(s) = (1 - s/CK_SINGULAR_ZONE)^2 below the zone and 0 at
 * or above it; without a zone phi = 1 (D = CK_REG^2 I). Eigen-decomposition by cyclic Jacobi rotations with the
 * eigenvectors accumulated: none for one rotary joint, exactly one (the closed form) for two, sweeps until the
 * off-diagonal part vanishes for three or more. 0 when no direction is damped (D = 0). */
static int ck_damping(double J[6][CK_NAX], double D[CK_NAX][CK_NAX]) {
    double G[CK_NAX][CK_NAX], V[CK_NAX][CK_NAX];
    const double lam2 = CK_REG * CK_REG;
    int idx[CK_NAX], n = 0, a, b, k, e, sweep, any = 0;
    for (a = 0; a < CK_NAX; ++a)
        for (b = 0; b < CK_NAX; ++b) D[a][b] = 0.0;
    for (a = 0; a < CK_NAX; ++a)
        if (ck_rotary[a]) idx[n++] = a;
    if (n == 0) return 0;
    if (!(CK_SINGULAR_ZONE > 0)) {
        for (a = 0; a < n; ++a) D[idx[a]][idx[a]] = lam2;
        return 1;
    }
    for (a = 0; a < n; ++a)
        for (b = 0; b < n; ++b) {
            G[a][b] = 0.0;
            for (k = 0; k < 3; ++k) G[a][b] += J[3 + k][idx[a]] * J[3 + k][idx[b]];
            V[a][b] = a == b ? 1.0 : 0.0;
        }
    for (sweep = 0; sweep < 12; ++sweep) {
        double off = 0.0;
        for (a = 0; a < n; ++a)
            for (b = a + 1; b < n; ++b) off += G[a][b] * G[a][b];
        if (off < 1e-30) break;
        for (a = 0; a < n; ++a)
            for (b = a + 1; b < n; ++b) {
                double theta, t, c, sn, tau;
                if (G[a][b] == 0.0) continue;
                theta = (G[b][b] - G[a][a]) / (2.0 * G[a][b]);
                t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                c = 1.0 / sqrt(t * t + 1.0);
                sn = t * c;
                tau = sn / (1.0 + c);
                G[a][a] -= t * G[a][b];
                G[b][b] += t * G[a][b];
                G[a][b] = G[b][a] = 0.0;
                for (k = 0; k < n; ++k) {
                    double gka, gkb, vka, vkb;
                    vka = V[k][a];
                    vkb = V[k][b];
                    V[k][a] = vka - sn * (vkb + tau * vka);
                    V[k][b] = vkb + sn * (vka - tau * vkb);
                    if (k == a || k == b) continue;
                    gka = G[k][a];
                    gkb = G[k][b];
                    G[k][a] = G[a][k] = gka - sn * (gkb + tau * gka);
                    G[k][b] = G[b][k] = gkb + sn * (gka - tau * gkb);
                }
            }
    }
    for (e = 0; e < n; ++e) {
        const double sigma = G[e][e] > 0 ? sqrt(G[e][e]) : 0.0;
        double phi;
        if (!(sigma < CK_SINGULAR_ZONE)) continue;
        phi = (1.0 - sigma / CK_SINGULAR_ZONE) * (1.0 - sigma / CK_SINGULAR_ZONE);
        for (a = 0; a < n; ++a)
            for (b = 0; b < n; ++b) D[idx[a]][idx[b]] += lam2 * phi * V[a][e] * V[b][e];
        any = 1;
    }
    return any;
}

/* Normal equations of the weighted residual; reg != 0 adds the damping of the rotary joints towards anchor
 * (ck_damping: N += D, g += D (anchor - q)) and the constant pull CK_REG of the extra linear joints (not X Y Z). */
static void ck_normal(double J[6][CK_NAX], const double *tip_t, const double *ax_t, const double *tip,
                      const double *ax, const double *q, const double *anchor, int reg, double N[CK_NAX][CK_NAX],
                      double *g) {
    double r[6], D[CK_NAX][CK_NAX];
    const int damped = reg ? ck_damping(J, D) : 0;
    int i, j, k;
    for (k = 0; k < 3; ++k) {
        r[k] = tip_t[k] - tip[k];
        r[3 + k] = CK_AXIS_WEIGHT * (ax_t[k] - ax[k]);
    }
    for (i = 0; i < CK_NAX; ++i) {
        for (j = 0; j < CK_NAX; ++j) {
            double s = 0.0;
            for (k = 0; k < 3; ++k) s += J[k][i] * J[k][j] + CK_AXIS_WEIGHT * CK_AXIS_WEIGHT * J[3 + k][i] * J[3 + k][j];
            N[i][j] = damped ? s + D[i][j] : s;
        }
        g[i] = 0.0;
        for (k = 0; k < 3; ++k) g[i] += J[k][i] * r[k] + CK_AXIS_WEIGHT * J[3 + k][i] * r[3 + k];
        if (damped)
            for (j = 0; j < CK_NAX; ++j) g[i] += D[i][j] * (anchor[j] - q[j]);
        if (reg && ck_regularised[i] && !ck_rotary[i]) { /* extra linear joints (tool-tip mode): constant pull */
            N[i][i] += CK_REG * CK_REG;
            g[i] += CK_REG * CK_REG * (anchor[i] - q[i]);
        }
    }
}

static double ck_cost(const double *q, double L, const double *tip_t, const double *ax_t) {
    double tip[3], ax[3], c = 0.0;
    int k;
    ck_tool(q, L, 1, tip, ax, 0);
    for (k = 0; k < 3; ++k)
        c += (tip_t[k] - tip[k]) * (tip_t[k] - tip[k]) +
             CK_AXIS_WEIGHT * CK_AXIS_WEIGHT * (ax_t[k] - ax[k]) * (ax_t[k] - ax[k]);
    return c;
}

/* Joints q (mm, rad) of the erroneous machine near start putting its tip at tip_t and its axis at ax_t (workpiece
 * frame); the pull holds the regularised joints towards anchor. 0 when converged. */
static int ck_solve(const double *tip_t, const double *ax_t, double L, const double *anchor, const double *start,
                    double *q, int *iterations, double *residual) {
    double J[6][CK_NAX], N[CK_NAX][CK_NAX], g[CK_NAX], step[CK_NAX], tip[3], ax[3];
    int it, i, k, converged = 0, polish;
    for (i = 0; i < CK_NAX; ++i) q[i] = start[i];
    for (it = 0; it < CK_MAX_ITERATIONS; ++it) {
        double sn = 0.0, qn = 0.0, lim;
        ck_tool(q, L, 1, tip, ax, J);
        ck_normal(J, tip_t, ax_t, tip, ax, q, anchor, 1, N, g);
        if (ck_cholesky_solve(N, g, step)) break;
        for (i = 0; i < CK_NAX; ++i) {
            q[i] += step[i];
            sn += step[i] * step[i];
            qn += q[i] * q[i];
        }
        lim = 1e-13 * (1.0 + sqrt(qn));
        if (0.1 * CK_TOLERANCE > lim) lim = 0.1 * CK_TOLERANCE;
        if (sqrt(sn) <= lim) {
            converged = 1;
            ++it;
            break;
        }
    }
    *iterations = it;
    if (converged && CK_POLISH) {
        /* Polish without the pull: regular poses then meet the axis fully; a step that would swing a rotary axis
         * (a singular direction) or does not lower the cost is refused. */
        double current = ck_cost(q, L, tip_t, ax_t);
        for (polish = 0; polish < 4; ++polish) {
            double trial[CK_NAX], rot = 0.0, c;
            ck_tool(q, L, 1, tip, ax, J);
            ck_normal(J, tip_t, ax_t, tip, ax, q, anchor, 0, N, g);
            if (CK_NAX > 6 || ck_cholesky_solve(N, g, step)) break;
            for (i = 0; i < CK_NAX; ++i) {
                if (ck_rotary[i] && fabs(step[i]) > rot) rot = fabs(step[i]);
                trial[i] = q[i] + step[i];
            }
            if (!(rot < CK_REG / CK_AXIS_WEIGHT)) break;
            c = ck_cost(trial, L, tip_t, ax_t);
            if (!(c < current)) break;
            for (i = 0; i < CK_NAX; ++i) q[i] = trial[i];
            current = c;
        }
    }
    ck_tool(q, L, 1, tip, ax, 0);
    *residual = 0.0;
    for (k = 0; k < 3; ++k) *residual += (tip_t[k] - tip[k]) * (tip_t[k] - tip[k]);
    *residual = sqrt(*residual);
    for (i = 0; i < CK_NAX; ++i)
        if (!isfinite(q[i])) converged = 0;
    return converged ? 0 : -1;
}

static double ck_slot(const EmcPose *p, int s) {
    switch (s) {
        case 0: return p->tran.x;
        case 1: return p->tran.y;
        case 2: return p->tran.z;
        case 3: return p->a;
        case 4: return p->b;
        case 5: return p->c;
        case 6: return p->u;
        case 7: return p->v;
        default: return p->w;
    }
}

static void ck_set_slot(EmcPose *p, int s, double v) {
    switch (s) {
        case 0: p->tran.x = v; break;
        case 1: p->tran.y = v; break;
        case 2: p->tran.z = v; break;
        case 3: p->a = v; break;
        case 4: p->b = v; break;
        case 5: p->c = v; break;
        case 6: p->u = v; break;
        case 7: p->v = v; break;
        default: p->w = v; break;
    }
}

/* Controller units (mm, deg from machine zero) <-> model commands (mm, rad). */
static double ck_to_model(int i, double v) { return v * (ck_rotary[i] ? CK_DEG : 1.0) + ck_zero[i]; }
static double ck_to_controller(int i, double v) { return (v - ck_zero[i]) / (ck_rotary[i] ? CK_DEG : 1.0); }

/* Inverse in model units: world w (controller units, per joint: the word of its letter) -> joints q (model). */
static int ck_inverse_model(int type, const double *w, const double *current, double *q, int *iterations,
                            double *residual) {
    double anchor[CK_NAX], start[CK_NAX], tip_t[3], ax_t[3];
    const double L = ck_tool_length();
    int i, k;
    ck_refresh();
    for (i = 0; i < CK_NAX; ++i) anchor[i] = ck_to_model(i, w[i]);
    if (type == 0) {
        /* joint mode: the nominal machine's pose at the commands */
        ck_tool(anchor, L, 0, tip_t, ax_t, 0);
        for (i = 0; i < CK_NAX; ++i) {
            const double c = current ? ck_to_model(i, current[i]) : anchor[i];
            start[i] = (isfinite(c) && fabs(c - anchor[i]) < (ck_rotary[i] ? CK_DEG : 1.0)) ? c : anchor[i];
        }
    } else {
        /* tool-tip mode: X Y Z are the tip in the world frame, the rotary words the angles */
        double p[3], tipn[3], nom[CK_NAX];
        /* G43: LinuxCNC adds the tool length to the Z word (emccanon.cc); taken off as trtfuncs.c does */
        for (k = 0; k < 3; ++k) p[k] = w[ck_xyz[k]] - ck_t0[k] - (k == 2 ? L : 0.0);
        for (k = 0; k < 3; ++k) tip_t[k] = ck_R0[0][k] * p[0] + ck_R0[1][k] * p[1] + ck_R0[2][k] * p[2];
        for (i = 0; i < CK_NAX; ++i) nom[i] = anchor[i];
        ck_tool(nom, L, 0, tipn, ax_t, 0); /* the nominal tool axis depends on the rotary axes only */
        for (i = 0; i < CK_NAX; ++i) {
            const double c = current ? ck_to_model(i, current[i]) : anchor[i];
            if (ck_regularised[i])
                start[i] = (isfinite(c) && fabs(c - anchor[i]) < (ck_rotary[i] ? CK_DEG : 1.0)) ? c : anchor[i];
            else
                start[i] = isfinite(c) ? c : 0.0;
        }
        for (k = 0; k < 3; ++k) anchor[ck_xyz[k]] = start[ck_xyz[k]];
    }
    return ck_solve(tip_t, ax_t, L, anchor, start, q, iterations, residual);
}

static void ck_report(int iterations, double residual, int fail) {
    ck_last_iterations = iterations;
    ck_last_residual = residual;
    ck_last_fail = fail;
    if (!ck_hal) return;
    *ck_hal->iterations = iterations;
    *ck_hal->residual = residual;
    *ck_hal->fail = fail;
}

int kinematicsInverse(const EmcPose *pos, double *joints, const KINEMATICS_INVERSE_FLAGS *iflags,
                      KINEMATICS_FORWARD_FLAGS *fflags) {
    double w[CK_NAX], q[CK_NAX], residual = 0.0;
    int i, iterations = 0, r;
    (void)iflags;
    (void)fflags;
    for (i = 0; i < CK_NAX; ++i) w[i] = ck_slot(pos, ck_world_slot[i]);
    r = ck_inverse_model(ck_type, w, joints, q, &iterations, &residual);
    if (r != 0 && !(residual <= CK_ACCEPT_RESIDUAL)) {
        /* not solved: the joints keep their values (LinuxCNC passes the current ones), fail is set */
        ck_report(iterations, residual, 1);
        return -1;
    }
    for (i = 0; i < CK_NAX; ++i)
        if (!isfinite(q[i])) {
            ck_report(iterations, residual, 1);
            return -1;
        }
    for (i = 0; i < CK_NAX; ++i) joints[i] = ck_to_controller(i, q[i]);
    ck_report(iterations, residual, r != 0);
    return 0;
}

/* Forward: the world words whose inverse gives these joints (fixed point w <- w + (joints - inverse(w)); the
 * inverse's derivative is the identity up to the deviations' size, so each pass gains their order of magnitude). */
int kinematicsForward(const double *joints, EmcPose *pos, const KINEMATICS_FORWARD_FLAGS *fflags,
                      KINEMATICS_INVERSE_FLAGS *iflags) {
    double w[CK_NAX], q[CK_NAX], jm[CK_NAX], back[CK_NAX], residual = 0.0;
    int i, pass, iterations = 0, r = 0, fail = 1;
    const double L = ck_tool_length();
    (void)fflags;
    (void)iflags;
    ck_refresh();
    for (i = 0; i < CK_NAX; ++i) {
        w[i] = joints[i];
        jm[i] = ck_to_model(i, joints[i]);
    }
    if (ck_type == 1) {
        double tip[3], ax[3];
        int k;
        ck_tool(jm, L, 1, tip, ax, 0);
        for (k = 0; k < 3; ++k)
            w[ck_xyz[k]] = ck_R0[k][0] * tip[0] + ck_R0[k][1] * tip[1] + ck_R0[k][2] * tip[2] + ck_t0[k] + (k == 2 ? L : 0.0);
    }
    for (pass = 0; pass < CK_FORWARD_PASSES; ++pass) {
        double d = 0.0;
        r = ck_inverse_model(ck_type, w, joints, q, &iterations, &residual);
        for (i = 0; i < CK_NAX; ++i) {
            back[i] = ck_to_controller(i, q[i]);
            if (ck_type == 1 && !ck_regularised[i]) continue; /* X Y Z: the tip, already exact */
            w[i] += joints[i] - back[i];
            if (fabs(joints[i] - back[i]) > d) d = fabs(joints[i] - back[i]);
        }
        if (!isfinite(d)) break;
        if (d <= 1e-12) {
            fail = r != 0 && !(residual <= CK_ACCEPT_RESIDUAL);
            break;
        }
    }
    for (i = 0; i < 9; ++i) ck_set_slot(pos, i, 0.0);
    for (i = 0; i < CK_NAX; ++i) ck_set_slot(pos, ck_world_slot[i], isfinite(w[i]) ? w[i] : joints[i]);
    ck_report(iterations, residual, fail);
    return 0;
}

static int ck_setup(void) {
    int res = 0, i;
    if (comp_id < 0) goto error;
    if (hal_set_unready(comp_id)) goto error;
    ck_hal = hal_malloc(sizeof(struct ck_hal_t));
    if (!ck_hal) goto error;
    res += hal_pin_float_newf(HAL_IN, &ck_hal->tool_offset, comp_id, "%s.tool-offset", CK_PREFIX);
    for (i = 0; i < CK_NDEV_PINS; ++i)
        res += hal_pin_float_newf(HAL_IN, &ck_hal->dev[i], comp_id, "%s.%s", CK_PREFIX, ck_dev_names[i]);
    for (i = CK_NDEV_PINS; i < CK_NDEV; ++i) ck_hal->dev[i] = ck_hal->tool_offset; /* no deviation: never read */
    res += hal_pin_bit_newf(HAL_OUT, &ck_hal->kinstype_is_0, comp_id, "kinstype.is-0");
    res += hal_pin_bit_newf(HAL_OUT, &ck_hal->kinstype_is_1, comp_id, "kinstype.is-1");
    res += hal_pin_bit_newf(HAL_OUT, &ck_hal->fail, comp_id, "%s.fail", CK_PREFIX);
    res += hal_pin_s32_newf(HAL_OUT, &ck_hal->iterations, comp_id, "%s.iterations", CK_PREFIX);
    res += hal_pin_float_newf(HAL_OUT, &ck_hal->residual, comp_id, "%s.residual", CK_PREFIX);
    if (res) goto error;
    *ck_hal->tool_offset = 0.0;
    for (i = 0; i < CK_NDEV_PINS; ++i) *ck_hal->dev[i] = ck_dev_init[i];
    *ck_hal->kinstype_is_0 = 1;
    *ck_hal->kinstype_is_1 = 0;
    *ck_hal->fail = 0;
    *ck_hal->iterations = 0;
    *ck_hal->residual = 0.0;
    hal_ready(comp_id);
    return 0;
error:
    ck_hal = 0;
    rtapi_print_msg(RTAPI_MSG_ERR, "%s: setup of the kinematics pins failed\n", CK_PREFIX);
    return -1;
}

EXPORT_SYMBOL(kinematicsType);
EXPORT_SYMBOL(kinematicsSwitchable);
EXPORT_SYMBOL(kinematicsSwitch);
EXPORT_SYMBOL(kinematicsInverse);
EXPORT_SYMBOL(kinematicsForward);

int kinematicsSwitchable(void) { return 1; }

int kinematicsSwitch(int new_type) {
    if (new_type < 0 || new_type > 1 || (new_type == 1 && !CK_TOOL_TIP_MODE)) {
        rtapi_print_msg(RTAPI_MSG_ERR, "%s: kinematicsSwitch: no type %d\n", CK_PREFIX, new_type);
        return -1;
    }
    ck_type = new_type;
    if (ck_hal) {
        *ck_hal->kinstype_is_0 = new_type == 0;
        *ck_hal->kinstype_is_1 = new_type == 1;
    }
    return 0;
}

KINEMATICS_TYPE kinematicsType(void) {
    static int is_setup = 0;
    if (!is_setup) {
        is_setup = 1;
        ck_setup();
    }
    return KINEMATICS_BOTH;
}
)C";

}  // namespace

IkOptions kinsSolverOptions(const KinsComponentOptions& o) {
    IkOptions ik;
    ik.tolerance = 0.1 * o.tolerance;  // the component's step test is 0.1 × tolerance (ck_solve)
    ik.maxIterations = 40;
    ik.axisWeight = o.axisWeight;
    ik.rotaryRegularization = o.rotaryRegularization;
    ik.singularZone = o.singularZone;
    ik.polish = o.polish;
    return ik;
}

std::string kinsDeviationPin(const MachineModel& m, int index, int k) {
    if (index < 0 || index >= static_cast<int>(m.deviations.size()))
        throw ModelError(fmt::format("machine '{}' has no deviation {}", m.name, index));
    const DeviationDef& d = m.deviations[index];
    const std::string base = "dev." + lowerName(d.name);
    return d.kind == DeviationKind::Location ? base : fmt::format("{}.{}", base, k);
}

std::string kinematicsComponent(const MachineModel& m, const DeviationSet& d, const KinsComponentOptions& o) {
    // ---- checks -------------------------------------------------------------------------------------------------
    if (o.name.empty() || !std::islower(static_cast<unsigned char>(o.name[0])) ||
        !std::all_of(o.name.begin(), o.name.end(), [](char c) {
            return std::islower(static_cast<unsigned char>(c)) || std::isdigit(static_cast<unsigned char>(c)) ||
                   c == '_';
        }))
        throw ModelError(fmt::format("kinematics component name '{}': expected lower-case letters, digits and '_', "
                                     "starting with a letter",
                                     o.name));
    d.requireMachine(m);
    if (!(o.maxIterations >= 1 && o.tolerance > 0 && o.axisWeight > 0 && o.rotaryRegularization > 0 && o.singularZone >= 0))
        throw ModelError("kinematics component options: maxIterations >= 1, tolerance, axisWeight and "
                         "rotaryRegularization > 0 expected");
    const int n = m.axisCount();
    if (n < 1 || n > kMaxAxes) throw ModelError(fmt::format("machine '{}': {} axes, 1..9 expected", m.name, n));
    std::vector<int> slot(n);
    std::set<int> used;
    for (int i = 0; i < n; ++i) {
        slot[i] = poseSlot(m.axisNames[i]);
        if (slot[i] < 0 || !used.insert(slot[i]).second)
            throw ModelError(fmt::format("machine '{}': axis '{}' has no LinuxCNC coordinate letter of its own (X Y Z "
                                         "A B C U V W, each once)",
                                         m.name, m.axisNames[i]));
    }
    if (d.values.size() != m.parameterCount())
        throw ModelError(fmt::format("deviation set of machine '{}' has {} values, {} expected", m.name,
                                     d.values.size(), m.parameterCount()));

    // Tool-tip mode: linear X, Y and Z; the other axes are rotary or extra linear axes held at their words.
    int xyz[3] = {-1, -1, -1};
    bool tipMode = true;
    for (int k = 0; k < 3; ++k) {
        xyz[k] = m.axisIndex(std::string(1, "XYZ"[k]));
        if (xyz[k] < 0 || m.axisLink(xyz[k]).kind != AxisKind::Linear) tipMode = false;
    }
    std::string coordinates;
    for (const auto& a : m.axisNames) coordinates += a;

    // ---- the machine data ----------------------------------------------------------------------------------------
    std::vector<std::string> pinNames;
    for (int k = 0; k < static_cast<int>(m.deviations.size()); ++k)
        for (int c = 0; c < m.deviations[k].size(); ++c) pinNames.push_back(kinsDeviationPin(m, k, c));
    {
        std::set<std::string> seen;
        for (const auto& p : pinNames)
            if (!seen.insert(p).second || o.name.size() + 1 + p.size() > 47)
                throw ModelError(fmt::format("machine '{}': HAL pin name '{}.{}' is not unique or longer than 47 "
                                             "characters",
                                             m.name, o.name, p));
    }
    const int nDev = static_cast<int>(pinNames.size());

    std::string links, locs, cmps, nodes;
    int nLoc = 0, nCmp = 0, nNodes = 0, nLinks = 0;
    const int nW = static_cast<int>(m.workpiece.links.size());
    for (Side side : {Side::Workpiece, Side::Tool}) {
        const Chain& chain = m.chain(side);
        for (int li = 0; li < static_cast<int>(chain.links.size()); ++li) {
            const Link& l = chain.links[li];
            const int loc0 = nLoc, cmp0 = nCmp;
            for (const DeviationDef& def : m.deviations) {
                if (def.side != side || def.link != li) continue;
                if (def.kind == DeviationKind::Location) {
                    locs += fmt::format("    {{{}, {}}}, /* {} */\n", def.component, def.offset, def.name);
                    ++nLoc;
                } else {
                    const int type = def.basis.type == ComponentBasis::Type::Polynomial ? 0
                                     : def.basis.type == ComponentBasis::Type::Fourier  ? 1
                                                                                         : 2;
                    const int order = type == 2 ? static_cast<int>(def.basis.nodes.size()) : def.basis.order;
                    cmps += fmt::format("    {{{}, {}, {}, {}, {}}}, /* {} */\n", def.component, type, order, nNodes,
                                        def.offset, def.name);
                    if (type == 2)
                        for (double x : def.basis.nodes) {
                            nodes += num(x) + ",";
                            ++nNodes;
                        }
                    ++nCmp;
                }
            }
            const int kind = l.kind == AxisKind::Fixed ? 0 : l.kind == AxisKind::Linear ? 1 : 2;
            const std::string flat = flatPose(l.placement);
            links += fmt::format("    {{{{{}}}, {{{}, {}, {}}}, {}, {}, {}, {}, {}, {}, {}}}, /* {} {} */\n", flat,
                                 num(l.direction.x()), num(l.direction.y()), num(l.direction.z()), kind, l.axisIndex,
                                 l.modulo ? 1 : 0, loc0, nLoc - loc0, cmp0, nCmp - cmp0,
                                 side == Side::Tool ? "tool" : "workpiece", l.name);
            ++nLinks;
        }
    }

    // The TCP world frame: the workpiece frame as it lies at machine zero (postproc/tcp_model.hpp):
    // world = R0 · p_w + t0, R0 = bRw(qz), t0 = bTw(qz) − bTt(qz), nominal machine.
    const Kinematics nominal(m);
    const AxisVector qz = m.fromController(AxisVector::Zero(n));
    const Pose w0 = nominal.baseToWorkpiece(qz), t0 = nominal.baseToTool(qz);
    const Vec3 origin = w0.translation() - t0.translation();

    std::string s;
    s += fmt::format("component {} \"Kinematics of machine '{}' with its identified deviations (generated by "
                     "cnccomp)\";\n",
                     o.name, m.name);
    s += "description\n\"\"\"\n";
    s += fmt::format(
        "Generated by cnccomp emit for machine '{}' ({} joints, coordinates {}). The exact model of the machine's two\n"
        "serial chains with every identified deviation: see cnccomp's README, LinuxCNC kinematics component.\n"
        "\n"
        "Build and install (Debian package linuxcnc-uspace-dev): halcompile --install {}.comp (sudo for a package\n"
        "install of LinuxCNC). Load it from the INI file:\n"
        "  [KINS] KINEMATICS = {}\n"
        "  [KINS] JOINTS = {}\n"
        "  [TRAJ] COORDINATES = {}\n"
        "and in the HAL file: net tool-offset motion.tooloffset.z => {}.tool-offset\n"
        "(joint i = axis i of the machine, in the order of the coordinates; joint values are the controller's\n"
        "machine coordinates, mm and degrees).\n"
        "\n"
        "kinstype 0 (default, joint mode): the axis words are the commands of the nominal machine; the joints\n"
        "put the real tool tip and tool axis where the nominal machine puts them at those commands.\n"
        "kinstype 1 (tool-tip mode{}): X Y Z = tool tip at {}.tool-offset in the workpiece frame as it lies at\n"
        "machine zero, rotary words = the angles. Switch with motion.switchkins-type (then M66 E0 L0).\n"
        "\n"
        "Pins: {}.dev.* (in, the deviations: link values in mm and rad, initialised to the identified ones),\n"
        "{}.tool-offset (in, mm), {}.fail (out, an inverse or forward did not converge),\n"
        "{}.iterations (out, s32), {}.residual (out, mm), kinstype.is-0 and kinstype.is-1 (out).\n"
        "\"\"\";\n",
        m.name, n, coordinates, o.name, o.name, n, coordinates, o.name,
        tipMode ? "" : ": not available, the machine has no linear X, Y and Z", o.name, o.name, o.name, o.name,
        o.name, o.name);
    s += "// halcompile needs one pin; the kinematics functions cannot reach instance pins (userkins.comp, note 1),\n"
         "// their pins are made by ck_setup() below.\n";
    s += "pin out s32 generated = 1 \"1: generated by cnccomp\";\n";
    s += "option userspace no;\n";
    s += "license \"GPL\";\n";
    s += "author \"cnccomp (generated)\";\n";
    s += ";;\n\n";
    s += "#include \"rtapi_math.h\"\n#include \"kinematics.h\"\n\n";
    s += fmt::format("/* Machine '{}' ({}). Generated: do not edit, run cnccomp emit again. */\n", m.name,
                     m.sourceFile.empty() ? "no file" : std::filesystem::path(m.sourceFile).filename().string());
    s += fmt::format("#define CK_PREFIX \"{}\"\n", o.name);
    s += fmt::format("#define CK_NAX {}\n#define CK_NW {}\n#define CK_NLINKS {}\n", n, nW, nLinks);
    s += fmt::format("#define CK_NDEV_PINS {}\n#define CK_NDEV {}\n", nDev, std::max(nDev, 1));
    s += fmt::format("#define CK_NLOC {}\n#define CK_NNODES {}\n", nLoc, nNodes);
    s += fmt::format("#define CK_MAX_ITERATIONS {}\n#define CK_TOLERANCE {}\n", o.maxIterations, num(o.tolerance));
    s += fmt::format("#define CK_AXIS_WEIGHT {}\n#define CK_REG {}\n#define CK_SINGULAR_ZONE {}\n#define CK_POLISH {}\n",
                     num(o.axisWeight), num(o.rotaryRegularization), num(o.singularZone), o.polish ? 1 : 0);
    s += "#define CK_ACCEPT_RESIDUAL 1e-6 /* mm: an unconverged solve is still used (fail set) below this */\n";
    s += "#define CK_FORWARD_PASSES 12\n";
    s += fmt::format("#define CK_TOOL_TIP_MODE {}\n\n", tipMode ? 1 : 0);
    s += "typedef struct {\n"
         "    double P[12];      /* nominal placement: R row-major, t (mm) */\n"
         "    double dir[3];     /* unit direction of motion / rotation in the placed frame */\n"
         "    int kind;          /* 0 fixed, 1 linear, 2 rotary */\n"
         "    int axis;          /* joint index, -1 for a fixed link */\n"
         "    int modulo;\n"
         "    int loc0, nloc;    /* location deviations: ck_loc[loc0 .. loc0 + nloc) */\n"
         "    int cmp0, ncmp;    /* component deviations: ck_cmp[cmp0 .. cmp0 + ncmp) */\n"
         "} ck_link_t;\n"
         "typedef struct { int comp; int dev; } ck_loc_t;  /* error component 0..5 (x y z a b c), dev pin */\n"
         "typedef struct { int comp; int type; int order; int node0; int dev; } ck_cmp_t;\n"
         "/* type 0 polynomial (coef k of q^(k+1)), 1 Fourier (cos kq, sin kq pairs), 2 table (order = node count,\n"
         "   nodes ck_nodes[node0 ..], linear interpolation, modulo axes wrap every 2 pi); coefficients from pin dev */\n\n";
    s += fmt::format("/* workpiece chain first (links 0 .. {}), then the tool chain */\n", nW - 1);
    s += "static const ck_link_t ck_links[CK_NLINKS] = {\n" + links + "};\n";
    s += "static const ck_loc_t ck_loc[" + std::to_string(std::max(nLoc, 1)) + "] = {\n" +
         (nLoc ? locs : "    {0, 0},\n") + "};\n";
    s += "static const ck_cmp_t ck_cmp[" + std::to_string(std::max(nCmp, 1)) + "] = {\n" +
         (nCmp ? cmps : "    {0, 0, 0, 0, 0},\n") + "};\n";
    if (nNodes > 0) s += "static const double ck_nodes[" + std::to_string(nNodes) + "] = {" + nodes + "};\n";
    s += "/* deviation values identified (link values, mm and rad) = the dev pins' initial values */\n";
    s += "static const double ck_dev_init[CK_NDEV] = {\n";
    for (int i = 0; i < nDev; ++i) s += "    " + num(d.values[i]) + ", /* " + pinNames[i] + " */\n";
    if (nDev == 0) s += "    0\n";
    s += "};\n";
    s += "static const char *const ck_dev_names[CK_NDEV] = {";
    for (int i = 0; i < nDev; ++i) s += "\"" + pinNames[i] + "\",";
    if (nDev == 0) s += "\"\"";
    s += "};\n";
    std::string zero, rotary, slots, reg;
    for (int i = 0; i < n; ++i) {
        const Link& l = m.axisLink(i);
        zero += num(l.machineZero) + ",";
        rotary += l.kind == AxisKind::Rotary ? "1," : "0,";
        slots += std::to_string(slot[i]) + ",";
        const bool isXyz = i == xyz[0] || i == xyz[1] || i == xyz[2];
        reg += (l.kind == AxisKind::Rotary || (l.kind == AxisKind::Linear && !isXyz && tipMode)) ? "1," : "0,";
    }
    s += "/* per joint: machine zero (model command at controller 0; mm, rad), rotary, EmcPose slot (X Y Z A B C U V\n"
         "   W = 0..8), pulled towards its word (rotary axes; extra linear axes) */\n";
    s += "static const double ck_zero[CK_NAX] = {" + zero + "};\n";
    s += "static const int ck_rotary[CK_NAX] = {" + rotary + "};\n";
    s += "static const int ck_world_slot[CK_NAX] = {" + slots + "};\n";
    s += "static const int ck_regularised[CK_NAX] = {" + reg + "};\n";
    s += fmt::format("static const int ck_xyz[3] = {{{}, {}, {}}};\n", std::max(xyz[0], 0), std::max(xyz[1], 0),
                     std::max(xyz[2], 0));
    s += fmt::format("static const double ck_tool_dir[3] = {{{}, {}, {}}};\n", num(m.toolDirection.x()),
                     num(m.toolDirection.y()), num(m.toolDirection.z()));
    s += "/* tool-tip mode world frame: world = R0 p_w + t0 (the workpiece frame at machine zero, nominal) */\n";
    s += "static const double ck_R0[3][3] = {";
    for (int r = 0; r < 3; ++r)
        s += fmt::format("{{{}, {}, {}}},", num(w0.linear()(r, 0)), num(w0.linear()(r, 1)), num(w0.linear()(r, 2)));
    s += "};\n";
    s += fmt::format("static const double ck_t0[3] = {{{}, {}, {}}};\n", num(origin.x()), num(origin.y()),
                     num(origin.z()));
    s += kBody;
    return s;
}

}  // namespace cnccomp::controllers::linuxcnc

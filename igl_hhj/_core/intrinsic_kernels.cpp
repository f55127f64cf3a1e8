// The drop-in's intrinsic smoothing (igl_hhj/intrinsic_numpy.py is the readable numpy
// reference; tests/vertex_stage/test_intrinsic.py compares them): twiced implicit diffusion of the
// per-vertex components X = (h, Re z, Im z), h with the scalar cotangent Laplacian and
// the spin-2 deviator z with the connection Laplacian (L_c z)_i = sum_j w_ij (z_i -
// r_ij z_j).  One Jacobi PCG per solve, with separate CG scalars for every (connected
// component, part) pair (part 0: h; part 1: z, its two real coordinates sharing one
// scalar so that a change of frames (a rotation of each z) commutes with the
// iteration): a component's iterates are those of its own solve, and the stopping
// test |r| <= rtol |b| is applied to each pair.  Reductions are deterministic: fixed
// chunks for one component, a serial pass over the rows for several.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core.hpp"

namespace hhj {

namespace {

struct HZSystem {
    i64 n = 0;
    std::vector<i64> indptr;
    std::vector<std::int32_t> indices;
    std::vector<double> a, pc, ps;   // entry, cos and sin of its phase
    std::vector<double> dinv;
};

// y = A x on (n, 3) rows: y_h = sum a x_h, y_z = sum a (pc + i ps) x_z
void apply(const HZSystem& S, const double* x, double* y, int nt) {
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 r = 0; r < S.n; ++r) {
        double h = 0.0, zr = 0.0, zi = 0.0;
        for (i64 q = S.indptr[r]; q < S.indptr[r + 1]; ++q) {
            const double* xc = x + 3 * (i64)S.indices[q];
            const double a = S.a[q], c = a * S.pc[q], s = a * S.ps[q];
            h += a * xc[0];
            zr += c * xc[1] - s * xc[2];
            zi += s * xc[1] + c * xc[2];
        }
        y[3 * r] = h; y[3 * r + 1] = zr; y[3 * r + 2] = zi;
    }
}

// Several groups in parallel while chunks x groups stay below this (the partial sums are
// zeroed and summed at every reduction); above it one serial pass.
constexpr i64 GROUP_CHUNK_MAX = 1 << 14;

// Row reductions: fn(row, vals) adds row's contributions vals[k][part] (k < K quantities,
// part 0: h, part 1: z) and may write that row's entries of the work vectors.  out[(k ng +
// g) 2 + part] receives the sums per group g.  One group: fixed chunks in parallel, then a
// serial sum over the chunks (the same bits for any thread count); several groups: the same
// per group while chunks x groups <= GROUP_CHUNK_MAX, else one serial pass.
template <int K, class RowFn>
void reduce_rows(i64 n, const std::int32_t* group, i64 ng, int nt, std::vector<double>& out, RowFn fn) {
    out.assign((size_t)K * ng * 2, 0.0);
    if (ng == 1) {
        const i64 nch = (n + CHUNK - 1) / CHUNK;
        std::vector<double> part((size_t)std::max<i64>(nch, 1) * K * 2, 0.0);
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
        for (i64 c = 0; c < nch; ++c) {
            double acc[K][2] = {};
            for (i64 r = c * CHUNK; r < std::min(n, (c + 1) * CHUNK); ++r) {
                double v[K][2] = {};
                fn(r, v);
                for (int k = 0; k < K; ++k) { acc[k][0] += v[k][0]; acc[k][1] += v[k][1]; }
            }
            for (int k = 0; k < K; ++k) { part[(c * K + k) * 2] = acc[k][0]; part[(c * K + k) * 2 + 1] = acc[k][1]; }
        }
        for (i64 c = 0; c < nch; ++c)
            for (int k = 0; k < K; ++k) { out[2 * k] += part[(c * K + k) * 2]; out[2 * k + 1] += part[(c * K + k) * 2 + 1]; }
        return;
    }
    const i64 nch = (n + CHUNK - 1) / CHUNK;
    if (nch > 1 && nch * ng <= GROUP_CHUNK_MAX) {
        // several groups, few enough: per-chunk partial sums of every group in parallel, then
        // a serial sum over the chunks (the same bits for any thread count)
        std::vector<double> part((size_t)nch * K * ng * 2, 0.0);
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
        for (i64 c = 0; c < nch; ++c) {
            double* pc = &part[(size_t)c * K * ng * 2];
            for (i64 r = c * CHUNK; r < std::min(n, (c + 1) * CHUNK); ++r) {
                double v[K][2] = {};
                fn(r, v);
                const i64 g = group[r];
                for (int k = 0; k < K; ++k) { pc[(k * ng + g) * 2] += v[k][0]; pc[(k * ng + g) * 2 + 1] += v[k][1]; }
            }
        }
        for (i64 c = 0; c < nch; ++c)
            for (i64 q = 0; q < K * ng * 2; ++q) out[q] += part[(size_t)c * K * ng * 2 + q];
        return;
    }
    for (i64 r = 0; r < n; ++r) {
        double v[K][2] = {};
        fn(r, v);
        const i64 g = group[r];
        for (int k = 0; k < K; ++k) { out[(k * ng + g) * 2] += v[k][0]; out[(k * ng + g) * 2 + 1] += v[k][1]; }
    }
}

// Solve A x = b (x0 = 0), Jacobi-preconditioned, CG scalars per (group, part), three fused
// sweeps per iteration (A p with p.Ap; the update of x and r with r.r and r.(D^-1 r); p).
// Returns 0 converged, 1 iteration cap, 3 breakdown (non-positive curvature).
// r, p, q: work vectors of n x 3 (reused across solves: no fresh pages per solve).
// PART 2: h and z together (one sweep for both); PART 0: h alone, PART 1: z alone (the
// other part's entries of x, r, p, q are neither read nor written, and it counts as
// converged): each part's operations and sums are those of PART 2, so two calls with
// PART 0 and 1, on two threads, give PART 2's bits.
template <int PART>
int pcg_hz_part(const HZSystem& S, const std::int32_t* group, i64 ng, const double* b, double* x,
                double rtol, i64 maxiter, int nt, i64* its, std::vector<double>& r, std::vector<double>& p,
                std::vector<double>& q) {
    constexpr bool H = PART != 1, Z = PART != 0;
    const i64 n = S.n;
    const size_t n3 = (size_t)n * 3;
    const size_t np = (size_t)ng * 2;
    const int th = nt;      // reduce_rows: the same bits for any thread count, one group or several
    r.resize(n3); p.resize(n3); q.resize(n3);
    std::vector<double> red;
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(th)
#endif
    for (i64 k = 0; k < (i64)n3; ++k) r[k] = b[k];
    std::vector<double> bb(np), rz(np), alpha(np), beta(np);
    std::vector<unsigned char> done(np, 0);
    auto gid = [&](i64 row) { return ng == 1 ? (i64)0 : (i64)group[row]; };
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(th)
#endif
    for (i64 k = 0; k < (i64)n3; ++k) x[k] = 0.0;
    // bb = b.b, rz = r.(D^-1 r), p = D^-1 r
    reduce_rows<2>(n, group, ng, th, red, [&](i64 i, double (&v)[2][2]) {
        const double d = S.dinv[i];
        const double* ri = &r[3 * i];
        double* pi = &p[3 * i];
        if (H) {
            pi[0] = d * ri[0];
            v[0][0] = ri[0] * ri[0];
            v[1][0] = d * v[0][0];
        }
        if (Z) {
            pi[1] = d * ri[1]; pi[2] = d * ri[2];
            v[0][1] = ri[1] * ri[1] + ri[2] * ri[2];
            v[1][1] = d * v[0][1];
        }
    });
    bool all = true;
    for (size_t k = 0; k < np; ++k) {
        bb[k] = red[k];
        rz[k] = red[np + k];
        done[k] = !(bb[k] > 0.0);
        all = all && done[k];
    }
    *its = 0;
    if (all) return 0;
    for (i64 it = 1; it <= maxiter; ++it) {
        // q = A p, p.q
        reduce_rows<1>(n, group, ng, th, red, [&](i64 i, double (&v)[1][2]) {
            double h = 0.0, zr = 0.0, zi = 0.0;
            for (i64 e = S.indptr[i]; e < S.indptr[i + 1]; ++e) {
                const double* pc = &p[3 * (i64)S.indices[e]];
                const double a = S.a[e];
                if (H) h += a * pc[0];
                if (Z) {
                    const double c = a * S.pc[e], s = a * S.ps[e];
                    zr += c * pc[1] - s * pc[2];
                    zi += s * pc[1] + c * pc[2];
                }
            }
            double* qi = &q[3 * i];
            const double* pi = &p[3 * i];
            if (H) { qi[0] = h; v[0][0] = pi[0] * h; }
            if (Z) { qi[1] = zr; qi[2] = zi; v[0][1] = pi[1] * zr + pi[2] * zi; }
        });
        for (size_t k = 0; k < np; ++k) {
            if (done[k]) { alpha[k] = 0.0; continue; }
            if (!(red[k] > 0.0)) return 3;
            alpha[k] = rz[k] / red[k];
        }
        // x += alpha p, r -= alpha q; r.r and r.(D^-1 r)
        reduce_rows<2>(n, group, ng, th, red, [&](i64 i, double (&v)[2][2]) {
            const i64 g = gid(i);
            const double a0 = alpha[2 * g], a1 = alpha[2 * g + 1], d = S.dinv[i];
            double* xi = x + 3 * i;
            double* ri = &r[3 * i];
            const double* pi = &p[3 * i];
            const double* qi = &q[3 * i];
            if (H) {
                xi[0] += a0 * pi[0]; ri[0] -= a0 * qi[0];
                v[0][0] = ri[0] * ri[0];
                v[1][0] = d * v[0][0];
            }
            if (Z) {
                xi[1] += a1 * pi[1]; ri[1] -= a1 * qi[1];
                xi[2] += a1 * pi[2]; ri[2] -= a1 * qi[2];
                v[0][1] = ri[1] * ri[1] + ri[2] * ri[2];
                v[1][1] = d * v[0][1];
            }
        });
        all = true;
        for (size_t k = 0; k < np; ++k) {
            if (!done[k] && red[k] <= rtol * rtol * bb[k]) done[k] = 1;
            all = all && done[k];
            beta[k] = done[k] ? 0.0 : red[np + k] / rz[k];
            if (!done[k]) rz[k] = red[np + k];
        }
        *its = it;
        if (all) return 0;
        // p = D^-1 r + beta p (frozen pairs keep their p)
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(th)
#endif
        for (i64 i = 0; i < n; ++i) {
            const i64 g = gid(i);
            const double d = S.dinv[i];
            if (H && !done[2 * g]) p[3 * i] = d * r[3 * i] + beta[2 * g] * p[3 * i];
            if (Z && !done[2 * g + 1]) {
                p[3 * i + 1] = d * r[3 * i + 1] + beta[2 * g + 1] * p[3 * i + 1];
                p[3 * i + 2] = d * r[3 * i + 2] + beta[2 * g + 1] * p[3 * i + 2];
            }
        }
    }
    return 1;
}

}  // namespace

// Connected components of the vertex graph (union-find over E), labelled in the order
// of their smallest vertex; vertices without edges join label 0 (their rows stay 0 in
// every solve, so they add nothing to any reduction).  Returns the number of labels.
i64 vertex_groups(i64 nV, const i32* E, i64 nE, std::vector<std::int32_t>& label) {
    std::vector<i64> parent(nV);
    std::vector<unsigned char> has_edge(nV, 0);
    for (i64 v = 0; v < nV; ++v) parent[v] = v;
    auto find = [&](i64 v) {
        while (parent[v] != v) { parent[v] = parent[parent[v]]; v = parent[v]; }
        return v;
    };
    for (i64 e = 0; e < nE; ++e) {
        const i64 a = find(E[2 * e]), b = find(E[2 * e + 1]);
        has_edge[E[2 * e]] = has_edge[E[2 * e + 1]] = 1;
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
    label.assign(nV, 0);
    std::vector<std::int32_t> root_label(nV, -1);
    i64 ng = 0;
    for (i64 v = 0; v < nV; ++v) {
        if (!has_edge[v]) continue;
        const i64 r = find(v);
        if (root_label[r] < 0) root_label[r] = (std::int32_t)ng++;
        label[v] = root_label[r];
    }
    return std::max<i64>(ng, 1);
}

// transport_phases (intrinsic.transport_phase_components): per edge (i < j) the cos and
// sin of 2 rho, rho the angle in the frame of i of e1_j carried onto the plane of i by
// the minimal rotation N_j -> N_i (x^2 - y^2, 2xy over x^2 + y^2); 0, 0 where undefined.
// Frames as tangent_frame, +z for non-finite normals.
void transport_phases(const double* N, i64 nV, const i32* E, i64 nE, double* phase, int nt) {
    std::vector<double> fr((size_t)nV * 9);
    normal_frames(N, nV, fr.data(), nt);
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 e = 0; e < nE; ++e) {
        const double* fi = &fr[9 * (i64)E[2 * e]];
        const double* fj = &fr[9 * (i64)E[2 * e + 1]];
        double t[3];
        min_rotation(fj + 3, fj, fi, t);
        const double x = dot3(t, fi + 3), y = dot3(t, fi + 6), n2 = x * x + y * y;
        double c = (x * x - y * y) / n2, s = 2.0 * x * y / n2;
        if (!(std::isfinite(c) && std::isfinite(s))) { c = 0.0; s = 0.0; }
        phase[2 * e] = c;
        phase[2 * e + 1] = s;
    }
}

// adaptive_radius (intrinsic.adaptive_radius): r_T = radius * mean over T's corners of
// a_v = clip(gain rho_v^power / max(c_v, 1e-3), lo, hi), rho and c the area-weighted
// ring means of rough and of h_v (|h| + |z|) of the pilot P (#V,3); non-finite a -> 1.
void adaptive_radius(const double* V, const i64* F, i64 nF, i64 nV, const double* P, const double* rough,
                     double radius, double gain, double power, double lo, double hi, double* r, int nt) {
    // faces in parallel; the per-vertex sums gather v's corners in face order (the bits of
    // a serial scatter over the faces, for any thread count)
    const VertexCorners vc(F, nF, nV);
    std::vector<double> area(nF), hT(nF);
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 f = 0; f < nF; ++f) {
        double l[3];
        area[f] = face_lengths(V, F, f, l);
        hT[f] = (l[0] + l[1] + l[2]) / 3.0;
    }
    std::vector<double> cv(nV);
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 v = 0; v < nV; ++v) {
        double hsum = 0.0, cnt = 0.0;
        for (i64 q = vc.start[v]; q < vc.start[v + 1]; ++q) { hsum += hT[vc.corner[q] / 3]; cnt += 1.0; }
        const double hv = hsum / std::max(cnt, 1.0);
        cv[v] = hv * (std::fabs(P[3 * v]) + std::hypot(P[3 * v + 1], P[3 * v + 2]));
    }
    std::vector<double> mc(nF), mr(nF);
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 f = 0; f < nF; ++f) {
        double c = 0.0, rr = 0.0;
        for (int k = 0; k < 3; ++k) { c += cv[F[3 * f + k]] / 3.0; rr += rough[F[3 * f + k]] / 3.0; }
        mc[f] = c; mr[f] = rr;
    }
    std::vector<double> a(nV);
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 v = 0; v < nV; ++v) {
        double num_c = 0.0, num_r = 0.0, den = 0.0;
        for (i64 q = vc.start[v]; q < vc.start[v + 1]; ++q) {
            const i64 f = vc.corner[q] / 3;
            num_c += area[f] * mc[f]; num_r += area[f] * mr[f]; den += area[f];
        }
        const double c = num_c / den, rho = num_r / den;
        double x = gain * std::pow(rho, power) / std::max(c, 1e-3);
        x = std::isfinite(x) ? std::min(std::max(x, lo), hi) : 1.0;
        a[v] = x;
    }
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 f = 0; f < nF; ++f)
        r[f] = radius * (a[F[3 * f]] + a[F[3 * f + 1]] + a[F[3 * f + 2]]) / 3.0;
}

// principal_hz (reference_intrinsic.principal, tests/vertex_stage): k1,2 = h +- |z|, PD1 = cos(phi) e1 + sin(phi) e2,
// phi = arg(z) / 2, PD2 = N x PD1, in the frames of N (tangent_frame; +z if non-finite).
void principal_hz(const double* X, const double* N, i64 n, double* PD1, double* PD2, double* PV1,
                  double* PV2, int nt) {
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 v = 0; v < n; ++v) {
        double nn[3], e1[3], e2[3];
        const bool fin = std::isfinite(N[3 * v]) && std::isfinite(N[3 * v + 1]) && std::isfinite(N[3 * v + 2]);
        for (int a = 0; a < 3; ++a) nn[a] = fin ? N[3 * v + a] : (a == 2 ? 1.0 : 0.0);
        tangent_frame(nn, e1, e2);
        const double h = X[3 * v], a = std::hypot(X[3 * v + 1], X[3 * v + 2]);
        const double phi = 0.5 * std::atan2(X[3 * v + 2], X[3 * v + 1]);
        const double c = std::cos(phi), s = std::sin(phi);
        double d[3];
        for (int q = 0; q < 3; ++q) d[q] = c * e1[q] + s * e2[q];
        double d2[3];
        cross3(N + 3 * v, d, d2);
        for (int q = 0; q < 3; ++q) { PD1[3 * v + q] = d[q]; PD2[3 * v + q] = d2[q]; }
        PV1[v] = h + a;
        PV2[v] = h - a;
    }
}

// face_times (intrinsic.smoothing_times): t[f] = (factor r_f h_f)^2 / steps, h_f the mean
// edge length of f, r (#F,) or a scalar (r_stride 0).
void face_times(const double* V, const i64* F, i64 nF, const double* r, int r_stride, double factor,
                int steps, double* t, int nt) {
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 f = 0; f < nF; ++f) {
        double le[3];
        face_lengths(V, F, f, le);
        const double h = le[0] + le[1] + le[2];
        const double l = factor * r[f * r_stride] * (h / 3.0);
        t[f] = l * l / steps;
    }
}

// The smoothing: X (#V,3) <- (I - (I - G)^order) X, G = `steps` implicit steps
// (M + L_t) Y = M Y_prev solved for the correction (M + L_t) dY = -L_t Y_prev.  C0 (#F,3)
// per-face stiffness entries (cotangent x reliability), t (#F,) the per-face time (the
// stiffness is C0 t), m (#V,) the floored lumped mass, phase (#E,2) (cos, sin) of
// r_e = e^{2 i rho_e} for edge (i < j).  The CG scalars are per connected component of
// the vertex graph (vertex_groups); a failed solve leaves X unchanged.
namespace {

// The structure of the smoothing system (built once per call) and its values for given
// per-face times t: w_e = sum over the edge's faces of C0[f, i] t_f, A = M + L_t.
struct HZProblem {
    HZSystem S;
    std::vector<i64> diag_pos, pos_lo, pos_hi;
    std::vector<std::int32_t> label;
    i64 ngroups = 1;
    const i32 *E = nullptr, *EF = nullptr;
    const i8* ELI = nullptr;
    const double *C0 = nullptr, *m = nullptr;
    i64 nE = 0;
    // E lists i < j in lexicographic order (TriangleMesh.edges): then every row of the
    // matrix lists its entries in the order of the edges, and fill() may sum the diagonal
    // row by row (in parallel) with the bits of the serial scatter over the edges
    bool rows_in_edge_order = true;
    // 2: every solve runs its h part and its z part as two tasks on two threads (each a
    // serial PCG: no fork and join per iteration; for meshes too small for two threads per
    // sweep); 1: one PCG for both, its sweeps on nt threads
    int tasks = 1;
    std::vector<double> Y, R, AY, dY, acc, wr, wp, wq;    // work vectors of run()
    std::vector<double> dYz, wr2, wp2, wq2;               // the z task's (tasks = 2)

    HZProblem(i64 nV, const i32* E_, i64 nE_, const i32* EF_, const i8* ELI_, const double* C0_,
              const double* m_, const double* phase)
        : E(E_), EF(EF_), ELI(ELI_), C0(C0_), m(m_), nE(nE_) {
        ngroups = vertex_groups(nV, E, nE, label);
        S.n = nV;
        for (i64 e = 0; e < nE && rows_in_edge_order; ++e)
            rows_in_edge_order = E[2 * e] < E[2 * e + 1] && (e == 0 || E[2 * e - 2] <= E[2 * e]);
        vertex_laplacian(nV, E, nE, EF, ELI, C0, S.indptr, S.indices, S.a, diag_pos, &pos_lo, &pos_hi);
        const size_t nnz = S.a.size();
        S.pc.assign(nnz, 1.0);
        S.ps.assign(nnz, 0.0);
        for (i64 e = 0; e < nE; ++e) {
            const double c = phase[2 * e], s = phase[2 * e + 1];
            S.pc[pos_lo[e]] = c; S.ps[pos_lo[e]] = s;      // row min(e): z of max(e) in the frame of min(e)
            S.pc[pos_hi[e]] = c; S.ps[pos_hi[e]] = -s;     // row max(e): the inverse transport
        }
        S.dinv.resize(nV);
    }

    // w_e = sum over the edge's faces of C0[f, i] t_f
    double edge_weight(i64 e, const double* t) const {
        double we = 0.0;
        for (int s = 0; s < 2; ++s) {
            const i64 f = EF[2 * e + s];
            if (f >= 0) we += C0[3 * f + ELI[2 * e + s]] * t[f];
        }
        return we;
    }

    void fill(const double* t, int nt) {
        const i64 nV = S.n;
        if (rows_in_edge_order) {
            // off-diagonal entries: one per (edge, end), distinct positions
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
            for (i64 e = 0; e < nE; ++e) {
                const double we = edge_weight(e, t);
                S.a[pos_lo[e]] = -we;
                S.a[pos_hi[e]] = -we;
            }
            // diagonal m_v + sum of the row's w_e, in the row's (= the edges') order
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
            for (i64 v = 0; v < nV; ++v) {
                double d = m[v];
                for (i64 q = S.indptr[v]; q < S.indptr[v + 1]; ++q)
                    if (q != diag_pos[v]) d += -S.a[q];
                S.a[diag_pos[v]] = d;
                S.dinv[v] = 1.0 / d;
            }
            return;
        }
        for (i64 v = 0; v < nV; ++v) S.a[diag_pos[v]] = m[v];
        for (i64 e = 0; e < nE; ++e) {
            const double we = edge_weight(e, t);
            S.a[pos_lo[e]] = -we;
            S.a[pos_hi[e]] = -we;
            S.a[diag_pos[E[2 * e]]] += we;
            S.a[diag_pos[E[2 * e + 1]]] += we;
        }
        for (i64 v = 0; v < nV; ++v) S.dinv[v] = 1.0 / S.a[diag_pos[v]];
    }

    // X <- (I - (I - G)^order) X, G = `steps` implicit steps; X unchanged on failure
    int run(double* X, int steps, const std::vector<double>& binom, double rtol, i64 maxiter, int nt,
            i64* iterations) {
        const i64 n3 = S.n * 3;
        for (auto* v : {&Y, &R, &AY, &dY, &acc}) v->resize((size_t)n3);
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
        for (i64 q = 0; q < n3; ++q) { Y[q] = X[q]; acc[q] = 0.0; }
        for (size_t j = 0; j < binom.size(); ++j) {
            for (int st = 0; st < steps; ++st) {
                apply(S, Y.data(), AY.data(), nt);
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
                for (i64 q = 0; q < n3; ++q) R[q] = m[q / 3] * Y[q] - AY[q];
                i64 its = 0;
                const int status = solve(R.data(), dY.data(), rtol, maxiter, nt, &its);
                *iterations += its;
                if (status != 0) return status;
                const double bj = binom[j];
                const bool last = st + 1 == steps;
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
                for (i64 q = 0; q < n3; ++q) {
                    Y[q] += std::isfinite(dY[q]) ? dY[q] : 0.0;
                    if (last) acc[q] += bj * Y[q];
                }
            }
        }
        std::copy(acc.begin(), acc.end(), X);
        return 0;
    }

    // dY = A^-1 R: one PCG for h and z, or (tasks = 2) the two parts on two threads, with
    // the same bits; its = the larger part's iterations, as the one PCG counts them
    int solve(const double* Rv, double* dYv, double rtol, i64 maxiter, int nt, i64* its) {
        if (tasks < 2)
            return pcg_hz_part<2>(S, label.data(), ngroups, Rv, dYv, rtol, maxiter, nt, its, wr, wp, wq);
        const i64 n3 = S.n * 3;
        dYz.resize((size_t)n3);
        int st_h = 0, st_z = 0;
        i64 it_h = 0, it_z = 0;
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel sections num_threads(2)
#endif
        {
#ifdef IGL_HHJ_OPENMP
#pragma omp section
#endif
            st_h = pcg_hz_part<0>(S, label.data(), ngroups, Rv, dYv, rtol, maxiter, 1, &it_h, wr, wp, wq);
#ifdef IGL_HHJ_OPENMP
#pragma omp section
#endif
            st_z = pcg_hz_part<1>(S, label.data(), ngroups, Rv, dYz.data(), rtol, maxiter, 1, &it_z, wr2, wp2,
                                  wq2);
        }
        for (i64 i = 0; i < S.n; ++i) { dYv[3 * i + 1] = dYz[3 * i + 1]; dYv[3 * i + 2] = dYz[3 * i + 2]; }
        *its = std::max(it_h, it_z);
        return st_h != 0 ? st_h : st_z;
    }

    // frees the work vectors (between the pilot and the final smoothing, so that the
    // adaptive radius's temporaries do not add to them: the memory peak stays that of a solve)
    void release_work() {
        for (auto* v : {&Y, &R, &AY, &dY, &acc, &wr, &wp, &wq, &dYz, &wr2, &wp2, &wq2}) std::vector<double>().swap(*v);
    }
};

}  // namespace

// intrinsic_smoothing (intrinsic.vertex_smoothing): the pilot (one implicit step at
// pilot_radius, to pilot_rtol), the adaptive per-face radius (adaptive_radius, written
// to r (#F,)), then the twiced smoothing at it, on one system structure.  Returns the
// status of the first failed solve (1: pilot, else the final's; X unchanged) or 0.
int intrinsic_smoothing(const double* V, const i64* F, i64 nF, i64 nV, const i32* E, i64 nE, const i32* EF,
                        const i8* ELI, const double* C0, const double* m, const double* phase,
                        const double* rough, double radius, double per_radius, double pilot_radius,
                        double pilot_rtol, double gain, double power, double lo, double hi, int steps,
                        const std::vector<double>& binom, double rtol, i64 maxiter, double* X, double* r,
                        int nt, i64* iterations, i64* ngroups_out, int tasks) {
    HZProblem P(nV, E, nE, EF, ELI, C0, m, phase);
    P.tasks = tasks;
    *ngroups_out = P.ngroups;
    *iterations = 0;
    std::vector<double> t(nF), pilot(X, X + (size_t)nV * 3);
    face_times(V, F, nF, &pilot_radius, 0, per_radius, 1, t.data(), nt);
    P.fill(t.data(), nt);
    int status = P.run(pilot.data(), 1, {1.0}, pilot_rtol, maxiter, nt, iterations);
    if (status != 0) return status;
    P.release_work();
    adaptive_radius(V, F, nF, nV, pilot.data(), rough, radius, gain, power, lo, hi, r, nt);
    std::vector<double>().swap(pilot);
    face_times(V, F, nF, r, 1, per_radius, steps, t.data(), nt);
    P.fill(t.data(), nt);
    return P.run(X, steps, binom, rtol, maxiter, nt, iterations);
}

}  // namespace hhj

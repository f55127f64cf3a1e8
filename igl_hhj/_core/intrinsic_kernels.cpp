// The drop-in's intrinsic smoothing (igl_hhj/intrinsic.py is the readable numpy
// reference; tests/test_intrinsic.py compares them): twiced implicit diffusion of the
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

// out[2 g + part] = sum over rows of group g of u.v restricted to the part
void dots(i64 n, const double* u, const double* v, const std::int32_t* group, i64 ng,
          std::vector<double>& out, int nt) {
    std::fill(out.begin(), out.end(), 0.0);
    if (ng == 1) {
        const i64 nch = (n + CHUNK - 1) / CHUNK;
        std::vector<double> part((size_t)std::max<i64>(nch, 1) * 2, 0.0);
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
        for (i64 c = 0; c < nch; ++c) {
            double s0 = 0.0, s1 = 0.0;
            for (i64 r = c * CHUNK; r < std::min(n, (c + 1) * CHUNK); ++r) {
                s0 += u[3 * r] * v[3 * r];
                s1 += u[3 * r + 1] * v[3 * r + 1] + u[3 * r + 2] * v[3 * r + 2];
            }
            part[2 * c] = s0; part[2 * c + 1] = s1;
        }
        for (i64 c = 0; c < nch; ++c) { out[0] += part[2 * c]; out[1] += part[2 * c + 1]; }
        return;
    }
    for (i64 r = 0; r < n; ++r) {
        const i64 g = group[r];
        out[2 * g] += u[3 * r] * v[3 * r];
        out[2 * g + 1] += u[3 * r + 1] * v[3 * r + 1] + u[3 * r + 2] * v[3 * r + 2];
    }
}

// Solve A x = b (x0 = 0), Jacobi-preconditioned, CG scalars per (group, part).
// Returns 0 converged, 1 iteration cap, 3 breakdown (non-positive curvature).
int pcg_hz(const HZSystem& S, const std::int32_t* group, i64 ng, const double* b, double* x,
           double rtol, i64 maxiter, int nt, i64* its) {
    const i64 n = S.n;
    const size_t n3 = (size_t)n * 3;
    const size_t np = (size_t)ng * 2;
    std::vector<double> r(b, b + n3), z(n3), p(n3), q(n3);
    std::vector<double> bb(np), rr(np), rz(np), pq(np), alpha(np), beta(np);
    std::vector<unsigned char> done(np, 0);
    std::fill(x, x + n3, 0.0);
    auto gp = [&](i64 row, int part) { return 2 * (size_t)(ng == 1 ? 0 : group[row]) + part; };
    dots(n, b, b, group, ng, bb, nt);
    bool all = true;
    for (size_t k = 0; k < np; ++k) {
        done[k] = !(bb[k] > 0.0);
        all = all && done[k];
    }
    *its = 0;
    if (all) return 0;
    for (size_t s = 0; s < n3; ++s) z[s] = S.dinv[s / 3] * r[s];
    p = z;
    dots(n, r.data(), z.data(), group, ng, rz, nt);
    for (i64 it = 1; it <= maxiter; ++it) {
        apply(S, p.data(), q.data(), nt);
        dots(n, p.data(), q.data(), group, ng, pq, nt);
        for (size_t k = 0; k < np; ++k) {
            if (done[k]) { alpha[k] = 0.0; continue; }
            if (!(pq[k] > 0.0)) return 3;
            alpha[k] = rz[k] / pq[k];
        }
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
        for (i64 row = 0; row < n; ++row)
            for (int c = 0; c < 3; ++c) {
                const double a = alpha[gp(row, c > 0)];
                const size_t s = 3 * (size_t)row + c;
                x[s] += a * p[s];
                r[s] -= a * q[s];
            }
        dots(n, r.data(), r.data(), group, ng, rr, nt);
        all = true;
        for (size_t k = 0; k < np; ++k) {
            if (!done[k] && rr[k] <= rtol * rtol * bb[k]) done[k] = 1;
            all = all && done[k];
        }
        *its = it;
        if (all) return 0;
        for (size_t s = 0; s < n3; ++s) z[s] = S.dinv[s / 3] * r[s];
        std::vector<double> rz_new(np);
        dots(n, r.data(), z.data(), group, ng, rz_new, nt);
        for (size_t k = 0; k < np; ++k) {
            beta[k] = done[k] ? 0.0 : rz_new[k] / rz[k];
            if (!done[k]) rz[k] = rz_new[k];
        }
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
        for (i64 row = 0; row < n; ++row)
            for (int c = 0; c < 3; ++c) {
                const size_t k = gp(row, c > 0);
                if (done[k]) continue;
                const size_t s = 3 * (size_t)row + c;
                p[s] = z[s] + beta[k] * p[s];
            }
    }
    return 1;
}

}  // namespace

// Connected components of the vertex graph (union-find over E), labelled in the order
// of their smallest vertex; vertices without edges join label 0 (their rows stay 0 in
// every solve, so they add nothing to any reduction).  Returns the number of labels.
i64 vertex_groups(i64 nV, const i64* E, i64 nE, std::vector<std::int32_t>& label) {
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

// connection_smoothing: X (#V,3) <- (I - (I - G)^order) X in place, G = `steps` implicit
// steps (M + L_t) Y = M Y_prev solved for the correction (M + L_t) dY = -L_t Y_prev.
// C (#F,3) per-face stiffness entries (cotangent x reliability x time t_T), m (#V,) the
// floored lumped mass, phase (#E,2) (cos, sin) of r_e = e^{2 i rho_e} for edge (i < j).
// The CG scalars are per connected component of the vertex graph (vertex_groups).
// Returns 0, or the status of the first solve that did not converge (X is then
// unchanged); *ngroups_out the number of components.
int connection_smoothing(i64 nV, const i64* E, i64 nE, const i64* EF, const i64* ELI, const double* C,
                         const double* m, const double* phase, int steps, const std::vector<double>& binom,
                         double rtol, i64 maxiter, double* X, int nt, i64* iterations, i64* ngroups_out) {
    std::vector<std::int32_t> label;
    const i64 ngroups = vertex_groups(nV, E, nE, label);
    const std::int32_t* group = label.data();
    *ngroups_out = ngroups;
    HZSystem S;
    S.n = nV;
    std::vector<i64> diag_pos, pos_lo, pos_hi;
    vertex_laplacian(nV, E, nE, EF, ELI, C, S.indptr, S.indices, S.a, diag_pos, &pos_lo, &pos_hi);
    const size_t nnz = S.a.size();
    S.pc.assign(nnz, 1.0);
    S.ps.assign(nnz, 0.0);
    for (i64 e = 0; e < nE; ++e) {
        const double c = phase[2 * e], s = phase[2 * e + 1];
        S.pc[pos_lo[e]] = c; S.ps[pos_lo[e]] = s;      // row min(e): z of max(e) in the frame of min(e)
        S.pc[pos_hi[e]] = c; S.ps[pos_hi[e]] = -s;     // row max(e): the inverse transport
    }
    // A = M + L_t; -L_t Y = M Y - A Y
    S.dinv.resize(nV);
    for (i64 v = 0; v < nV; ++v) {
        S.a[diag_pos[v]] += m[v];
        S.dinv[v] = 1.0 / S.a[diag_pos[v]];
    }
    const size_t n3 = (size_t)nV * 3;
    std::vector<double> Y(X, X + n3), R(n3), AY(n3), dY(n3), acc(n3, 0.0);
    *iterations = 0;
    for (size_t j = 0; j < binom.size(); ++j) {
        for (int st = 0; st < steps; ++st) {
            apply(S, Y.data(), AY.data(), nt);
            for (size_t q = 0; q < n3; ++q) R[q] = m[q / 3] * Y[q] - AY[q];
            i64 its = 0;
            const int status = pcg_hz(S, group, ngroups, R.data(), dY.data(), rtol, maxiter, nt, &its);
            *iterations += its;
            if (status != 0) return status;
            for (size_t q = 0; q < n3; ++q) Y[q] += std::isfinite(dY[q]) ? dY[q] : 0.0;
        }
        for (size_t q = 0; q < n3; ++q) acc[q] += binom[j] * Y[q];
    }
    std::copy(acc.begin(), acc.end(), X);
    return 0;
}

}  // namespace hhj

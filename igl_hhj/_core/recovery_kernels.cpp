// Vertex recovery of the drop-in: the face reliability weights (recovery.recovery_weights),
// the intrinsic patch recovery (weighted linear least-squares fit in each vertex's tangent
// frame of the face tensors carried there by minimal rotations; numpy reference
// tests/vertex_stage/reference_intrinsic.py), the vertex Laplacian's CSR structure (used by
// intrinsic_kernels.cpp) and the boundary-normal fits (boundary_estimation.py).  Scatters
// over corners run serially in face order, so results do not depend on the thread count;
// tests/vertex_stage/test_vertex_stage_kernels.py compares them with the references.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core.hpp"

namespace hhj {

namespace {
inline void face_cross(const double* V, const i64* F, i64 f, double c[3]) {
    const double* x0 = V + 3 * F[3 * f];
    const double* x1 = V + 3 * F[3 * f + 1];
    const double* x2 = V + 3 * F[3 * f + 2];
    const double e1[3] = {x1[0] - x0[0], x1[1] - x0[1], x1[2] - x0[2]};
    const double e2[3] = {x2[0] - x0[0], x2[1] - x0[1], x2[2] - x0[2]};
    cross3(e1, e2, c);
}

}  // namespace

// recovery_weights: w[f] = |T| min(1, q~_T / floor), q_T = 4 sqrt(3) |T| / (l0^2 + l1^2 + l2^2)
// (recovery.face_quality, non-finite -> 0), q~_T = min of q over T and its edge
// neighbours (recovery.recovery_weights).  FE (#F,3), EF (#E,2); w (#F,).
void recovery_weights(const double* V, const i64* F, i64 nF, const i32* FE, const i32* EF, i64 nE,
                      double floor, double* w, int nt) {
    std::vector<double> q(nF), qe(nE);
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 f = 0; f < nF; ++f) {
        double l[3];
        const double area = face_lengths(V, F, f, l);
        const double l2 = l[0] * l[0] + l[1] * l[1] + l[2] * l[2];
        const double qf = 4.0 * std::sqrt(3.0) * area / l2;
        q[f] = std::isfinite(qf) ? qf : 0.0;
        w[f] = area;
    }
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 e = 0; e < nE; ++e) {
        const i64 f0 = EF[2 * e], f1 = EF[2 * e + 1];
        const double inf = std::numeric_limits<double>::infinity();
        qe[e] = std::min(f0 >= 0 ? q[f0] : inf, f1 >= 0 ? q[f1] : inf);
    }
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 f = 0; f < nF; ++f) {
        const double qt = std::min(qe[FE[3 * f]], std::min(qe[FE[3 * f + 1]], qe[FE[3 * f + 2]]));
        w[f] *= std::min(1.0, qt / floor);
    }
}

// The weighted least-squares linear patch fit of intrinsic_patch_recovery
// (recovery.recovery_operator("patch")): for every corner
// (f, c) of vertex v the coefficient k_{v,(f,c)} = W (g0 + g1 u + g2 v) / det of the fit
// of a + b u + c v to the corner values at the centroid offsets (u, v) / h in v's
// tangent frame, evaluated at the vertex; the lumped weight W / sum W where the linear
// part is ill-conditioned.  cw(f, c) the corner weight (vertices whose corners all
// weigh 0 get weight 1 on each), W = cw / (the largest corner weight).  Each vertex
// gathers its corners in face order (VertexCorners) and calls emit(f, c, v, k) for them
// in that order, then done(v): vertices run in parallel, emit and done may write v's
// own outputs only, and every sum has the order of a serial scatter over the faces (the
// same bits for any thread count).  N (#V,3) (non-finite entries count as 0), ref (#V,).
template <class CornerWeight, class Emit, class Done>
void patch_fit(const double* V, const i64* F, i64 nF, i64 nV, const double* N, const unsigned char* ref,
               double h, const VertexCorners& vc, CornerWeight cw, Emit emit, Done done, int nt) {
    // lost: referenced vertices whose corners all weigh 0 (plain average, weight 1 each);
    // s0: the sum of the corner weights (of the 1s where lost)
    std::vector<double> s0(nV, 0.0);
    std::vector<unsigned char> lost(nV, 0);
    double wmax = 0.0;
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt) reduction(max : wmax)
#endif
    for (i64 v = 0; v < nV; ++v) {
        double sum = 0.0, mx = 0.0;
        for (i64 q = vc.start[v]; q < vc.start[v + 1]; ++q) {
            const double W = cw(vc.corner[q] / 3, (int)(vc.corner[q] % 3));
            sum += W;
            mx = std::max(mx, W);
        }
        lost[v] = ref[v] && !(sum > 0);
        if (lost[v]) {       // its corners weigh 1 each
            sum = 0.0;
            for (i64 q = vc.start[v]; q < vc.start[v + 1]; ++q) sum += 1.0;
            mx = vc.start[v + 1] > vc.start[v] ? 1.0 : 0.0;
        }
        s0[v] = sum;
        wmax = std::max(wmax, mx);
    }
    wmax = std::max(wmax, std::numeric_limits<double>::min());
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel num_threads(nt)
#endif
    {
        std::vector<double> off;   // this vertex's corner offsets (u, t)
#ifdef IGL_HHJ_OPENMP
#pragma omp for schedule(static)
#endif
        for (i64 v = 0; v < nV; ++v) {
            const i64 q0 = vc.start[v], deg = vc.start[v + 1] - q0;
            double n[3], e1[3], e2[3];
            for (int a = 0; a < 3; ++a) n[a] = std::isfinite(N[3 * v + a]) ? N[3 * v + a] : 0.0;
            if (!ref[v]) { n[0] = 0.0; n[1] = 0.0; n[2] = 1.0; }
            tangent_frame(n, e1, e2);
            off.resize((size_t)deg * 2);
            // moments of the weighted fit: a, b, c, d, e, f = sum W (1, u, v, uu, uv, vv)
            double m[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
            for (i64 k = 0; k < deg; ++k) {
                const i64 f = vc.corner[q0 + k] / 3;
                const int c = (int)(vc.corner[q0 + k] % 3);
                const double* x0 = V + 3 * F[3 * f];
                const double* x1 = V + 3 * F[3 * f + 1];
                const double* x2 = V + 3 * F[3 * f + 2];
                double d[3];
                for (int a = 0; a < 3; ++a) d[a] = ((x0[a] + x1[a] + x2[a]) / 3.0 - V[3 * v + a]) / h;
                const double u = dot3(d, e1), t = dot3(d, e2);
                off[2 * k] = u; off[2 * k + 1] = t;
                const double W = (lost[v] ? 1.0 : cw(f, c)) / wmax;
                m[0] += W; m[1] += W * u; m[2] += W * t;
                m[3] += W * u * u; m[4] += W * u * t; m[5] += W * t * t;
            }
            // g / det of the fit (3 values) and whether it is well posed
            const double a = m[0], b = m[1], c = m[2], d = m[3], e = m[4], ff = m[5];
            const double g0 = d * ff - e * e, g1 = c * e - b * ff, g2 = b * e - c * d;
            const double det = a * g0 + b * g1 + c * g2;
            const double mu = b / a, mv = c / a;
            const double cuu = d / a - mu * mu, cuv = e / a - mu * mv, cvv = ff / a - mv * mv;
            const double tr = cuu + cvv;
            const bool good = ref[v] && !lost[v] && a > 0 && (cuu * cvv - cuv * cuv > 0.05 * tr * tr) &&
                              (tr > 0.05 * (d + ff) / a) && std::isfinite(det) && det != 0.0;
            const double G0 = g0 / det, G1 = g1 / det, G2 = g2 / det;
            for (i64 k = 0; k < deg; ++k) {
                const i64 f = vc.corner[q0 + k] / 3;
                const int cc = (int)(vc.corner[q0 + k] % 3);
                const double W = lost[v] ? 1.0 : cw(f, cc);
                double kv = good ? W / wmax * (G0 + G1 * off[2 * k] + G2 * off[2 * k + 1]) : W / s0[v];
                if (!std::isfinite(kv)) kv = 0.0;
                emit(f, cc, v, kv);
            }
            done(v);
        }
    }
}

// intrinsic_patch_recovery (reference_intrinsic.recover): the corner components (h, Re z, Im z) of
// R S_T R^T in the frame of v, R the minimal rotation nu_T -> N_v (corner weight w_T
// where nu_T . N_v > 0, else 0), fitted by patch_fit.  X (#V,3), rows of unreferenced 0.
// rough (#V,) or nullptr: reference_intrinsic.roughness, h_v sqrt(sum w |Y_T - X_v|^2 / sum w) over
// the corners of v (w the fit's corner weights), h_v the mean over them of the faces'
// mean edge lengths (0 where undefined).
void intrinsic_patch_recovery(const double* V, const i64* F, i64 nF, i64 nV, const double* S,
                              const double* N, const double* w, const unsigned char* ref, double h,
                              double* X, double* rough, int nt) {
    // vertex frames once (tangent_frame of N, +z where N is not finite), then the corner
    // components and cosines in one pass over faces (parallel: no scatter)
    std::vector<double> fr((size_t)nV * 9);
    normal_frames(N, nV, fr.data(), nt);
    std::vector<double> Y((size_t)nF * 9), cosine((size_t)nF * 3), hT(rough ? nF : 0);
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 f = 0; f < nF; ++f) {
        if (rough) {
            double l[3];
            face_lengths(V, F, f, l);
            hT[f] = (l[0] + l[1] + l[2]) / 3.0;
        }
        double c[3];
        face_cross(V, F, f, c);
        const double nc = std::sqrt(dot3(c, c));
        const double nu[3] = {c[0] / nc, c[1] / nc, c[2] / nc};
        const double* Sf = S + 9 * f;
        for (int k = 0; k < 3; ++k) {
            const double* n = &fr[9 * F[3 * f + k]];
            double f1[3], f2[3];
            const double cs = min_rotation(n + 3, n, nu, f1);
            min_rotation(n + 6, n, nu, f2);
            double Sf1[3], Sf2[3];
            for (int p = 0; p < 3; ++p) {
                Sf1[p] = Sf[3 * p] * f1[0] + Sf[3 * p + 1] * f1[1] + Sf[3 * p + 2] * f1[2];
                Sf2[p] = Sf[3 * p] * f2[0] + Sf[3 * p + 1] * f2[1] + Sf[3 * p + 2] * f2[2];
            }
            const double a = dot3(f1, Sf1), d = dot3(f2, Sf2), b = dot3(f1, Sf2);
            double* y = &Y[9 * f + 3 * k];
            y[0] = 0.5 * (a + d); y[1] = 0.5 * (a - d); y[2] = b;
            for (int q = 0; q < 3; ++q) if (!std::isfinite(y[q])) y[q] = 0.0;
            cosine[3 * f + k] = cs;
        }
    }
    std::vector<double>().swap(fr);
    std::fill(X, X + (size_t)nV * 3, 0.0);
    const VertexCorners vc(F, nF, nV);
    patch_fit(V, F, nF, nV, N, ref, h, vc, [&](i64 f, int c) { return cosine[3 * f + c] > 0 ? w[f] : 0.0; },
              [&](i64 f, int c, i64 v, double k) {
                  const double* y = &Y[9 * f + 3 * c];
                  for (int q = 0; q < 3; ++q) X[3 * v + q] += k * y[q];
              },
              [&](i64 v) {
                  if (!rough) return;
                  // sum |T| d^2, sum |T| (the fit's corner weights), sum h_T over v's corners
                  double a0 = 0.0, a1 = 0.0, a2 = 0.0;
                  const i64 q0 = vc.start[v], q1 = vc.start[v + 1];
                  for (i64 q = q0; q < q1; ++q) {
                      const i64 f = vc.corner[q] / 3;
                      const int k = (int)(vc.corner[q] % 3);
                      const double area = cosine[3 * f + k] > 0 ? w[f] : 0.0;
                      const double* y = &Y[9 * f + 3 * k];
                      double d2 = 0.0;
                      for (int c = 0; c < 3; ++c) d2 += (y[c] - X[3 * v + c]) * (y[c] - X[3 * v + c]);
                      a0 += area * d2;
                      a1 += area;
                      a2 += hT[f];
                  }
                  const i64 cnt = q1 - q0;
                  const double r = cnt && a1 > 0 ? a2 / cnt * std::sqrt(a0 / a1) : 0.0;
                  rough[v] = std::isfinite(r) ? r : 0.0;
              },
              nt);
}

// vertex_laplacian: CSR structure of the vertex graph from the unique edges E (#E,2,
// lexicographic (min, max) pairs) plus the diagonal: row v = [lower neighbours,
// v, upper neighbours], ascending.  L values: -w_e off the diagonal, sum of the w_e
// on it, w_e = sum over the edge's faces of C[f, i] (C (#F,3): the face's cotangent
// stiffness entry of the edge opposite corner i, recovery.smoothing_matrices).
void vertex_laplacian(i64 nV, const i32* E, i64 nE, const i32* EF, const i8* ELI, const double* C,
                      std::vector<i64>& indptr, std::vector<std::int32_t>& indices,
                      std::vector<double>& L, std::vector<i64>& diag_pos,
                      std::vector<i64>* pos_lo_out, std::vector<i64>* pos_hi_out) {
    indptr.assign(nV + 1, 0);
    for (i64 e = 0; e < nE; ++e) { ++indptr[E[2 * e] + 1]; ++indptr[E[2 * e + 1] + 1]; }
    for (i64 v = 0; v < nV; ++v) indptr[v + 1] += indptr[v] + 1;   // + 1: the diagonal
    const i64 nnz = indptr[nV];
    indices.assign(nnz, 0);
    L.assign(nnz, 0.0);
    diag_pos.assign(nV, 0);
    std::vector<i64> fill(indptr.begin(), indptr.end() - 1), pos_hi(nE), pos_lo(nE);
    // row max(e): the lower neighbour min(e); edges are sorted by min, so ascending
    for (i64 e = 0; e < nE; ++e) { pos_hi[e] = fill[E[2 * e + 1]]; indices[fill[E[2 * e + 1]]++] = (std::int32_t)E[2 * e]; }
    for (i64 v = 0; v < nV; ++v) { diag_pos[v] = fill[v]; indices[fill[v]++] = (std::int32_t)v; }
    // row min(e): the upper neighbour max(e); contiguous and ascending in the edge order
    for (i64 e = 0; e < nE; ++e) { pos_lo[e] = fill[E[2 * e]]; indices[fill[E[2 * e]]++] = (std::int32_t)E[2 * e + 1]; }
    for (i64 e = 0; e < nE; ++e) {
        double we = 0.0;
        for (int s = 0; s < 2; ++s) {
            const i64 f = EF[2 * e + s];
            if (f >= 0) we += C[3 * f + ELI[2 * e + s]];
        }
        L[pos_lo[e]] = -we;
        L[pos_hi[e]] = -we;
        L[diag_pos[E[2 * e]]] += we;
        L[diag_pos[E[2 * e + 1]]] += we;
    }
    if (pos_lo_out) *pos_lo_out = std::move(pos_lo);
    if (pos_hi_out) *pos_hi_out = std::move(pos_hi);
}


// ---------------------------------------------------------------------------------------
// boundary_normal_fits (boundary_estimation.estimate_boundary_normals, its numpy reference):
// for each vertex v of verts the vertices of its `rings`-ring in the graph of the unique
// edges E (rings + 1 where that ring has fewer than 10), and two weighted quadric height
// fits z = g1 x + g2 y + (a x^2 + 2 b xy + c y^2)/2 through x_v, the first in the frame of
// N0, the second in the frame of the first's normal.  N (n,3) gets the second normal
// where both fits are well posed (>= 6 neighbours, finite, Gram condition < 1e10), else N0.
// Coordinates are scaled by the mean length of v's edges (conditioning only).
namespace {

// eigenvalues of a symmetric 5x5 matrix (cyclic Jacobi), ascending
void sym5_eigenvalues(const double (&A)[5][5], double (&lam)[5]) {
    double a[5][5];
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 5; ++j) a[i][j] = A[i][j];
    // quadratic convergence: a handful of sweeps reach off-diagonal entries at the
    // round-off of the diagonal (an entry below 1e-18 sqrt|a_pp a_qq| is dropped)
    for (int sweep = 0; sweep < 30; ++sweep) {
        double off = 0.0, tot = 0.0;
        for (int i = 0; i < 5; ++i)
            for (int j = 0; j < 5; ++j) { tot += a[i][j] * a[i][j]; if (i != j) off += a[i][j] * a[i][j]; }
        if (!(off > 1e-28 * tot)) break;
        for (int p = 0; p < 4; ++p)
            for (int q = p + 1; q < 5; ++q) {
                if (std::fabs(a[p][q]) <= 1e-18 * std::sqrt(std::fabs(a[p][p] * a[q][q]))) { a[p][q] = a[q][p] = 0.0; continue; }
                const double th = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                const double t = (th >= 0 ? 1.0 : -1.0) / (std::fabs(th) + std::sqrt(th * th + 1.0));
                const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 5; ++k) {
                    const double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 5; ++k) {
                    const double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
            }
    }
    for (int i = 0; i < 5; ++i) lam[i] = a[i][i];
    std::sort(lam, lam + 5);
}

// An upper bound of the 2-norm condition number of a symmetric positive definite 5x5
// matrix, trace(G) trace(G^-1) (>= lam_max / lam_min, at most 25 times it), from its
// Cholesky factor; infinity when the factorisation fails.
double sym5_condition_bound(const double (&G)[5][5]) {
    double L[5][5] = {};
    double tr = 0.0;
    for (int j = 0; j < 5; ++j) {
        tr += G[j][j];
        double d = G[j][j];
        for (int k = 0; k < j; ++k) d -= L[j][k] * L[j][k];
        if (!(d > 0.0)) return INFINITY;
        L[j][j] = std::sqrt(d);
        for (int i = j + 1; i < 5; ++i) {
            double v = G[i][j];
            for (int k = 0; k < j; ++k) v -= L[i][k] * L[j][k];
            L[i][j] = v / L[j][j];
        }
    }
    // trace(G^-1) = |L^-1|_F^2, L^-1 column by column (forward substitution on e_c)
    double tinv = 0.0;
    for (int c = 0; c < 5; ++c) {
        double y[5] = {};
        for (int i = c; i < 5; ++i) {
            double v = i == c ? 1.0 : 0.0;
            for (int k = c; k < i; ++k) v -= L[i][k] * y[k];
            y[i] = v / L[i][i];
            tinv += y[i] * y[i];
        }
    }
    return tr * tinv;
}

// x = G^-1 r, Gaussian elimination with partial pivoting (G, r overwritten)
void solve5(double (&G)[5][5], double (&r)[5], double (&x)[5]) {
    for (int k = 0; k < 5; ++k) {
        int piv = k;
        for (int i = k + 1; i < 5; ++i)
            if (std::fabs(G[i][k]) > std::fabs(G[piv][k])) piv = i;
        if (piv != k) {
            for (int j = 0; j < 5; ++j) std::swap(G[k][j], G[piv][j]);
            std::swap(r[k], r[piv]);
        }
        for (int i = k + 1; i < 5; ++i) {
            const double f = G[i][k] / G[k][k];
            for (int j = k; j < 5; ++j) G[i][j] -= f * G[k][j];
            r[i] -= f * r[k];
        }
    }
    for (int k = 4; k >= 0; --k) {
        double s = r[k];
        for (int j = k + 1; j < 5; ++j) s -= G[k][j] * x[j];
        x[k] = s / G[k][k];
    }
}

// one fit at a vertex: (N out, ok)
bool quadric_fit(const double* X, const double* xv, const i64* nb, i64 cnt, const double* n0, double scale,
                 double* nout) {
    double e1[3], e2[3];
    tangent_frame(n0, e1, e2);      // boundary_estimation._frames (NaN normals: NaN frames)
    double G[5][5] = {}, r[5] = {};
    for (i64 q = 0; q < cnt; ++q) {
        const double* xc = X + 3 * nb[q];
        double d[3];
        for (int a = 0; a < 3; ++a) d[a] = (xc[a] - xv[a]) / scale;
        const double x = dot3(d, e1), y = dot3(d, e2), z = dot3(d, n0);
        const double w = 1.0 / (1.0 + x * x + y * y);
        const double phi[5] = {x, y, 0.5 * x * x, x * y, 0.5 * y * y};
        for (int a = 0; a < 5; ++a) {
            r[a] += w * phi[a] * z;
            for (int b = a; b < 5; ++b) G[a][b] += w * phi[a] * phi[b];
        }
    }
    bool finite = true;
    for (int a = 0; a < 5; ++a) {
        finite = finite && std::isfinite(r[a]);
        for (int b = a; b < 5; ++b) { G[b][a] = G[a][b]; finite = finite && std::isfinite(G[a][b]); }
    }
    bool ok = cnt >= 6 && finite;
    // the reference's test, cond = lam_max / lam_min < 1e10; the eigenvalues only where
    // the cheap bound does not already decide it
    if (ok && !(sym5_condition_bound(G) < 1e10)) {
        double lam[5];
        sym5_eigenvalues(G, lam);
        const double cond = lam[0] > 0 ? lam[4] / lam[0] : INFINITY;
        ok = std::isfinite(cond) && cond < 1e10;
    }
    double g[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
    if (ok) solve5(G, r, g);
    double len2 = 0.0;
    for (int a = 0; a < 3; ++a) { nout[a] = n0[a] - g[0] * e1[a] - g[1] * e2[a]; len2 += nout[a] * nout[a]; }
    const double len = std::sqrt(len2);
    for (int a = 0; a < 3; ++a) nout[a] /= len;
    return ok;
}

}  // namespace

void boundary_normal_fits(const double* X, i64 nV, const i32* E, i64 nE, const i64* verts, i64 n, int rings,
                          const double* N0, double* N, int nt) {
    std::vector<i64> ptr(nV + 1, 0), adj(2 * nE);
    for (i64 e = 0; e < nE; ++e) { ++ptr[E[2 * e] + 1]; ++ptr[E[2 * e + 1] + 1]; }
    for (i64 v = 0; v < nV; ++v) ptr[v + 1] += ptr[v];
    {
        std::vector<i64> fill(ptr.begin(), ptr.end() - 1);
        for (i64 e = 0; e < nE; ++e) {
            adj[fill[E[2 * e]]++] = E[2 * e + 1];
            adj[fill[E[2 * e + 1]]++] = E[2 * e];
        }
    }
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel num_threads(nt)
#endif
    {
        std::vector<i64> stamp(nV, -1), ring;
        std::vector<int> depth;
#ifdef IGL_HHJ_OPENMP
#pragma omp for schedule(dynamic, 64)
#endif
        for (i64 k = 0; k < n; ++k) {
            const i64 v = verts[k];
            // breadth-first rings around v (v excluded from the fit's neighbours)
            auto grow = [&](int depth_max) {
                ring.clear(); depth.clear();
                ring.push_back(v); depth.push_back(0);
                stamp[v] = k;
                for (size_t h = 0; h < ring.size(); ++h) {
                    if (depth[h] == depth_max) continue;
                    const i64 u = ring[h];
                    for (i64 q = ptr[u]; q < ptr[u + 1]; ++q) {
                        const i64 w = adj[q];
                        if (stamp[w] == k) continue;
                        stamp[w] = k;
                        ring.push_back(w); depth.push_back(depth[h] + 1);
                    }
                }
            };
            grow(rings);
            if ((i64)ring.size() - 1 < 10) {
                for (i64 u : ring) stamp[u] = -1;
                grow(rings + 1);
            }
            for (i64 u : ring) stamp[u] = -1;
            // spacing of the fit (conditioning only): the mean length of v's edges
            double scale = 0.0;
            for (i64 q = ptr[v]; q < ptr[v + 1]; ++q) {
                const double* xu = X + 3 * adj[q];
                scale += std::sqrt((xu[0] - X[3 * v]) * (xu[0] - X[3 * v]) + (xu[1] - X[3 * v + 1]) * (xu[1] - X[3 * v + 1]) +
                                   (xu[2] - X[3 * v + 2]) * (xu[2] - X[3 * v + 2]));
            }
            scale /= (double)std::max<i64>(ptr[v + 1] - ptr[v], 1);
            const i64* nb = ring.data() + 1;
            const i64 cnt = (i64)ring.size() - 1;
            double n1[3], n2[3];
            const bool ok1 = quadric_fit(X, X + 3 * v, nb, cnt, N0 + 3 * k, scale, n1);
            const double* start = ok1 ? n1 : N0 + 3 * k;
            const bool ok2 = quadric_fit(X, X + 3 * v, nb, cnt, start, scale, n2);
            for (int a = 0; a < 3; ++a) N[3 * k + a] = (ok1 && ok2) ? n2[a] : N0[3 * k + a];
        }
    }
}

}  // namespace hhj

// The drop-in on a small mesh in one call: stage 2 of igl_hhj/pipeline.py (the fixed cost
// per call).
//
// igl_hhj.principal_curvature runs ~40 Python steps (validation, topology, the HHJ
// system, its direct solve, S_h, the vertex stage, the eigen-problem), each a few
// microseconds: 0.3 ms on a 12-face cube against libigl's 0.05 ms.  On a small mesh
// this kernel runs the same compiled kernels in the same order with the same inputs, so
// it returns the general path's values (tests/vertex_stage/test_small_mesh.py compares
// them); anything else -- boundary="plain" on an open mesh, a defect the general path
// would refuse or repair, more edges than the envelope solver takes, a solve that fails
// -- returns a nonzero status and the caller takes the general path.  The sections below
// are the pipeline's stages 3 and 5-8 (igl_hhj/pipeline.py names them).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core.hpp"

namespace hhj {

namespace {

// numpy's pairwise summation (add.reduce on a contiguous float64 array), so that the
// mean edge length is the general path's float64 value, bit for bit.
double pairwise_sum(const double* a, i64 n) {
    if (n < 8) {
        double res = 0.0;
        for (i64 i = 0; i < n; ++i) res += a[i];
        return res;
    }
    if (n <= 128) {
        double r[8];
        for (int j = 0; j < 8; ++j) r[j] = a[j];
        i64 i = 8;
        for (; i < n - (n % 8); i += 8)
            for (int j = 0; j < 8; ++j) r[j] += a[i + j];
        double res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
        for (; i < n; ++i) res += a[i];
        return res;
    }
    i64 n2 = n / 2;
    n2 -= n2 % 8;
    return pairwise_sum(a, n2) + pairwise_sum(a + n2, n - n2);
}

// Whether two of the rows `rows` of V (#V, 3) hold the same coordinates (mesh._warn_unwelded).
bool coincident_rows(const double* V, const std::vector<i64>& rows) {
    std::vector<i64> o(rows);
    auto less = [&](i64 a, i64 b) {
        for (int k = 0; k < 3; ++k)
            if (V[3 * a + k] != V[3 * b + k]) return V[3 * a + k] < V[3 * b + k];
        return false;
    };
    std::sort(o.begin(), o.end(), less);
    for (size_t q = 1; q < o.size(); ++q)
        if (!less(o[q - 1], o[q])) return true;
    return false;
}

}  // namespace

int dropin_small(const double* V, i64 nV, const i64* F, i64 nF, const double* N0, const double* cot,
                 const SmallParams& p, double* PD1, double* PD2, double* PV1, double* PV2,
                 unsigned char* bad) {
    // ---- stage 3, mesh: the checks of TriangleMesh that the general path would fail or repair on
    for (i64 f = 0; f < nF; ++f) {
        const i64 a = F[3 * f], b = F[3 * f + 1], c = F[3 * f + 2];
        if (a == b || b == c || c == a) return SMALL_DEFECT;
    }
    std::vector<double> cross((size_t)nF * 3), dbl(nF), l2max(nF);
    face_metrics(V, F, nF, cross.data(), dbl.data(), l2max.data(), 1);
    double l2 = 0.0;
    for (i64 f = 0; f < nF; ++f) {
        const bool ok = dbl[f] > p.degenerate_rtol * l2max[f] && std::isfinite(dbl[f]) && std::isfinite(l2max[f]);
        if (!ok) return SMALL_DEFECT;
        if (l2max[f] > l2) l2 = l2max[f];
    }
    if (!(std::sqrt(l2) >= p.min_mesh_size)) return SMALL_DEFECT;
    Topology T;
    topology(F, nF, nV, T);
    const i64 nE = T.n_edges;
    if (nE > p.max_edges) return SMALL_TOO_LARGE;
    std::vector<int> positive(nE, 0);
    for (i64 q = 0; q < 3 * nF; ++q)
        if (T.sign[q] > 0) ++positive[T.face_edges[q]];
    std::vector<i64> bnd_edges;                                      // ascending
    for (i64 e = 0; e < nE; ++e) {
        if (T.count[e] == 1) { bnd_edges.push_back(e); continue; }
        if (T.count[e] != 2 || positive[e] != 1) return SMALL_DEFECT;  // non-manifold, orientation
    }
    const i64 nb = (i64)bnd_edges.size();
    if (nb > 0 && !p.estimate) return SMALL_OPEN;                    // boundary="plain": general path
    std::vector<unsigned char> on_boundary(nV, 0);
    for (i64 e : bnd_edges) on_boundary[T.edges[2 * e]] = on_boundary[T.edges[2 * e + 1]] = 1;
    std::vector<i64> bverts;                                          // ascending
    for (i64 v = 0; v < nV; ++v)
        if (on_boundary[v]) bverts.push_back(v);
    if (coincident_rows(V, bverts)) return SMALL_DEFECT;              // unwelded: the general path warns
    // ---- stage 3, mesh: referenced and folded vertices (TriangleMesh.folded_vertices), the normals
    std::vector<unsigned char> ref(nV, 0);
    for (i64 q = 0; q < 3 * nF; ++q) ref[F[q]] = 1;
    std::vector<double> s((size_t)nV * 3), asum(nV), N(N0, N0 + 3 * nV);
    vertex_area_sums(F, nF, nV, cross.data(), dbl.data(), s.data(), asum.data());
    std::vector<unsigned char> folded(nV, 0);
    for (i64 v = 0; v < nV; ++v) {
        const double* sv = &s[3 * v];
        folded[v] = ref[v] && std::sqrt(dot3(sv, sv)) <= p.folded_rtol * asum[v];
        if (!ref[v] || folded[v])
            for (int a = 0; a < 3; ++a) N[3 * v + a] = NAN;
    }
    // ---- stage 5, boundary treatment: boundary="estimate" (boundary_estimation.estimate_boundary_normals;
    // boundary.boundary_partition, normalised_boundary_normals, boundary_rhs, clamped_load)
    std::vector<double> Nb;                     // (nV, 3) clamped normals, NaN: plain edge
    std::vector<unsigned char> clamped(nE, 0);
    std::vector<i64> bface(nb), bloc(nb);       // the boundary edges' face and local index
    for (i64 q = 0; q < nb; ++q) {
        const i64 e = bnd_edges[q];
        const bool first = T.edge_faces[2 * e] >= 0;
        bface[q] = first ? T.edge_faces[2 * e] : T.edge_faces[2 * e + 1];
        bloc[q] = first ? T.local_index[2 * e] : T.local_index[2 * e + 1];
    }
    if (nb > 0) {
        const i64 n = (i64)bverts.size();
        std::vector<double> Nstart((size_t)n * 3), Nfit((size_t)n * 3);
        for (i64 q = 0; q < n; ++q)
            for (int a = 0; a < 3; ++a) Nstart[3 * q + a] = N[3 * bverts[q] + a];
        boundary_normal_fits(V, nV, T.edges.data(), nE, bverts.data(), n, p.fit_rings, Nstart.data(), Nfit.data(),
                             1);
        std::vector<double> fn((size_t)nb * 3), full((size_t)nV * 3, 0.0);
        for (i64 q = 0; q < nb; ++q)
            for (int a = 0; a < 3; ++a) fn[3 * q + a] = cross[3 * bface[q] + a] / dbl[bface[q]];
        for (int col = 0; col < 2; ++col)
            for (i64 q = 0; q < nb; ++q)
                for (int a = 0; a < 3; ++a) full[3 * (i64)T.edges[2 * bnd_edges[q] + col] + a] += fn[3 * q + a];
        Nb.assign((size_t)nV * 3, NAN);
        for (i64 q = 0; q < n; ++q)
            for (int a = 0; a < 3; ++a) Nb[3 * bverts[q] + a] = Nfit[3 * q + a];
        // flag[v]: the normal of end `col` of one of v's boundary edges fails N·ν_T > SIDE_DOT_MIN
        std::vector<unsigned char> flag(nV);
        auto looking_away = [&](int col) {
            std::fill(flag.begin(), flag.end(), 0);
            for (i64 q = 0; q < nb; ++q) {
                const i64 v = T.edges[2 * bnd_edges[q] + col];
                if (!(dot3(&Nb[3 * v], &fn[3 * q]) > p.side_dot_min)) flag[v] = 1;
            }
        };
        for (int col = 0; col < 2; ++col) {     // the faces' mean normal where the fit looks away
            looking_away(col);
            for (i64 v = 0; v < nV; ++v)
                if (flag[v]) {
                    const double* f = &full[3 * v];
                    const double nf = std::sqrt(dot3(f, f));
                    for (int a = 0; a < 3; ++a) Nb[3 * v + a] = f[a] / nf;
                }
        }
        for (int col = 0; col < 2; ++col) {     // no normal where even that looks away
            looking_away(col);
            for (i64 v = 0; v < nV; ++v)
                if (flag[v])
                    for (int a = 0; a < 3; ++a) Nb[3 * v + a] = NAN;
        }
        auto usable = [&](i64 v) {
            return std::isfinite(Nb[3 * v]) && std::isfinite(Nb[3 * v + 1]) && std::isfinite(Nb[3 * v + 2]);
        };
        std::fill(flag.begin(), flag.end(), 0);
        for (i64 e : bnd_edges)
            if (usable(T.edges[2 * e]) && usable(T.edges[2 * e + 1])) {
                clamped[e] = 1;
                flag[T.edges[2 * e]] = flag[T.edges[2 * e + 1]] = 1;
            }
        for (i64 v = 0; v < nV; ++v)            // normalised on the clamped edges' vertices
            if (flag[v]) {
                double* x = &Nb[3 * v];
                const double nn = std::sqrt(dot3(x, x));
                if (nn < 1e-12) return SMALL_DEFECT;
                for (int a = 0; a < 3; ++a) x[a] /= nn;
            }
    }
    // ---- stage 6, S_h: HHJ system in the Morton numbering and its direct solve (HHJSystem, "direct")
    std::vector<i64> perm(nE), iperm(nE);
    edge_morton_order(V, nV, T.edges.data(), nE, perm.data());
    for (i64 i = 0; i < nE; ++i) iperm[perm[i]] = i;
    std::vector<i32> FEp((size_t)nF * 3), EFp((size_t)nE * 2);
    std::vector<i8> ELIp((size_t)nE * 2);
    for (i64 q = 0; q < 3 * nF; ++q) FEp[q] = (i32)iperm[T.face_edges[q]];
    for (i64 i = 0; i < nE; ++i)
        for (int c = 0; c < 2; ++c) {
            EFp[2 * i + c] = T.edge_faces[2 * perm[i] + c];
            ELIp[2 * i + c] = T.local_index[2 * perm[i] + c];
        }
    std::vector<double> Aloc((size_t)nF * 9), sin_min(nF), A((size_t)nE * 5);
    std::vector<std::int32_t> cols((size_t)nE * 5);
    local_mass(V, F, nF, Aloc.data(), sin_min.data());
    assemble_ell(Aloc.data(), FEp.data(), EFp.data(), ELIp.data(), nE, cols.data(), A.data(), 1);
    std::vector<double> load((size_t)nE * 3), R((size_t)nE * 3), X((size_t)nE * 3);
    jump_apply(V, F, nF, T.edge_faces.data(), T.local_index.data(), nE, V, 3, load.data(), 1);   // B X
    for (i64 q = 0; q < 3 * nE; ++q) load[q] = -load[q];                                      // -B X
    std::vector<double> len(nE);
    for (i64 e = 0; e < nE; ++e) {
        const double* a = V + 3 * (i64)T.edges[2 * e];
        const double* b = V + 3 * (i64)T.edges[2 * e + 1];
        const double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        len[e] = std::sqrt(dot3(d, d));          // (d0² + d1²) + d2², as mesh.unique_edge_lengths
    }
    for (i64 q = 0; q < nb; ++q) {
        const i64 e = bnd_edges[q];
        double* row = &load[3 * e];
        if (!clamped[e]) { row[0] = row[1] = row[2] = 0.0; continue; }   // plain assembly
        // g_e^k = l_e n·ξ^k, ξ^k the mean over the edge of row k of P = I - ν~ ⊗ ν~
        const i64 f = bface[q];
        const int i = (int)bloc[q];
        const double* x1 = V + 3 * F[3 * f + (i + 1) % 3];
        const double* x2 = V + 3 * F[3 * f + (i + 2) % 3];
        double t[3] = {x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2]};
        const double tl = std::sqrt(dot3(t, t));
        for (int a = 0; a < 3; ++a) t[a] /= tl;
        double nu[3], cn[3];
        for (int a = 0; a < 3; ++a) nu[a] = cross[3 * f + a] / dbl[f];
        cross3(t, nu, cn);
        double xi[3][3];
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 3; ++a) {
                double pe[2];
                for (int c = 0; c < 2; ++c) {
                    const double* nv = &Nb[3 * (i64)T.edges[2 * e + c]];
                    const double v = (k == a ? 1.0 : 0.0) - nv[k] * nv[a];
                    pe[c] = std::isfinite(v) ? v : 0.0;
                }
                xi[k][a] = 0.5 * (pe[0] + pe[1]);
            }
        for (int k = 0; k < 3; ++k) row[k] += len[e] * dot3(cn, xi[k]);   // (n0 ξ0 + n1 ξ1) + n2 ξ2
    }
    for (i64 i = 0; i < nE; ++i)
        for (int k = 0; k < 3; ++k) R[3 * i + k] = load[3 * perm[i] + k];
    std::vector<i64> indptr(nE + 1);
    for (i64 i = 0; i <= nE; ++i) indptr[i] = 5 * i;
    if (envelope_ldl_solve(nE, 3, indptr.data(), cols.data(), A.data(), R.data(), X.data(), p.direct_rtol) != 0)
        return SMALL_SOLVE;
    std::vector<double> sigma((size_t)nE * 3);
    for (i64 i = 0; i < nE; ++i)
        for (int k = 0; k < 3; ++k) {
            if (!std::isfinite(X[3 * i + k])) return SMALL_SOLVE;
            sigma[3 * perm[i] + k] = X[3 * i + k];
        }
    std::vector<double> S((size_t)nF * 9);
    shape_operator_faces(V, F, T.face_edges.data(), nF, sigma.data(), S.data(), 1);   // S_h
    // ---- stage 7, vertex stage (intrinsic.vertex_recovery, then intrinsic.vertex_smoothing)
    std::vector<double> w(nF);
    recovery_weights(V, F, nF, T.face_edges.data(), T.edge_faces.data(), nE, p.quality_floor, w.data(), 1);
    const double h = pairwise_sum(len.data(), nE) / (double)nE;
    std::vector<double> Xv((size_t)nV * 3), rough(nV);
    intrinsic_patch_recovery(V, F, nF, nV, S.data(), N.data(), w.data(), ref.data(), h, Xv.data(), rough.data(), 1);
    if (p.radius > 0) {
        // recovery.smoothing_coefficients: b_T² = BOUNDARY_LENGTH_FACTOR² on faces touching
        // the boundary band (recovery.boundary_band: BOUNDARY_BAND_RINGS dilations)
        std::vector<unsigned char> band(on_boundary), grown;
        if (nb > 0)
            for (int ring = 0; ring < p.band_rings; ++ring) {
                grown = band;
                for (i64 e = 0; e < nE; ++e) {
                    if (band[T.edges[2 * e + 1]]) grown[T.edges[2 * e]] = 1;
                    if (band[T.edges[2 * e]]) grown[T.edges[2 * e + 1]] = 1;
                }
                band.swap(grown);
            }
        std::vector<double> C((size_t)nF * 3), m(nV, 0.0);
        for (i64 f = 0; f < nF; ++f) {
            const double area = 0.5 * dbl[f];
            const double fac = area > 0 ? w[f] / area : 0.0;
            const bool near = band[F[3 * f]] || band[F[3 * f + 1]] || band[F[3 * f + 2]];
            const double stiff = fac * (near ? p.band_factor * p.band_factor : 1.0);   // fac · 1 = fac
            const double share = w[f] * fac / 3.0;
            for (int c = 0; c < 3; ++c) {
                const double x = cot[3 * f + c] * stiff;
                C[3 * f + c] = std::isfinite(x) ? x : 0.0;
                m[F[3 * f + c]] += share;
            }
        }
        double mmax = m[0];
        for (i64 v = 1; v < nV; ++v) mmax = m[v] > mmax ? m[v] : mmax;
        const double floor = 1e-12 * (mmax > 1e-300 ? mmax : 1e-300);
        for (i64 v = 0; v < nV; ++v) m[v] = m[v] > floor ? m[v] : floor;
        std::vector<double> phase((size_t)nE * 2), r(nF);
        transport_phases(N.data(), nV, T.edges.data(), nE, phase.data(), 1);
        i64 iterations = 0, ngroups = 0;
        const int status = intrinsic_smoothing(V, F, nF, nV, T.edges.data(), nE, T.edge_faces.data(),
                                               T.local_index.data(), C.data(), m.data(), phase.data(), rough.data(),
                                               p.radius, p.per_radius, p.pilot_radius, p.smoothing_rtol, p.gain,
                                               p.power, p.lo, p.hi, p.steps, p.binom, p.smoothing_rtol, p.maxiter,
                                               Xv.data(), r.data(), 1, &iterations, &ngroups);
        if (status != 0) return SMALL_SOLVE;
    }
    // ---- stage 8, principal values (kernels.principal_hz)
    principal_hz(Xv.data(), N.data(), nV, PD1, PD2, PV1, PV2, 1);
    // ---- stage 8, NaN rows (pipeline._nan_rows, mesh.mark_bad_vertices)
    for (i64 v = 0; v < nV; ++v) {
        bool b = !ref[v] || folded[v];
        for (int a = 0; a < 3; ++a) b = b || !std::isfinite(PD1[3 * v + a]) || !std::isfinite(PD2[3 * v + a]);
        b = b || !std::isfinite(PV1[v]) || !std::isfinite(PV2[v]);
        bad[v] = b;
        if (b) {
            for (int a = 0; a < 3; ++a) PD1[3 * v + a] = PD2[3 * v + a] = NAN;
            PV1[v] = PV2[v] = NAN;
        }
    }
    return SMALL_OK;
}

}  // namespace hhj

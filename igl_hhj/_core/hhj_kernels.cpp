// The lowest-order surface HHJ layer (Walker 2023, §3–§5; design note
// hhj_lowest_order.md): local mass blocks, assembly of A, the face-Schwarz
// preconditioner, the jump operator B, S_h per face and the closed-form 2x2
// eigen-problem.  Loops over faces or edges
// write disjoint outputs (no atomics): results are independent of threads.
#include <algorithm>

#include "core.hpp"

namespace hhj {

namespace {
// phi_j = sym(t_a (x) t_b) / ((n_j.t_a)(n_j.t_b)),  {a, b} = the other two edges
inline double basis_denominator(const FaceGeom& g, int j) {
    const int a = (j + 1) % 3, b = (j + 2) % 3;
    return dot3(g.n[j], g.t[a]) * dot3(g.n[j], g.t[b]);
}
inline void basis_tensor(const FaceGeom& g, int j, double phi[3][3]) {
    const int a = (j + 1) % 3, b = (j + 2) % 3;
    const double s = 0.5 / basis_denominator(g, j);
    for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q) phi[p][q] = s * (g.t[a][p] * g.t[b][q] + g.t[b][p] * g.t[a][q]);
}
}  // namespace

// local_mass: Aloc[f] (3x3) = |T| phi_i : phi_j (eq. 5.14), closed form:
// sym(a(x)b):sym(c(x)d) = ((a.c)(b.d) + (a.d)(b.c)) / 2 with the Gram matrix of the t_i.
// Also sin_min[f] = sine of the smallest angle, 2|T| l_min / (l_0 l_1 l_2) (may be nullptr).
void local_mass(const double* V, const i64* F, i64 nF, double* Aloc, double* sin_min) {
    ThreadBudget tb(nF);
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(tb.nt)
#endif
    for (i64 f = 0; f < nF; ++f) {
        FaceGeom g;
        face_geom(V, F, f, g);
        double G[3][3], den[3];
        for (int p = 0; p < 3; ++p)
            for (int q = 0; q < 3; ++q) G[p][q] = dot3(g.t[p], g.t[q]);
        for (int j = 0; j < 3; ++j) den[j] = basis_denominator(g, j);
        const double area = 0.5 * g.dbl;
        if (sin_min)
            sin_min[f] = g.dbl * std::min(g.l[0], std::min(g.l[1], g.l[2])) / (g.l[0] * g.l[1] * g.l[2]);
        double* A = Aloc + 9 * f;
        for (int i = 0; i < 3; ++i) {
            const int ai = (i + 1) % 3, bi = (i + 2) % 3;
            for (int j = 0; j < 3; ++j) {
                const int aj = (j + 1) % 3, bj = (j + 2) % 3;
                const double ff = 0.5 * (G[ai][aj] * G[bi][bj] + G[ai][bj] * G[bi][aj]);
                A[3 * i + j] = area * ff / (den[i] * den[j]);
            }
        }
    }
}

// assemble_ell: sum of face blocks blk[f] (#F,3,3) into a fixed-width row format
// (#E, 5): slot 0 = diagonal (sum over the edge's faces), slots 1-2 / 3-4 = the
// couplings to the other two edges of the face on side 0 / side 1 (col = e,
// value 0 when the side is missing).  The same layout serves A and the Schwarz M
// (cols may be nullptr when the columns are already known).  Columns are int32.
void assemble_ell(const double* blk, const i32* FE, const i32* EF, const i8* ELI, i64 nE,
                  std::int32_t* cols, double* vals, int nt) {
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 e = 0; e < nE; ++e) {
        double d = 0.0;
        if (cols) cols[5 * e] = (std::int32_t)e;
        for (int s = 0; s < 2; ++s) {
            const i64 f = EF[2 * e + s];
            if (f < 0) {
                if (cols) cols[5 * e + 1 + 2 * s] = cols[5 * e + 2 + 2 * s] = (std::int32_t)e;
                vals[5 * e + 1 + 2 * s] = vals[5 * e + 2 + 2 * s] = 0.0;
                continue;
            }
            const int i = (int)ELI[2 * e + s];
            const double* B = blk + 9 * f;
            d += B[4 * i];
            const int a = (i + 1) % 3, b = (i + 2) % 3;
            if (cols) {
                cols[5 * e + 1 + 2 * s] = (std::int32_t)FE[3 * f + a];
                cols[5 * e + 2 + 2 * s] = (std::int32_t)FE[3 * f + b];
            }
            vals[5 * e + 1 + 2 * s] = B[3 * i + a];
            vals[5 * e + 2 + 2 * s] = B[3 * i + b];
        }
        vals[5 * e] = d;
    }
}

// face_schwarz: inv[f] = (R_T A R_T^T)^{-1}, the face's 3x3 block of the assembled A
// (assembled diagonal `diag`, the face's own off-diagonal entries), fixed DOFs
// removed (their rows/columns of inv are zero).  Inverted after scaling to unit
// diagonal (C = D blk D) by Cholesky pivots; a face whose scaled block is
// numerically singular (pivot < 1e-8: near-degenerate triangle) gets the Jacobi
// block diag(1/blk_ii) instead, so M stays SPD for every accepted mesh.
// Returns the number of such faces.  inv may alias Aloc (each face reads its block first).
i64 face_schwarz(const double* Aloc, const double* diag, const i32* FE, const unsigned char* fixed,
                 i64 nF, double* inv, int nt) {
    i64 n_jacobi = 0;
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt) reduction(+ : n_jacobi)
#endif
    for (i64 f = 0; f < nF; ++f) {
        double b[3][3];
        bool fx[3];
        for (int i = 0; i < 3; ++i) fx[i] = fixed && fixed[FE[3 * f + i]];
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                b[i][j] = (fx[i] || fx[j]) ? 0.0 : (i == j ? diag[FE[3 * f + i]] : Aloc[9 * f + 3 * i + j]);
        for (int i = 0; i < 3; ++i) if (fx[i]) b[i][i] = 1.0;
        double d[3];
        for (int i = 0; i < 3; ++i) d[i] = 1.0 / std::sqrt(b[i][i]);
        const double c01 = b[0][1] * d[0] * d[1], c02 = b[0][2] * d[0] * d[2], c12 = b[1][2] * d[1] * d[2];
        const double p2 = 1.0 - c01 * c01;
        const double l21 = p2 > 0 ? (c12 - c02 * c01) / std::sqrt(p2) : 0.0;
        const double p3 = 1.0 - c02 * c02 - l21 * l21;
        double* out = inv + 9 * f;
        if (!(p2 >= 1e-8 && p3 >= 1e-8)) {
            ++n_jacobi;
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) out[3 * i + j] = (i == j) ? d[i] * d[i] : 0.0;
        } else {
            const double det = p2 * p3;  // det C = product of the Cholesky pivots
            double ci[3][3];
            ci[0][0] = (1.0 - c12 * c12) / det;
            ci[1][1] = (1.0 - c02 * c02) / det;
            ci[2][2] = p2 / det;
            ci[0][1] = ci[1][0] = (c02 * c12 - c01) / det;
            ci[0][2] = ci[2][0] = (c01 * c12 - c02) / det;
            ci[1][2] = ci[2][1] = (c01 * c02 - c12) / det;
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) out[3 * i + j] = ci[i][j] * d[i] * d[j];
        }
        for (int i = 0; i < 3; ++i)
            if (fx[i])
                for (int j = 0; j < 3; ++j) out[3 * i + j] = out[3 * j + i] = 0.0;
    }
    return n_jacobi;
}

// jump_apply: out (#E, k) = B W, B[e, v] = sum_{T∋e} l_e n_{e,T}.grad(lambda_v)|_T
// (b_h(phi_e, lambda_v), eq. 3.8 on flat P1 triangles), W (#V, k).
void jump_apply(const double* V, const i64* F, i64 nF, const i32* EF, const i8* ELI, i64 nE,
                const double* W, int k, double* out, int nt) {
    std::vector<double> c((size_t)nF * 3 * k);
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 f = 0; f < nF; ++f) {
        FaceGeom g;
        face_geom(V, F, f, g);
        for (int kk = 0; kk < k; ++kk) {
            double grad[3] = {0, 0, 0};
            for (int cc = 0; cc < 3; ++cc) {
                const double w = W[F[3 * f + cc] * k + kk] * (-g.l[cc] / g.dbl);
                for (int a = 0; a < 3; ++a) grad[a] += w * g.n[cc][a];
            }
            for (int i = 0; i < 3; ++i) c[((size_t)f * 3 + i) * k + kk] = g.l[i] * dot3(g.n[i], grad);
        }
    }
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 e = 0; e < nE; ++e) {
        for (int kk = 0; kk < k; ++kk) {
            double s = 0.0;
            for (int side = 0; side < 2; ++side) {
                const i64 f = EF[2 * e + side];
                if (f >= 0) s += c[((size_t)f * 3 + ELI[2 * e + side]) * k + kk];
            }
            out[e * k + kk] = s;
        }
    }
}

// shape_operator_faces: S[f] (3x3) = -sum_k nu_T^k sigma^k|_T (eq. 5.12) with
// sigma^k|_T = sum_j s[e(f,j), k] phi_j;  s (#E, 3).
void shape_operator_faces(const double* V, const i64* F, const i32* FE, i64 nF,
                          const double* s, double* S, int nt) {
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 f = 0; f < nF; ++f) {
        FaceGeom g;
        face_geom(V, F, f, g);
        double out[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
        for (int j = 0; j < 3; ++j) {
            const double* sj = s + 3 * (i64)FE[3 * f + j];
            const double c = -(sj[0] * g.nu[0] + sj[1] * g.nu[1] + sj[2] * g.nu[2]);
            double phi[3][3];
            basis_tensor(g, j, phi);
            for (int p = 0; p < 3; ++p)
                for (int q = 0; q < 3; ++q) out[p][q] += c * phi[p][q];
        }
        for (int p = 0; p < 3; ++p)
            for (int q = 0; q < 3; ++q) S[9 * f + 3 * p + q] = out[p][q];
    }
}

// face_tensors: H[f, kk] (3x3) = sum_j s[e(f,j), kk] phi_j (HHJ function on each face); s (#E, k).
void face_tensors(const double* V, const i64* F, const i32* FE, i64 nF,
                  const double* s, int k, double* H, int nt) {
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 f = 0; f < nF; ++f) {
        FaceGeom g;
        face_geom(V, F, f, g);
        double phi[3][3][3];
        for (int j = 0; j < 3; ++j) basis_tensor(g, j, phi[j]);
        for (int kk = 0; kk < k; ++kk) {
            double* out = H + ((size_t)f * k + kk) * 9;
            for (int p = 0; p < 9; ++p) out[p] = 0.0;
            for (int j = 0; j < 3; ++j) {
                const double c = s[(i64)FE[3 * f + j] * k + kk];
                for (int p = 0; p < 3; ++p)
                    for (int q = 0; q < 3; ++q) out[3 * p + q] += c * phi[j][p][q];
            }
        }
    }
}

// principal_2x2: eigen-pairs of the tangential 2x2 block E^T S E (E = [e1 e2], e1 = N x
// (coordinate axis least aligned with N), e2 = N x e1), closed form:
// kappa_{1,2} = m +- sqrt(((a-c)/2)^2 + b^2); PD1 = E v1 / |E v1|, PD2 = N x PD1.
void principal_2x2(const double* S, const double* N, i64 n, double* PD1, double* PD2,
                   double* PV1, double* PV2, int nt) {
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 r = 0; r < n; ++r) {
        const double* nv = N + 3 * r;
        const double* M = S + 9 * r;
        double e1[3], e2[3];
        tangent_frame(nv, e1, e2);
        double Se1[3], Se2[3];
        for (int p = 0; p < 3; ++p) {
            Se1[p] = M[3 * p] * e1[0] + M[3 * p + 1] * e1[1] + M[3 * p + 2] * e1[2];
            Se2[p] = M[3 * p] * e2[0] + M[3 * p + 1] * e2[1] + M[3 * p + 2] * e2[2];
        }
        const double a = dot3(e1, Se1), c = dot3(e2, Se2);
        const double b = 0.5 * (dot3(e1, Se2) + dot3(e2, Se1));
        const double m = 0.5 * (a + c), h = 0.5 * (a - c);
        const double d = std::sqrt(h * h + b * b);
        const double k1 = m + d, k2 = m - d;
        // eigenvector of k1: (k1 - c, b) or (b, k1 - a), the better conditioned one
        double v0 = k1 - c, v1 = b;
        const double u0 = b, u1 = k1 - a;
        if (u0 * u0 + u1 * u1 > v0 * v0 + v1 * v1) { v0 = u0; v1 = u1; }
        if (v0 == 0.0 && v1 == 0.0) v0 = 1.0;  // umbilic: any direction
        double p1[3];
        for (int q = 0; q < 3; ++q) p1[q] = v0 * e1[q] + v1 * e2[q];
        const double np1 = std::sqrt(dot3(p1, p1));
        for (int q = 0; q < 3; ++q) p1[q] /= np1;
        double p2[3];
        cross3(nv, p1, p2);
        for (int q = 0; q < 3; ++q) { PD1[3 * r + q] = p1[q]; PD2[3 * r + q] = p2[q]; }
        PV1[r] = k1;
        PV2[r] = k2;
    }
}

}  // namespace hhj

// Fused block preconditioned conjugate gradients: k independent CG recurrences
// (e.g. the 3 coordinate right-hand sides of eq. 5.14) sharing every sweep over
// the matrix.  Deterministic reductions: per-chunk partial sums over fixed
// CHUNK-row blocks, then a serial sum over the chunks.
#include <algorithm>
#include <cmath>

#include "core.hpp"

#include <cstdlib>
#include <new>
#if defined(__unix__) || defined(__APPLE__)
#include <sys/mman.h>
#endif

namespace hhj {

namespace {
struct Partials {
    i64 nch;
    int k;
    std::vector<double> buf;
    Partials(i64 n, int k_) : nch((n + CHUNK - 1) / CHUNK), k(k_), buf((size_t)std::max<i64>(nch, 1) * k_) {}
    void reduce(std::vector<double>& out) const {
        std::fill(out.begin(), out.end(), 0.0);
        for (i64 c = 0; c < nch; ++c)
            for (int j = 0; j < k; ++j) out[j] += buf[(size_t)c * k + j];
    }
};

// y = Op x for CSR (p, i, v) or, without it, y = dinv .* x;  partial sums of d.y per chunk.
// K = number of columns known at compile time (0: runtime k), local accumulators.
// I = the row pointer's type (int32 for the HHJ system's fixed-width rows, else int64).
template <int K, class I>
void apply_and_dot_k(i64 n, int kr, const I* p, const std::int32_t* idx, const double* v, const double* dinv,
                     const double* x, double* y, const double* d, Partials& P, int nt) {
    const int k = K ? K : kr;
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 c = 0; c < P.nch; ++c) {
        const i64 r0 = c * CHUNK, r1 = std::min(n, r0 + CHUNK);
        double acc[16] = {0};
        for (i64 r = r0; r < r1; ++r) {
            double yr[16];
            if (p) {
                for (int j = 0; j < k; ++j) yr[j] = 0.0;
                const i64 q1 = p[r + 1];
                for (i64 q = p[r]; q < q1; ++q) {
                    const double a = v[q];
                    const double* xc = x + (i64)idx[q] * k;
                    for (int j = 0; j < k; ++j) yr[j] += a * xc[j];
                }
            } else {
                const double di = dinv[r];
                for (int j = 0; j < k; ++j) yr[j] = di * x[r * k + j];
            }
            for (int j = 0; j < k; ++j) {
                y[r * k + j] = yr[j];
                acc[j] += d[r * k + j] * yr[j];
            }
        }
        for (int j = 0; j < k; ++j) P.buf[(size_t)c * k + j] = acc[j];
    }
}

template <class I>
void apply_and_dot(i64 n, int k, const I* p, const std::int32_t* idx, const double* v, const double* dinv,
                   const double* x, double* y, const double* d, Partials& P, int nt) {
    switch (k) {
        case 1: apply_and_dot_k<1, I>(n, k, p, idx, v, dinv, x, y, d, P, nt); break;
        case 3: apply_and_dot_k<3, I>(n, k, p, idx, v, dinv, x, y, d, P, nt); break;
        case 6: apply_and_dot_k<6, I>(n, k, p, idx, v, dinv, x, y, d, P, nt); break;
        default: apply_and_dot_k<0, I>(n, k, p, idx, v, dinv, x, y, d, P, nt);
    }
}

// X += alpha p; r -= alpha q; partial sums of r.r per chunk.  JACOBI: also partial sums
// of r.(dinv r) (the next r.z) into P2, so that z = dinv r is never stored (the same
// operations as apply_and_dot_k with dinv: the same bits).
template <int K, bool JACOBI>
void update_k(i64 n, int kr, const double* alpha_in, double* X, double* r, const double* p,
              const double* q, const double* dinv, Partials& P, Partials* P2, int nt) {
    const int k = K ? K : kr;
    double alpha[16];
    for (int j = 0; j < k; ++j) alpha[j] = alpha_in[j];
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 c = 0; c < P.nch; ++c) {
        const i64 r0 = c * CHUNK, r1 = std::min(n, r0 + CHUNK);
        double acc[16] = {0}, acc2[16] = {0};
        for (i64 i = r0; i < r1; ++i) {
            const double di = JACOBI ? dinv[i] : 0.0;
            for (int j = 0; j < k; ++j) {
                const size_t s = (size_t)i * k + j;
                X[s] += alpha[j] * p[s];
                const double rs = r[s] - alpha[j] * q[s];
                r[s] = rs;
                acc[j] += rs * rs;
                if (JACOBI) acc2[j] += rs * (di * rs);
            }
        }
        for (int j = 0; j < k; ++j) P.buf[(size_t)c * k + j] = acc[j];
        if (JACOBI)
            for (int j = 0; j < k; ++j) P2->buf[(size_t)c * k + j] = acc2[j];
    }
}

// dinv == nullptr: plain update; else the Jacobi-fused one (P2 receives r.(dinv r))
void update(i64 n, int k, const double* alpha, double* X, double* r, const double* p, const double* q,
            const double* dinv, Partials& P, Partials* P2, int nt) {
    if (dinv) {
        switch (k) {
            case 1: update_k<1, true>(n, k, alpha, X, r, p, q, dinv, P, P2, nt); break;
            case 3: update_k<3, true>(n, k, alpha, X, r, p, q, dinv, P, P2, nt); break;
            case 6: update_k<6, true>(n, k, alpha, X, r, p, q, dinv, P, P2, nt); break;
            default: update_k<0, true>(n, k, alpha, X, r, p, q, dinv, P, P2, nt);
        }
        return;
    }
    switch (k) {
        case 1: update_k<1, false>(n, k, alpha, X, r, p, q, nullptr, P, nullptr, nt); break;
        case 3: update_k<3, false>(n, k, alpha, X, r, p, q, nullptr, P, nullptr, nt); break;
        case 6: update_k<6, false>(n, k, alpha, X, r, p, q, nullptr, P, nullptr, nt); break;
        default: update_k<0, false>(n, k, alpha, X, r, p, q, nullptr, P, nullptr, nt);
    }
}
}  // namespace

// block_pcg: solve A X = R, A (n x n) SPD in CSR (Ap, Ai, Ax), R and X (n, k) row-major
// (R is overwritten by the final residual),
// preconditioner M in CSR (Mp, Mi, Mx) or, with Mp == nullptr, Jacobi dinv (n,).
// Column j stops when |r_j| <= rtol |R_j|.  Every probe_iter iterations (0: never) the
// iterations still needed are extrapolated from the mean rate so far; when more than
// max_predicted would remain, the solve stops early (status 2) so the caller can switch
// solvers.
// Status 3: breakdown (p.Ap <= 0 or the residual grew 1e4-fold: A numerically singular).
template <class I>
PCGResult block_pcg(i64 n, int k, const I* Ap, const std::int32_t* Ai, const double* Ax,
                    const I* Mp, const std::int32_t* Mi, const double* Mx, const double* dinv,
                    double* R, double* X, double rtol, i64 maxiter,
                    i64 probe_iter, double max_predicted, int nt, const SubdomainSolve* sub,
                    bool coupled) {
    if (k > 16) throw std::invalid_argument("block_pcg: at most 16 right-hand sides per call");
    PCGResult res;
    res.relres.assign(k, 0.0);
    double* r = R;  // R becomes the residual (caller's scratch: no copy of n x k)
    // Jacobi without a second level: z = dinv r is fused into the update and p sweeps
    const bool fused = Mp == nullptr && !(sub && sub->nS > 0);
    std::vector<double> z(fused ? 0 : (size_t)n * k), p((size_t)n * k), q((size_t)n * k);
    std::fill(X, X + (size_t)n * k, 0.0);
    Partials P(n, k);
    std::vector<double> bb(k), rr(k), rz(k), rz_new(k), pq(k), alpha(k), beta(k), tol2(k);
    std::vector<char> active(k);
    // bb = R.R (Jacobi-free: use apply_and_dot with the identity is wasteful; direct chunked dot)
    auto chunk_dot = [&](const double* a, const double* b, std::vector<double>& out) {
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
        for (i64 c = 0; c < P.nch; ++c) {
            const i64 r0 = c * CHUNK, r1 = std::min(n, r0 + CHUNK);
            double acc[16] = {0};
            for (i64 i = r0; i < r1; ++i)
                for (int j = 0; j < k; ++j) acc[j] += a[i * k + j] * b[i * k + j];
            for (int j = 0; j < k; ++j) P.buf[(size_t)c * k + j] = acc[j];
        }
        P.reduce(out);
    };
    // coupled: one CG on the k columns together (every scalar summed over the columns),
    // so that an orthogonal mixing of the columns (a rotation of the coordinates of the
    // HHJ right-hand sides) commutes with the iteration
    auto couple = [&](std::vector<double>& v) {
        if (!coupled) return;
        double sum = 0.0;
        for (int j = 0; j < k; ++j) sum += v[j];
        for (int j = 0; j < k; ++j) v[j] = sum;
    };
    chunk_dot(R, R, bb);
    couple(bb);
    bool any = false;
    for (int j = 0; j < k; ++j) {
        tol2[j] = rtol * rtol * bb[j];
        rr[j] = bb[j];
        active[j] = rr[j] > tol2[j];
        any = any || active[j];
    }
    if (!any || n == 0) return res;
    std::vector<double> rS, zS;
    if (sub && sub->nS > 0) { rS.resize((size_t)sub->nS * k); zS.resize((size_t)sub->nS * k); }
    // z = M r (+ R_S^T C R_S r), out = r.z; the second level's share of r.z is summed
    // serially over S in a fixed order (deterministic).
    auto precondition = [&](std::vector<double>& out) {
        apply_and_dot(n, k, Mp, Mi, Mx, dinv, r, fused ? p.data() : z.data(), r, P, nt);
        P.reduce(out);
        if (rS.empty()) return;
        const i64 nS = sub->nS;
        const int nts = nS * k >= PCG_MIN_WORK / 8 ? nt : 1;     // copies: S is unique
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nts)
#endif
        for (i64 i = 0; i < nS; ++i)
            for (int j = 0; j < k; ++j) rS[(size_t)i * k + j] = r[(size_t)sub->S[i] * k + j];
        sub->solve(rS.data(), zS.data(), nt);
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nts)
#endif
        for (i64 i = 0; i < nS; ++i)
            for (int j = 0; j < k; ++j) z[(size_t)sub->S[i] * k + j] += zS[(size_t)i * k + j];
        for (i64 i = 0; i < nS; ++i)                              // serial: a fixed order
            for (int j = 0; j < k; ++j) out[j] += rS[(size_t)i * k + j] * zS[(size_t)i * k + j];
    };
    precondition(rz);   // fused: p = dinv r directly
    couple(rz);
    if (!fused) std::copy(z.begin(), z.end(), p.begin());
    Partials P2(n, k);
    res.status = 1;
    for (i64 it = 1; it <= maxiter; ++it) {
        apply_and_dot(n, k, Ap, Ai, Ax, nullptr, p.data(), q.data(), p.data(), P, nt);
        P.reduce(pq);
        couple(pq);
        bool breakdown = false;
        for (int j = 0; j < k; ++j) {
            alpha[j] = active[j] ? rz[j] / pq[j] : 0.0;
            breakdown = breakdown || (active[j] && !(pq[j] > 0.0 && std::isfinite(alpha[j])));
        }
        if (breakdown) { res.status = 3; res.iterations = it; break; }
        update(n, k, alpha.data(), X, r, p.data(), q.data(), fused ? dinv : nullptr, P, &P2, nt);
        if (fused) P2.reduce(rz_new);
        P.reduce(rr);
        couple(rr);
        res.iterations = it;
        any = false;
        for (int j = 0; j < k; ++j) {
            active[j] = active[j] && rr[j] > tol2[j];
            any = any || active[j];
            // divergence in floating point (A numerically singular): residual up 1e4x
            breakdown = breakdown || !std::isfinite(rr[j]) || rr[j] > 1e8 * bb[j];
        }
        if (breakdown) { res.status = 3; break; }
        if (!any) { res.status = 0; break; }
        if (probe_iter > 0 && it % probe_iter == 0 && rtol > 0) {
            double worst = 0.0;
            for (int j = 0; j < k; ++j)
                if (active[j] && bb[j] > 0) worst = std::max(worst, std::sqrt(rr[j] / bb[j]));
            if (worst > 0 && worst < 1) {
                const double remaining = (double)it * std::log(rtol) / std::log(worst) - (double)it;
                if (remaining > max_predicted) { res.status = 2; break; }
            } else if (worst >= 1) {
                res.status = 2; break;
            }
        }
        if (!fused) precondition(rz_new);
        couple(rz_new);
        for (int j = 0; j < k; ++j) {
            beta[j] = active[j] ? rz_new[j] / rz[j] : 0.0;
            rz[j] = rz_new[j];
        }
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
        for (i64 c = 0; c < P.nch; ++c) {
            const i64 r0 = c * CHUNK, r1 = std::min(n, r0 + CHUNK);
            double b[16];
            for (int j = 0; j < k; ++j) b[j] = beta[j];
            double* pp = p.data();
            if (fused) {
                for (i64 i = r0; i < r1; ++i) {
                    const double di = dinv[i];
                    for (int j = 0; j < k; ++j) {
                        const size_t s = (size_t)i * k + j;
                        pp[s] = di * r[s] + b[j] * pp[s];
                    }
                }
                continue;
            }
            const double* zz = z.data();
            for (i64 i = r0; i < r1; ++i)
                for (int j = 0; j < k; ++j) {
                    const size_t s = (size_t)i * k + j;
                    pp[s] = zz[s] + b[j] * pp[s];
                }
        }
    }
    for (int j = 0; j < k; ++j) res.relres[j] = bb[j] > 0 ? std::sqrt(rr[j] / bb[j]) : 0.0;
    return res;
}

void ldl_schedule(LDLFactor& f) {
    const i64 n = f.n;
    std::vector<i64> root(n);
    std::vector<i64> parent(n, -1);
    for (i64 j = 0; j < n; ++j)
        for (i64 q = f.Lp[j]; q < f.Lp[j + 1]; ++q)
            if (parent[j] < 0 || f.Li[q] < parent[j]) parent[j] = f.Li[q];
    std::vector<i64> tree_work(n, 0);
    for (i64 j = n - 1; j >= 0; --j) root[j] = parent[j] < 0 ? j : root[parent[j]];
    for (i64 j = 0; j < n; ++j) tree_work[root[j]] += f.Lp[j + 1] - f.Lp[j] + 1;
    std::vector<i64> roots;
    for (i64 j = 0; j < n; ++j)
        if (parent[j] < 0) roots.push_back(j);
    // heaviest first, ties by column: a deterministic assignment
    std::sort(roots.begin(), roots.end(), [&](i64 a, i64 b) {
        return tree_work[a] != tree_work[b] ? tree_work[a] > tree_work[b] : a < b;
    });
    std::vector<unsigned char> side(n, 0);
    i64 load[2] = {0, 0};
    for (i64 t : roots) {
        const int g = load[1] < load[0] ? 1 : 0;
        side[t] = (unsigned char)g;
        load[g] += tree_work[t];
    }
    f.group[0].clear();
    f.group[1].clear();
    for (i64 j = 0; j < n; ++j) f.group[side[root[j]]].push_back(j);
}

void ldl_solve_block(const LDLFactor& f, int k, const double* r, double* z, double* w, int nt) {
    // both groups non-empty: one thread each (a group's columns touch only its own rows of w)
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static, 1) num_threads(nt > 1 && !f.group[1].empty() ? 2 : 1)
#endif
    for (int g = 0; g < 2; ++g) {
        const std::vector<i64>& cols = f.group[g];
        const i64 m = (i64)cols.size();
        for (i64 t = 0; t < m; ++t) {
            const i64 i = cols[t];
            for (int c = 0; c < k; ++c) w[(size_t)i * k + c] = r[(size_t)f.perm[i] * k + c];
        }
        for (i64 t = 0; t < m; ++t) {                        // (I + L) u = w, column-oriented
            const i64 j = cols[t];
            const double* wj = w + (size_t)j * k;
            for (i64 q = f.Lp[j]; q < f.Lp[j + 1]; ++q) {
                double* wi = w + (size_t)f.Li[q] * k;
                const double l = f.Lx[q];
                for (int c = 0; c < k; ++c) wi[c] -= l * wj[c];
            }
        }
        for (i64 t = 0; t < m; ++t) {
            const i64 i = cols[t];
            const double d = f.D[i];
            for (int c = 0; c < k; ++c) w[(size_t)i * k + c] /= d;
        }
        for (i64 t = m - 1; t >= 0; --t) {                   // (I + L)ᵀ x = v, dot products
            const i64 j = cols[t];
            double* wj = w + (size_t)j * k;
            for (i64 q = f.Lp[j]; q < f.Lp[j + 1]; ++q) {
                const double* wi = w + (size_t)f.Li[q] * k;
                const double l = f.Lx[q];
                for (int c = 0; c < k; ++c) wj[c] -= l * wi[c];
            }
        }
        for (i64 t = 0; t < m; ++t) {
            const i64 i = cols[t];
            for (int c = 0; c < k; ++c) z[(size_t)f.perm[i] * k + c] = w[(size_t)i * k + c];
        }
    }
}

// the two row-pointer types (kernels.block_pcg picks int32 when A's and M's are)
template PCGResult block_pcg<i64>(i64, int, const i64*, const std::int32_t*, const double*, const i64*,
                                  const std::int32_t*, const double*, const double*, double*, double*, double,
                                  i64, i64, double, int, const SubdomainSolve*, bool);
template PCGResult block_pcg<i32>(i64, int, const i32*, const std::int32_t*, const double*, const i32*,
                                  const std::int32_t*, const double*, const double*, double*, double*, double,
                                  i64, i64, double, int, const SubdomainSolve*, bool);

}  // namespace hhj

namespace hhj {
// Envelope LDLᵀ of a small SPD matrix given in CSR rows (duplicates summed here): row i
// of the factor is stored packed, only from its first nonzero column first[i] to the
// diagonal (the factorisation keeps that envelope), so memory is Σ_i (i - first[i] + 1)
// values and the cost Σ_i (i - first[i])² / 2 flops (icosphere(2), 480 unknowns in Morton
// order: 126 KB instead of 1.8 MB dense).  No pivoting: a pivot ≤ 1e-13 × max|a_ii| (a
// numerically semi-definite matrix) returns status 1, a solution whose relative residual
// exceeds resid_rtol in some column returns status 2; the caller then uses its pivoted
// sparse fallback.  Status 3: a column index out of range.
namespace {
// Zeroed storage of the packed factor: calloc below glibc's default mmap threshold
// (128 KiB), else its own anonymous mapping.  Freeing a malloc'ed block above the
// threshold raises the threshold to the block's size, after which every later array up
// to that size comes from the heap and stays resident after the call (the benchmark's
// fresh-process peak then read 0 KB/face: memory retained, not saved).
struct ZeroedBuffer {
    static constexpr size_t kMallocMax = 128 * 1024;
    double* p = nullptr;
    size_t bytes = 0;
    bool mapped = false;
    explicit ZeroedBuffer(size_t n) : bytes((n ? n : 1) * sizeof(double)) {
#if defined(__unix__) || defined(__APPLE__)
        if (bytes >= kMallocMax) {
            void* m = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
            if (m != MAP_FAILED) {
                p = static_cast<double*>(m);      // anonymous pages are zero
                mapped = true;
                return;
            }
        }
#endif
        p = static_cast<double*>(std::calloc(bytes / sizeof(double), sizeof(double)));
        if (!p) throw std::bad_alloc();
    }
    ~ZeroedBuffer() {
#if defined(__unix__) || defined(__APPLE__)
        if (mapped) { munmap(p, bytes); return; }
#endif
        std::free(p);
    }
    ZeroedBuffer(const ZeroedBuffer&) = delete;
    ZeroedBuffer& operator=(const ZeroedBuffer&) = delete;
};
}  // namespace

int envelope_ldl_solve(i64 n, int k, const i64* Ap, const std::int32_t* Ai, const double* Ax,
                       const double* R, double* X, double resid_rtol) {
    std::vector<i64> first(n), base(n);
    size_t size = 0;
    for (i64 i = 0; i < n; ++i) {
        i64 f = i;
        for (i64 q = Ap[i]; q < Ap[i + 1]; ++q) {
            const i64 j = Ai[q];
            if (j < 0 || j >= n) return 3;
            if (Ax[q] != 0.0 && j < f) f = j;
        }
        first[i] = f;
        base[i] = (i64)size - f;                 // row i's column c lives at base[i] + c
        size += (size_t)(i - f + 1);
    }
    ZeroedBuffer buf(size);
    double* L = buf.p;
    auto row = [&](i64 i) { return L + base[i]; };   // valid for columns first[i]..i
    for (i64 i = 0; i < n; ++i)
        for (i64 q = Ap[i]; q < Ap[i + 1]; ++q)
            if (Ai[q] <= i && Ax[q] != 0.0) row(i)[Ai[q]] += Ax[q];
    double amax = 0.0;
    for (i64 i = 0; i < n; ++i) amax = std::max(amax, std::abs(row(i)[i]));
    const double tiny = 1e-13 * amax;
    std::vector<double> D(n), W(n);                  // W[c] = L[i][c] D[c] for the current row
    for (i64 i = 0; i < n; ++i) {
        double* Li = row(i);
        const i64 fi = first[i];
        for (i64 j = fi; j < i; ++j) {           // Li[j] = (a_ij - Σ_c L_ic D_c L_jc) / D_j
            const double* Lj = row(j);
            const i64 c0 = std::max(fi, first[j]);
            double s = Li[j];
            for (i64 c = c0; c < j; ++c) s -= W[c] * Lj[c];
            W[j] = s;                             // = L_ij D_j
            Li[j] = s / D[j];
        }
        double d = Li[i];
        for (i64 c = fi; c < i; ++c) d -= W[c] * Li[c];
        if (!(d > tiny)) return 1;
        D[i] = d;
    }
    std::vector<double>& y = W;                  // the work vector of the solves
    for (int col = 0; col < k; ++col) {
        for (i64 i = 0; i < n; ++i) {            // (I + L) y = r
            const double* Li = row(i);
            double s = R[(size_t)i * k + col];
            for (i64 c = first[i]; c < i; ++c) s -= Li[c] * y[c];
            y[i] = s;
        }
        for (i64 i = 0; i < n; ++i) y[i] /= D[i];
        for (i64 i = n - 1; i >= 0; --i) {       // (I + L)ᵀ x = y, column-oriented
            const double* Li = row(i);
            const double xi = y[i];
            for (i64 c = first[i]; c < i; ++c) y[c] -= Li[c] * xi;
        }
        double rn = 0.0, res = 0.0;
        for (i64 i = 0; i < n; ++i) X[(size_t)i * k + col] = y[i];
        for (i64 i = 0; i < n; ++i) {
            double s = R[(size_t)i * k + col];
            rn += s * s;
            for (i64 q = Ap[i]; q < Ap[i + 1]; ++q) s -= Ax[q] * X[(size_t)Ai[q] * k + col];
            res += s * s;
        }
        if (!std::isfinite(res) || res > resid_rtol * resid_rtol * rn) return 2;
    }
    return 0;
}
}  // namespace hhj

// igl_hhj compiled core: declarations shared by the kernels and the bindings.
//
// Conventions (igl_hhj/mesh.py, shared/design/hhj_lowest_order.md):
//   edge i of face T is opposite corner i and runs x_{i+1} -> x_{i+2};
//   t_i = unit edge vector, nu = unit face normal of (x1-x0)x(x2-x0),
//   n_i = t_i x nu (outward conormal), grad lambda_i = -l_i n_i / (2|T|).
// No hidden state: every kernel reads its inputs and writes caller-owned outputs.
// Arrays are row-major (C-contiguous) float64 / int64; the topology maps of
// mesh.TriangleMesh are narrow (memory): edge, face and vertex indices in
// them int32 (i32), local indices, signs and incidence counts int8 (i8).  Load an
// i32 into an i64 before multiplying it (3 * e overflows int above 715M).
#pragma once
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#ifdef IGL_HHJ_OPENMP
#include <omp.h>
#endif

namespace hhj {

using i64 = std::int64_t;
using i32 = std::int32_t;
using i8 = std::int8_t;

// ------------------------------------------------------------------ threads
// Number of threads a kernel may use.  One call at a time gets all OpenMP
// threads; a call made while another igl_hhj kernel is running (several Python
// threads, the GIL released) runs single-threaded, so N Python threads never
// start N x #cores OpenMP threads.  Small problems run single-threaded.
struct ThreadBudget {
    static std::atomic<int>& active() { static std::atomic<int> a{0}; return a; }
    int nt = 1;
    int free_threads = 1;   // the threads this call may use, whatever its size
    // work below min_work runs single-threaded (fork/join costs more than it saves)
    explicit ThreadBudget(i64 work, i64 min_work = 20000) {
        int prev = active().fetch_add(1);
#ifdef IGL_HHJ_OPENMP
        free_threads = prev == 0 ? omp_get_max_threads() : 1;
        nt = work >= min_work ? free_threads : 1;
#else
        (void)prev; (void)work; (void)min_work;
#endif
    }
    ~ThreadBudget() { active().fetch_sub(1); }
};

// Reductions use this fixed chunk size: partial sums per chunk, then a serial
// sum over chunks, so results do not depend on the thread count.
constexpr i64 CHUNK = 2048;

// The block PCG forks and joins several times per iteration: two threads only pay from
// n·k ≥ PCG_MIN_WORK (measured on the HHJ systems, k = 3: 2 threads are 1.6x slower at
// 20k unknowns (cheburashka), 8 % slower at 34k (camelhead; the same time in a later
// round), 1.15x faster at 58k (beetle: shape_operator 137 -> 119 ms), 1.5x faster at 123k).
constexpr i64 PCG_MIN_WORK = 150000;

// The intrinsic smoothing of a mesh with fewer vertices than ThreadBudget's two-thread size
// runs the h and z parts of each solve as two tasks from this many vertices on.
constexpr i64 SMOOTHING_TASK_MIN = 2000;

// The corners of every vertex in face order (a counting sort of F): corners of v are
// corner[start[v] .. start[v + 1]), each f * 3 + c.  Sums over a vertex's corners in this
// order are the sums a scatter over the faces makes, bit for bit.
struct VertexCorners {
    std::vector<i64> start, corner;
    VertexCorners(const i64* F, i64 nF, i64 nV) : start(nV + 1, 0), corner((size_t)nF * 3) {
        for (i64 q = 0; q < 3 * nF; ++q) ++start[F[q] + 1];
        for (i64 v = 0; v < nV; ++v) start[v + 1] += start[v];
        std::vector<i64> next(start.begin(), start.end() - 1);
        for (i64 q = 0; q < 3 * nF; ++q) corner[next[F[q]]++] = q;
    }
};

// ------------------------------------------------------------------ geometry
struct FaceGeom {
    double t[3][3];   // unit edge vectors t_i
    double n[3][3];   // unit outward conormals n_i
    double l[3];      // edge lengths l_i
    double nu[3];     // unit face normal
    double dbl;       // twice the area |(x1-x0)x(x2-x0)|
};

inline void cross3(const double* a, const double* b, double* c) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}
inline double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Tangent frame of a unit normal n: e1 = n x a / |n x a| (a = the first coordinate axis
// least aligned with n), e2 = n x e1 (recovery.recovery_operator, curvature's 2x2 eigen).
inline void tangent_frame(const double* n, double e1[3], double e2[3]) {
    int ax = 0;
    double best = std::fabs(n[0]);
    for (int a = 1; a < 3; ++a)
        if (std::fabs(n[a]) < best) { best = std::fabs(n[a]); ax = a; }
    double axis[3] = {0, 0, 0};
    axis[ax] = 1.0;
    cross3(n, axis, e1);
    const double ne = std::sqrt(dot3(e1, e1));
    for (int a = 0; a < 3; ++a) e1[a] /= ne;
    cross3(n, e1, e2);
}

// Edge lengths l_i (edge opposite corner i) of face f; returns the face's area.
inline double face_lengths(const double* V, const i64* F, i64 f, double l[3]) {
    const double* x[3] = {V + 3 * F[3 * f], V + 3 * F[3 * f + 1], V + 3 * F[3 * f + 2]};
    for (int i = 0; i < 3; ++i) {
        const double* a = x[(i + 1) % 3];
        const double* b = x[(i + 2) % 3];
        const double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        l[i] = std::sqrt(dot3(d, d));
    }
    const double e1[3] = {x[1][0] - x[0][0], x[1][1] - x[0][1], x[1][2] - x[0][2]};
    const double e2[3] = {x[2][0] - x[0][0], x[2][1] - x[0][1], x[2][2] - x[0][2]};
    double c[3];
    cross3(e1, e2, c);
    return 0.5 * std::sqrt(dot3(c, c));
}

// out = R x, R the minimal rotation taking unit a to unit b (Rodrigues:
// R x = c x + k x x + (k.x) k / (1 + c), k = a x b, c = a.b; intrinsic.transport).
// Returns c; undefined for c = -1 (callers give such pairs no weight).
inline double min_rotation(const double* x, const double* a, const double* b, double out[3]) {
    double k[3], kx[3];
    cross3(a, b, k);
    cross3(k, x, kx);
    const double c = dot3(a, b);
    const double s = dot3(k, x) / (1.0 + c);
    for (int p = 0; p < 3; ++p) out[p] = c * x[p] + kx[p] + s * k[p];
    return c;
}

// Per-vertex frames fr (nV, 9): the normal (N, or +z where a component of N is not
// finite) and its tangent_frame (e1, e2): intrinsic.vertex_frames.
inline void normal_frames(const double* N, i64 nV, double* fr, int nt) {
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 v = 0; v < nV; ++v) {
        double* n = fr + 9 * v;
        const bool fin = std::isfinite(N[3 * v]) && std::isfinite(N[3 * v + 1]) && std::isfinite(N[3 * v + 2]);
        for (int a = 0; a < 3; ++a) n[a] = fin ? N[3 * v + a] : (a == 2 ? 1.0 : 0.0);
        tangent_frame(n, n + 3, n + 6);
    }
}

// Face geometry of face f of (V, F), same formulas as mesh.py's properties.
inline void face_geom(const double* V, const i64* F, i64 f, FaceGeom& g) {
    const double* x[3] = {V + 3 * F[3 * f], V + 3 * F[3 * f + 1], V + 3 * F[3 * f + 2]};
    double e1[3], e2[3], c[3];
    for (int k = 0; k < 3; ++k) { e1[k] = x[1][k] - x[0][k]; e2[k] = x[2][k] - x[0][k]; }
    cross3(e1, e2, c);
    g.dbl = std::sqrt(dot3(c, c));
    for (int k = 0; k < 3; ++k) g.nu[k] = c[k] / g.dbl;
    for (int i = 0; i < 3; ++i) {
        const double* a = x[(i + 1) % 3];
        const double* b = x[(i + 2) % 3];
        double ev[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        g.l[i] = std::sqrt(dot3(ev, ev));
        for (int k = 0; k < 3; ++k) g.t[i][k] = ev[k] / g.l[i];
        cross3(g.t[i], g.nu, g.n[i]);
    }
}

// ------------------------------------------------------------------ kernels
// mesh_kernels.cpp
struct Topology {
    std::vector<i32> edges;        // (#E, 2) (min, max), lexicographic order (= igl uE order)
    std::vector<i32> face_edges;   // (#F, 3)
    std::vector<i8> count;         // (#E,), saturates at 127 (only 1, 2 and > 2 matter)
    std::vector<i32> edge_faces;   // (#E, 2), -1 = none
    std::vector<i8> local_index;   // (#E, 2), -1 = none
    std::vector<i8> sign;          // (#F, 3) +-1
    i64 n_edges = 0;
};
void topology(const i64* F, i64 nF, i64 nV, Topology& out);
void edge_morton_order(const double* V, i64 nV, const i32* E, i64 nE, i64* perm);
void face_metrics(const double* V, const i64* F, i64 nF, double* cross, double* dbl, double* l2max, int nt);
void vertex_area_sums(const i64* F, i64 nF, i64 nV, const double* cross, const double* dbl, double* s,
                      double* a);
void dihedral_magnitudes(const double* N, const i32* EF, const i8* count, i64 nE, double* theta, int nt);
void crease_cut(const i64* F, i64 nF, i64 nV, const i32* EF, const i8* ELI, i64 nE,
                const unsigned char* join, const double* face_area, i64* Fc, std::vector<i64>& extra);

// hhj_kernels.cpp
void local_mass(const double* V, const i64* F, i64 nF, double* Aloc, double* sin_min = nullptr);
void assemble_ell(const double* Aloc, const i32* FE, const i32* EF, const i8* ELI, i64 nE,
                  std::int32_t* cols, double* vals, int nt);
i64 face_schwarz(const double* Aloc, const double* diag, const i32* FE, const unsigned char* fixed,
                 i64 nF, double* inv, int nt);
void jump_apply(const double* V, const i64* F, i64 nF, const i32* EF, const i8* ELI, i64 nE,
                const double* W, int k, double* out, int nt);
void shape_operator_faces(const double* V, const i64* F, const i32* FE, i64 nF,
                          const double* s, double* S, int nt);
void face_tensors(const double* V, const i64* F, const i32* FE, i64 nF,
                  const double* s, int k, double* H, int nt);
void principal_2x2(const double* S, const double* N, i64 n, double* PD1, double* PD2,
                   double* PV1, double* PV2, int nt);

// recovery_kernels.cpp
void recovery_weights(const double* V, const i64* F, i64 nF, const i32* FE, const i32* EF, i64 nE,
                      double floor, double* w, int nt);
void intrinsic_patch_recovery(const double* V, const i64* F, i64 nF, i64 nV, const double* S,
                              const double* N, const double* w, const unsigned char* ref, double h,
                              double* X, double* rough, int nt);
void vertex_laplacian(i64 nV, const i32* E, i64 nE, const i32* EF, const i8* ELI, const double* C,
                      std::vector<i64>& indptr, std::vector<std::int32_t>& indices,
                      std::vector<double>& L, std::vector<i64>& diag_pos,
                      std::vector<i64>* pos_lo = nullptr, std::vector<i64>* pos_hi = nullptr);

void boundary_normal_fits(const double* X, i64 nV, const i32* E, i64 nE, const i64* verts, i64 n, int rings,
                          const double* N0, double* N, int nt);

// intrinsic_kernels.cpp
i64 vertex_groups(i64 nV, const i32* E, i64 nE, std::vector<std::int32_t>& label);
void transport_phases(const double* N, i64 nV, const i32* E, i64 nE, double* phase, int nt);
void adaptive_radius(const double* V, const i64* F, i64 nF, i64 nV, const double* P, const double* rough,
                     double radius, double gain, double power, double lo, double hi, double* r, int nt);
void face_times(const double* V, const i64* F, i64 nF, const double* r, int r_stride, double factor,
                int steps, double* t, int nt);
void principal_hz(const double* X, const double* N, i64 n, double* PD1, double* PD2, double* PV1,
                  double* PV2, int nt);
int intrinsic_smoothing(const double* V, const i64* F, i64 nF, i64 nV, const i32* E, i64 nE, const i32* EF,
                        const i8* ELI, const double* C0, const double* m, const double* phase,
                        const double* rough, double radius, double per_radius, double pilot_radius,
                        double pilot_rtol, double gain, double power, double lo, double hi, int steps,
                        const std::vector<double>& binom, double rtol, i64 maxiter, double* X, double* r,
                        int nt, i64* iterations, i64* ngroups, int tasks = 1);

// pcg.cpp
struct PCGResult {
    i64 iterations = 0;
    int status = 0;              // 0 converged, 1 iteration cap, 2 stopped early (slow)
    std::vector<double> relres;  // per column
};
// Optional second level of the preconditioner: z += R_S^T C (R_S r) on the index set S,
// C given as a function (rS (nS,k) -> zS (nS,k), threads it may use), e.g. an exact
// sparse solve.
struct SubdomainSolve {
    const i64* S = nullptr;
    i64 nS = 0;
    std::function<void(const double*, double*, int)> solve;
};
// A sparse LDLᵀ factor P (I + L) D (I + L)ᵀ Pᵀ (QDLDL's layout: L strictly lower, CSC;
// perm[k] = row of A that is row k of the factor) and its block solve on k interleaved
// columns (rS (n,k) -> zS (n,k), w scratch (n,k)): the two-level's subdomain solve without
// a Python round trip.
// group[0], group[1]: the factor's columns split by elimination tree (ldl_schedule), each
// in ascending order; a tree's columns only update rows of the same tree, so the two
// groups are solved by two threads with the same operations in the same order (the same
// bits as one thread).
struct LDLFactor {
    i64 n = 0;
    const i64* Lp = nullptr;
    const i64* Li = nullptr;
    const double* Lx = nullptr;
    const double* D = nullptr;
    const i64* perm = nullptr;
    std::vector<i64> group[2];
};
// Fill f.group: elimination trees (parent of column j = its smallest row index) assigned
// greedily, heaviest first, to the group with less work (nonzeros + 1 per column).
void ldl_schedule(LDLFactor& f);
void ldl_solve_block(const LDLFactor& f, int k, const double* r, double* z, double* w, int nt);
// I = i64 or i32: the row pointers of A and M (explicitly instantiated in pcg.cpp)
template <class I>
PCGResult block_pcg(i64 n, int k, const I* Ap, const std::int32_t* Ai, const double* Ax,
                    const I* Mp, const std::int32_t* Mi, const double* Mx, const double* dinv,
                    double* R, double* X, double rtol, i64 maxiter,
                    i64 probe_iter, double max_predicted, int nt,
                    const SubdomainSolve* sub = nullptr, bool coupled = false);

int envelope_ldl_solve(i64 n, int k, const i64* Ap, const std::int32_t* Ai, const double* Ax,
                       const double* R, double* X, double resid_rtol);

// small_mesh.cpp: the drop-in on a small mesh in one call (the fixed cost per call).
// The parameters are the Python constants of the general path (igl_hhj.constants, passed
// by igl_hhj.small_mesh).
struct SmallParams {
    double degenerate_rtol, min_mesh_size, folded_rtol, quality_floor, direct_rtol;
    i64 max_edges;            // the envelope solver's limit (solvers.ENVELOPE_MAX)
    bool estimate;            // boundary="estimate" (else an open mesh takes the general path)
    int fit_rings;            // boundary_estimation.FIT_RINGS
    double side_dot_min;      // boundary_estimation.SIDE_DOT_MIN
    int band_rings;           // recovery.BOUNDARY_BAND_RINGS
    double band_factor;       // recovery.BOUNDARY_LENGTH_FACTOR
    double radius, per_radius, pilot_radius, smoothing_rtol, gain, power, lo, hi;
    int steps;
    std::vector<double> binom;
    i64 maxiter;
};
// status of dropin_small: 0 done; else the general path must run (and raise or repair)
enum { SMALL_OK = 0, SMALL_DEFECT = 1, SMALL_OPEN = 2, SMALL_TOO_LARGE = 3, SMALL_SOLVE = 4 };
// V (nV, 3), F (nF, 3) with indices in range; N0 (nV, 3) libigl's area-weighted vertex
// normals, cot (nF, 3) igl.cotmatrix_entries.  Writes PD1, PD2 (nV, 3), PV1, PV2 (nV,),
// bad (nV,) as curvature.principal_curvature.
int dropin_small(const double* V, i64 nV, const i64* F, i64 nF, const double* N0, const double* cot,
                 const SmallParams& p, double* PD1, double* PD2, double* PV1, double* PV2,
                 unsigned char* bad);

// Large-call heap scope (heap.cpp): raise glibc's mmap threshold while open; the last
// exit restores glibc's 32 MiB ceiling and trims.  enter returns whether it is raised,
// exit whether this exit restored and trimmed.
bool heap_scope_enter(std::size_t mmap_threshold);
bool heap_scope_exit();
int heap_scope_depth();

}  // namespace hhj

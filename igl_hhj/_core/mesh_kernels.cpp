// Mesh topology in one pass (counting sort of the 3 #F half-edges by their
// smaller vertex, then by the larger): unique edges, face->edge, edge->face,
// incidence counts and half-edge signs, in the conventions of igl_hhj/mesh.py.
#include <algorithm>
#include <utility>

#include "core.hpp"

namespace hhj {

// topology: F (#F,3) -> edges (#E,2) lexicographic (min,max) pairs (the order of
// igl.unique_edge_map's uE), face_edges (#F,3) (edge opposite corner i),
// count (#E,), edge_faces / local_index (#E,2) (column 0: the face whose
// half-edge runs min->max), sign (#F,3) (+1 where the half-edge x_{i+1}->x_{i+2}
// runs min->max).  On non-manifold edges (count > 2) the last faces win.  The maps are
// int32 (indices) and int8 (counts saturated at 127, local indices, signs); at most
// 2^31 - 1 unique edges (checked here) and vertex indices below 2^31 (the binding).
void topology(const i64* F, i64 nF, i64 nV, Topology& T) {
    const i64 nH = 3 * nF;
    // half-edge h = 3f + i gets the key (hi << 32) | h, bucketed by its lower vertex: sorting
    // the keys of a bucket sorts by (hi, h) on contiguous memory (no indirection; needs
    // nH, nV < 2^32, checked by the binding)
    std::vector<i64> start(nV + 1, 0), lo(nH);
    std::vector<std::uint64_t> hikey(nH);
    for (i64 f = 0; f < nF; ++f)
        for (int i = 0; i < 3; ++i) {
            const i64 a = F[3 * f + (i + 1) % 3], b = F[3 * f + (i + 2) % 3];
            const i64 h = 3 * f + i;
            lo[h] = a < b ? a : b;
            hikey[h] = ((std::uint64_t)(a < b ? b : a) << 32) | (std::uint64_t)h;
            ++start[lo[h] + 1];
        }
    for (i64 v = 0; v < nV; ++v) start[v + 1] += start[v];
    std::vector<std::uint64_t> order(nH);
    {
        std::vector<i64> fill(start.begin(), start.end() - 1);
        for (i64 h = 0; h < nH; ++h) order[fill[lo[h]]++] = hikey[h];
    }
    // sort each bucket by key = (hi, h): buckets are small (vertex valence), insertion sort
    for (i64 v = 0; v < nV; ++v) {
        std::uint64_t* b = order.data() + start[v];
        const i64 m = start[v + 1] - start[v];
        if (m > 32) {
            std::sort(b, b + m);
            continue;
        }
        for (i64 p = 1; p < m; ++p) {
            const std::uint64_t key = b[p];
            i64 q = p - 1;
            while (q >= 0 && b[q] > key) { b[q + 1] = b[q]; --q; }
            b[q + 1] = key;
        }
    }
    T.face_edges.assign(nH, 0);
    T.sign.assign(nH, 0);
    T.edges.clear();
    T.edges.reserve(nH);  // ~ #E * 2 = 2/3 nH * 2
    i64 nE = 0, prev_lo = -1, prev_hi = -1;
    for (i64 v = 0; v < nV; ++v) {
        for (i64 p = start[v]; p < start[v + 1]; ++p) {
            const i64 h = (i64)(order[p] & 0xffffffffULL);
            const i64 hi = (i64)(order[p] >> 32);
            if (v != prev_lo || hi != prev_hi) {
                if (nE == INT32_MAX)     // the int32 maps hold at most 2^31 - 1 edges
                    throw std::invalid_argument("topology: the mesh has 2**31 or more unique edges; "
                                                "igl_hhj's int32 edge maps hold at most 2**31 - 1");
                T.edges.push_back((i32)v);
                T.edges.push_back((i32)hi);
                prev_lo = v; prev_hi = hi;
                ++nE;
            }
            T.face_edges[h] = (i32)(nE - 1);
            const i64 f = h / 3, i = h % 3;
            T.sign[h] = (F[3 * f + (i + 1) % 3] == v) ? 1 : -1;
        }
    }
    T.n_edges = nE;
    T.count.assign(nE, 0);
    T.edge_faces.assign(2 * nE, -1);
    T.local_index.assign(2 * nE, -1);
    for (i64 h = 0; h < nH; ++h) {  // ascending (f, i): the last write wins, as in numpy
        const i64 e = T.face_edges[h];
        if (T.count[e] < INT8_MAX) ++T.count[e];      // saturates: only 1, 2 and > 2 matter
        const int col = T.sign[h] < 0 ? 1 : 0;
        T.edge_faces[2 * e + col] = (i32)(h / 3);
        T.local_index[2 * e + col] = (i8)(h % 3);
    }
}

}  // namespace hhj

namespace hhj {

namespace {
inline std::uint64_t spread3(std::uint64_t x) {  // 21 bits -> every third bit
    x &= 0x1fffffULL;
    x = (x | x << 32) & 0x1f00000000ffffULL;
    x = (x | x << 16) & 0x1f0000ff0000ffULL;
    x = (x | x << 8) & 0x100f00f00f00f00fULL;
    x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
    x = (x | x << 2) & 0x1249249249249249ULL;
    return x;
}
}  // namespace

// edge_morton_order: perm (#E,) listing the edges by the Morton (Z-order) code of their
// midpoints on a 2048³ grid (ties by index): a memory-local numbering for the solver's
// sparse sweeps.  2048 cells per axis are finer than the edges of any mesh that fits in
// memory along a curve; 33-bit codes sort in three stable 11-bit radix passes whose
// 2048 buckets stay in cache (16-bit digits over 63-bit codes took 2.5x longer).
void edge_morton_order(const double* V, i64 nV, const i32* E, i64 nE, i64* perm) {
    constexpr int BITS = 11;
    constexpr double CELLS = (double)((1 << BITS) - 1);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (i64 v = 0; v < nV; ++v)
        for (int a = 0; a < 3; ++a) { lo[a] = std::min(lo[a], V[3 * v + a]); hi[a] = std::max(hi[a], V[3 * v + a]); }
    double scale = 0.0;
    for (int a = 0; a < 3; ++a) scale = std::max(scale, hi[a] - lo[a]);
    scale = scale > 0 ? CELLS / scale : 0.0;
    std::vector<std::uint64_t> key(nE), key2(nE);
    std::vector<i64> idx(nE), idx2(nE);
    for (i64 e = 0; e < nE; ++e) {
        std::uint64_t code = 0;
        for (int a = 0; a < 3; ++a) {
            const double mid = 0.5 * (V[3 * (i64)E[2 * e] + a] + V[3 * (i64)E[2 * e + 1] + a]);
            double q = (mid - lo[a]) * scale;
            q = q >= 0 ? (q > CELLS ? CELLS : q) : 0.0;     // NaN -> 0 (no UB cast)
            code |= spread3((std::uint64_t)q) << a;
        }
        key[e] = code;
        idx[e] = e;
    }
    // LSD radix sort, 11-bit digits over the 33-bit codes (stable: ties keep index order)
    constexpr int RADIX = 1 << BITS;
    std::vector<i64> cnt(RADIX + 1);
    for (int pass = 0; pass < 3; ++pass) {
        const int shift = BITS * pass;
        std::fill(cnt.begin(), cnt.end(), 0);
        for (i64 e = 0; e < nE; ++e) ++cnt[((key[e] >> shift) & (RADIX - 1)) + 1];
        for (int d = 0; d < RADIX; ++d) cnt[d + 1] += cnt[d];
        for (i64 e = 0; e < nE; ++e) {
            const i64 dst = cnt[(key[e] >> shift) & (RADIX - 1)]++;
            key2[dst] = key[e];
            idx2[dst] = idx[e];
        }
        key.swap(key2);
        idx.swap(idx2);
    }
    for (i64 e = 0; e < nE; ++e) perm[e] = idx[e];
}

}  // namespace hhj

namespace hhj {

// face_metrics: per face the cross product c = (x1 - x0) x (x2 - x0) (#F,3), twice the
// area |c| (#F,) and the squared longest edge (#F,) (mesh.TriangleMesh._cross,
// face_double_areas and the l2max of mesh.zero_area_faces), one pass.
void face_metrics(const double* V, const i64* F, i64 nF, double* cross, double* dbl, double* l2max, int nt) {
#ifdef IGL_HHJ_OPENMP
#pragma omp parallel for schedule(static) num_threads(nt)
#endif
    for (i64 f = 0; f < nF; ++f) {
        const double* x[3] = {V + 3 * F[3 * f], V + 3 * F[3 * f + 1], V + 3 * F[3 * f + 2]};
        double ev[3][3];  // edge i = x_{i+2} - x_{i+1}
        for (int i = 0; i < 3; ++i)
            for (int a = 0; a < 3; ++a) ev[i][a] = x[(i + 2) % 3][a] - x[(i + 1) % 3][a];
        const double e1[3] = {x[1][0] - x[0][0], x[1][1] - x[0][1], x[1][2] - x[0][2]};
        const double e2[3] = {x[2][0] - x[0][0], x[2][1] - x[0][1], x[2][2] - x[0][2]};
        double* c = cross + 3 * f;
        cross3(e1, e2, c);
        dbl[f] = std::sqrt(dot3(c, c));
        double m = 0.0;
        for (int i = 0; i < 3; ++i) {
            const double l2 = dot3(ev[i], ev[i]);
            m = (l2 > m || std::isnan(l2)) ? l2 : m;
        }
        l2max[f] = m;
    }
}

// vertex_area_sums: s[v] = sum_{T ∋ v} c_T (#V,3) and a[v] = sum_{T ∋ v} |c_T| (#V,), the
// sums of mesh.TriangleMesh.folded_vertices; serial scatter in face order (deterministic).
void vertex_area_sums(const i64* F, i64 nF, i64 nV, const double* cross, const double* dbl, double* s,
                      double* a) {
    std::fill(s, s + 3 * nV, 0.0);
    std::fill(a, a + nV, 0.0);
    for (i64 f = 0; f < nF; ++f)
        for (int c = 0; c < 3; ++c) {
            const i64 v = F[3 * f + c];
            for (int k = 0; k < 3; ++k) s[3 * v + k] += cross[3 * f + k];
            a[v] += dbl[f];
        }
}

}  // namespace hhj

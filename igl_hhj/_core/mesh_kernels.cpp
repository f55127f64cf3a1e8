// Mesh topology in one pass (counting sort of the 3 #F half-edges by their
// smaller vertex, then by the larger): unique edges, face->edge, edge->face,
// incidence counts and half-edge signs, in the conventions of igl_hhj/mesh.py.
#include <algorithm>
#include <cmath>
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

// dihedral_magnitudes (tests/vertex_stage/reference_creases.py): |θ_e| = atan2(|ν_0 × ν_1|,
// ν_0 · ν_1) of the unit normals N (#F,3) of the two faces EF (#E,2) of every edge with
// exactly two faces (count (#E,) == 2), 0 on the others; the cross product's components in
// the order of np.cross.
void dihedral_magnitudes(const double* N, const i32* EF, const i8* count, i64 nE, double* theta, int nt) {
#pragma omp parallel for schedule(static) num_threads(nt)
    for (i64 e = 0; e < nE; ++e) {
        const i64 f0 = EF[2 * e], f1 = EF[2 * e + 1];
        if (count[e] != 2 || f0 < 0 || f1 < 0) { theta[e] = 0.0; continue; }
        const double* a = N + 3 * f0;
        const double* b = N + 3 * f1;
        double c = a[1] * b[2] - a[2] * b[1];
        double s = c * c;
        c = a[2] * b[0] - a[0] * b[2];
        s += c * c;
        c = a[0] * b[1] - a[1] * b[0];
        s += c * c;
        theta[e] = std::atan2(std::sqrt(s), a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
    }
}

// crease_cut (creases.cut_along): the sides of every vertex are the connected components of
// its corners, corners 3f+c of the two faces of an edge with join[e] != 0 being joined where
// they hold the same vertex (union-find over the 3#F corners; components labelled in the
// order of their smallest corner).  A vertex's primary side (largest incident area, ties to
// the lowest label) keeps its index; its other sides get #V, #V+1, ... in the order (vertex,
// -area, label).  Writes Fc (#F,3) (the cut faces, F's order and corner order) and appends
// the vertex of every extra side to `extra` (its row #V + k).
void crease_cut(const i64* F, i64 nF, i64 nV, const i32* EF, const i8* ELI, i64 nE,
                const unsigned char* join, const double* face_area, i64* Fc, std::vector<i64>& extra) {
    const i64 nC = 3 * nF;
    std::vector<i64> parent(nC);
    for (i64 q = 0; q < nC; ++q) parent[q] = q;
    auto find = [&](i64 q) {
        while (parent[q] != q) { parent[q] = parent[parent[q]]; q = parent[q]; }
        return q;
    };
    auto unite = [&](i64 p, i64 q) {
        p = find(p);
        q = find(q);
        if (p != q) parent[std::max(p, q)] = std::min(p, q);
    };
    static const int nxt[3] = {1, 2, 0}, prv[3] = {2, 0, 1};
    for (i64 e = 0; e < nE; ++e) {
        if (!join[e]) continue;
        const i64 f0 = EF[2 * e], f1 = EF[2 * e + 1];
        const int i0 = ELI[2 * e], i1 = ELI[2 * e + 1];
        // in f0 the edge runs x_{i0+1} -> x_{i0+2}, in f1 the other way
        unite(3 * f0 + nxt[i0], 3 * f1 + prv[i1]);
        unite(3 * f0 + prv[i0], 3 * f1 + nxt[i1]);
    }
    std::vector<i64> label(nC), root_label(nC, -1), comp_vertex, count(nV, 0);
    std::vector<double> area;
    for (i64 q = 0; q < nC; ++q) {
        const i64 r = find(q);
        if (root_label[r] < 0) {
            root_label[r] = (i64)comp_vertex.size();
            comp_vertex.push_back(F[q]);
            area.push_back(0.0);
            ++count[F[q]];
        }
        label[q] = root_label[r];
        area[label[q]] += face_area[q / 3];      // the sums of np.bincount over the corners
    }
    const i64 nS = (i64)comp_vertex.size();
    std::vector<i64> index(nS);
    for (i64 c = 0; c < nS; ++c) index[c] = comp_vertex[c];
    if (nS > nV) {
        // the sides of the vertices with several, by vertex (counting sort, labels ascending)
        std::vector<i64> start(nV + 1, 0);
        for (i64 c = 0; c < nS; ++c)
            if (count[comp_vertex[c]] > 1) ++start[comp_vertex[c] + 1];
        for (i64 v = 0; v < nV; ++v) start[v + 1] += start[v];
        std::vector<i64> sides(start[nV]), fill(start.begin(), start.end() - 1);
        for (i64 c = 0; c < nS; ++c)
            if (count[comp_vertex[c]] > 1) sides[fill[comp_vertex[c]]++] = c;
        for (i64 v = 0; v < nV; ++v) {
            if (start[v + 1] - start[v] < 2) continue;
            auto b = sides.begin() + start[v], en = sides.begin() + start[v + 1];
            std::stable_sort(b, en, [&](i64 x, i64 y) { return area[x] > area[y]; });
            for (auto it = b + 1; it != en; ++it) {
                index[*it] = nV + (i64)extra.size();
                extra.push_back(v);
            }
        }
    }
    for (i64 q = 0; q < nC; ++q) Fc[q] = index[label[q]];
}

}  // namespace hhj

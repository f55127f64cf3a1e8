// Mesh topology in one pass (counting sort of the 3 #F half-edges by their
// smaller vertex, then by the larger): unique edges, face->edge, edge->face,
// incidence counts and half-edge signs, in the conventions of igl_hhj/mesh.py.
#include <algorithm>

#include "core.hpp"

namespace hhj {

// topology: F (#F,3) -> edges (#E,2) lexicographic (min,max) pairs (the order of
// igl.unique_edge_map's uE), face_edges (#F,3) (edge opposite corner i),
// count (#E,), edge_faces / local_index (#E,2) (column 0: the face whose
// half-edge runs min->max), sign (#F,3) (+1 where the half-edge x_{i+1}->x_{i+2}
// runs min->max).  On non-manifold edges (count > 2) the last faces win.
void topology(const i64* F, i64 nF, i64 nV, Topology& T) {
    const i64 nH = 3 * nF;
    std::vector<i64> start(nV + 1, 0);
    auto ends = [&](i64 h, i64& lo, i64& hi) {
        const i64 f = h / 3, i = h % 3;
        const i64 a = F[3 * f + (i + 1) % 3], b = F[3 * f + (i + 2) % 3];
        lo = a < b ? a : b;
        hi = a < b ? b : a;
    };
    for (i64 h = 0; h < nH; ++h) { i64 lo, hi; ends(h, lo, hi); ++start[lo + 1]; }
    for (i64 v = 0; v < nV; ++v) start[v + 1] += start[v];
    std::vector<i64> order(nH), fill(start.begin(), start.end() - 1);
    std::vector<i64> hikey(nH);
    for (i64 h = 0; h < nH; ++h) {
        i64 lo, hi; ends(h, lo, hi);
        order[fill[lo]++] = h;
        hikey[h] = hi;
    }
    // sort each bucket by (hi, h): buckets are small (vertex valence)
    for (i64 v = 0; v < nV; ++v) {
        i64* b = order.data() + start[v];
        i64* e = order.data() + start[v + 1];
        std::sort(b, e, [&](i64 x, i64 y) { return hikey[x] != hikey[y] ? hikey[x] < hikey[y] : x < y; });
    }
    T.face_edges.assign(nH, 0);
    T.sign.assign(nH, 0.0);
    T.edges.clear();
    T.edges.reserve(nH);  // ~ #E * 2 = 2/3 nH * 2
    i64 nE = 0, prev_lo = -1, prev_hi = -1;
    for (i64 v = 0; v < nV; ++v) {
        for (i64 p = start[v]; p < start[v + 1]; ++p) {
            const i64 h = order[p];
            const i64 hi = hikey[h];
            if (v != prev_lo || hi != prev_hi) {
                T.edges.push_back(v);
                T.edges.push_back(hi);
                prev_lo = v; prev_hi = hi;
                ++nE;
            }
            T.face_edges[h] = nE - 1;
            const i64 f = h / 3, i = h % 3;
            T.sign[h] = (F[3 * f + (i + 1) % 3] == v) ? 1.0 : -1.0;
        }
    }
    T.n_edges = nE;
    T.count.assign(nE, 0);
    T.edge_faces.assign(2 * nE, -1);
    T.local_index.assign(2 * nE, -1);
    for (i64 h = 0; h < nH; ++h) {  // ascending (f, i): the last write wins, as in numpy
        const i64 e = T.face_edges[h];
        ++T.count[e];
        const int col = T.sign[h] < 0 ? 1 : 0;
        T.edge_faces[2 * e + col] = h / 3;
        T.local_index[2 * e + col] = h % 3;
    }
}

}  // namespace hhj

// The only file that knows nanobind: ndarrays in (C-contiguous float64 / int64, the
// topology maps int32 / int8 as TriangleMesh stores them,
// shapes checked in igl_hhj/kernels.py and again here where an index could go
// out of bounds), ndarrays out (owned by Python), the GIL released around work.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>
#include <nanobind/stl/optional.h>
#include <memory>
#include <optional>

#include "core.hpp"

namespace nb = nanobind;
using namespace nb::literals;
using hhj::i64;
using hhj::i32;
using hhj::i8;

template <class T>
using In = nb::ndarray<const T, nb::c_contig, nb::device::cpu>;
template <class T>
using Out = nb::ndarray<nb::numpy, T>;

template <class T>
static Out<T> to_numpy(std::vector<T>&& v, std::initializer_list<size_t> shape) {
    auto* heap = new std::vector<T>(std::move(v));
    nb::capsule owner(heap, [](void* p) noexcept { delete static_cast<std::vector<T>*>(p); });
    return Out<T>(heap->data(), shape, owner);
}

static void need(bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(what);
}

// block_pcg of the module, for either row-pointer type I of A and M
template <class I>
static nb::tuple block_pcg_py(In<I> Ap, In<std::int32_t> Ai, In<double> Ax, std::optional<In<I>> Mp,
                              std::optional<In<std::int32_t>> Mi, std::optional<In<double>> Mx,
                              std::optional<In<double>> dinv, nb::ndarray<double, nb::c_contig, nb::device::cpu> R,
                              double rtol, i64 maxiter,
                              i64 probe_iter, double max_predicted, std::optional<In<i64>> S,
                              std::optional<nb::callable> subdomain_solve, std::optional<nb::tuple> subdomain_ldl,
                              bool coupled) {
    need(R.ndim() == 2, "block_pcg: R must be (n, k)");
    const i64 n = R.shape(0);
    const int k = (int)R.shape(1);
    need(Ap.shape(0) == (size_t)n + 1, "block_pcg: indptr must have n + 1 entries");
    need(Mp.has_value() || (dinv.has_value() && dinv->shape(0) == (size_t)n),
         "block_pcg: need a preconditioner (CSR) or dinv (n,)");
    std::vector<double> X((size_t)n * k);
    hhj::PCGResult res;
    hhj::SubdomainSolve sub;
    if (S && (subdomain_ldl || subdomain_solve)) {
        sub.S = S->data();
        sub.nS = (i64)S->shape(0);
        for (i64 i = 0; i < sub.nS; ++i) need(sub.S[i] >= 0 && sub.S[i] < n, "block_pcg: S index out of range");
    }
    // keeps the factor's arrays alive for the native solve below
    std::optional<In<i64>> Lp, Li, perm;
    std::optional<In<double>> Lx, D;
    if (S && subdomain_ldl) {
        need(subdomain_ldl->size() == 5, "block_pcg: subdomain_ldl must be (Lp, Li, Lx, D, perm)");
        Lp = nb::cast<In<i64>>((*subdomain_ldl)[0]);
        Li = nb::cast<In<i64>>((*subdomain_ldl)[1]);
        Lx = nb::cast<In<double>>((*subdomain_ldl)[2]);
        D = nb::cast<In<double>>((*subdomain_ldl)[3]);
        perm = nb::cast<In<i64>>((*subdomain_ldl)[4]);
        const i64 nS = sub.nS;
        need(Lp->ndim() == 1 && Lp->shape(0) == (size_t)nS + 1 && D->shape(0) == (size_t)nS &&
             perm->shape(0) == (size_t)nS && Li->shape(0) == Lx->shape(0),
             "block_pcg: subdomain_ldl shapes do not match S");
        const i64* lp = Lp->data();
        need(lp[0] == 0 && lp[nS] == (i64)Li->shape(0), "block_pcg: subdomain_ldl Lp");
        for (i64 j = 0; j < nS; ++j) {
            need(lp[j] <= lp[j + 1], "block_pcg: subdomain_ldl Lp not monotone");
            for (i64 q = lp[j]; q < lp[j + 1]; ++q)
                need(Li->data()[q] > j && Li->data()[q] < nS, "block_pcg: subdomain_ldl L not strictly lower");
        }
        std::vector<unsigned char> seen(nS, 0);
        for (i64 i = 0; i < nS; ++i) {
            const i64 o = perm->data()[i];
            need(o >= 0 && o < nS && !seen[o], "block_pcg: subdomain_ldl perm is not a permutation");
            seen[o] = 1;
        }
        hhj::LDLFactor f;
        f.n = nS;
        f.Lp = lp;
        f.Li = Li->data();
        f.Lx = Lx->data();
        f.D = D->data();
        f.perm = perm->data();
        hhj::ldl_schedule(f);
        auto work = std::make_shared<std::vector<double>>((size_t)nS * k);
        auto fac = std::make_shared<const hhj::LDLFactor>(std::move(f));
        sub.solve = [fac, work, k](const double* rS, double* zS, int nt) {
            hhj::ldl_solve_block(*fac, k, rS, zS, work->data(), nt);
        };
    } else if (S && subdomain_solve) {
        const size_t nS = sub.nS, kk = k;
        nb::callable fn = *subdomain_solve;
        sub.solve = [fn, nS, kk](const double* rS, double* zS, int) {
            nb::gil_scoped_acquire gil;
            // rS is a scratch buffer: writable, so that solvers taking writable input accept it
            nb::ndarray<nb::numpy, double> a(const_cast<double*>(rS), {nS, kk});
            nb::ndarray<nb::numpy, double> b(zS, {nS, kk});
            // reference policy: the callee writes into zS itself (no copies)
            fn(nb::cast(a, nb::rv_policy::reference), nb::cast(b, nb::rv_policy::reference));
        };
    }
    {
        nb::gil_scoped_release nogil;
        hhj::ThreadBudget tb(n * k, hhj::PCG_MIN_WORK);
        res = hhj::block_pcg(n, k, Ap.data(), Ai.data(), Ax.data(),
                             Mp ? Mp->data() : nullptr, Mp ? Mi->data() : nullptr,
                             Mp ? Mx->data() : nullptr, dinv ? dinv->data() : nullptr,
                             R.data(), X.data(), rtol, maxiter, probe_iter, max_predicted, tb.nt,
                             sub.nS ? &sub : nullptr, coupled);
    }
    return nb::make_tuple(to_numpy(std::move(X), {(size_t)n, (size_t)k}), res.iterations, res.status,
                          res.relres);
}

NB_MODULE(_hhj_core, m) {
    m.doc() = "igl_hhj compiled core (use igl_hhj.kernels, not this module directly)";

    m.def("max_threads", []() {
#ifdef IGL_HHJ_OPENMP
        return omp_get_max_threads();
#else
        return 1;
#endif
    });
    m.def("set_num_threads", [](int n) {
#ifdef IGL_HHJ_OPENMP
        omp_set_num_threads(n < 1 ? 1 : n);
#else
        (void)n;
#endif
    });
    m.def("has_openmp", []() {
#ifdef IGL_HHJ_OPENMP
        return true;
#else
        return false;
#endif
    });

    m.def("heap_scope_enter", [](size_t threshold) {
        return hhj::heap_scope_enter(threshold);
    }, "mmap_threshold"_a);
    m.def("heap_scope_exit", []() {
        nb::gil_scoped_release release;     // malloc_trim walks the heap
        return hhj::heap_scope_exit();
    });
    m.def("heap_scope_depth", []() { return hhj::heap_scope_depth(); });

    m.def("topology", [](In<i64> F, i64 nV) {
        need(F.ndim() == 2 && F.shape(1) == 3, "F must be (#F, 3)");
        const i64 nF = F.shape(0);
        need(3 * nF < ((i64)1 << 32) && nV < ((i64)1 << 31),
             "topology: at most 1 431 655 765 faces and 2**31 - 1 vertices (int32 edge maps)");
        hhj::Topology T;
        {
            nb::gil_scoped_release nogil;
            hhj::ThreadBudget tb(0);
            hhj::topology(F.data(), nF, nV, T);
        }
        const size_t nE = T.n_edges, nf = nF;
        return nb::make_tuple(to_numpy(std::move(T.edges), {nE, 2}),
                              to_numpy(std::move(T.face_edges), {nf, 3}),
                              to_numpy(std::move(T.count), {nE}),
                              to_numpy(std::move(T.edge_faces), {nE, 2}),
                              to_numpy(std::move(T.local_index), {nE, 2}),
                              to_numpy(std::move(T.sign), {nf, 3}));
    }, "F"_a, "nV"_a);

    m.def("face_metrics", [](In<double> V, In<i64> F) {
        need(V.ndim() == 2 && V.shape(1) == 3 && F.ndim() == 2 && F.shape(1) == 3, "face_metrics: shapes");
        const i64 nF = F.shape(0), nV = V.shape(0);
        const i64* f = F.data();
        for (i64 q = 0; q < 3 * nF; ++q) need(f[q] >= 0 && f[q] < nV, "face_metrics: index out of range");
        std::vector<double> cross((size_t)nF * 3), dbl(nF), l2max(nF);
        {
            nb::gil_scoped_release nogil;
            hhj::ThreadBudget tb(nF);
            hhj::face_metrics(V.data(), F.data(), nF, cross.data(), dbl.data(), l2max.data(), tb.nt);
        }
        const size_t nf = nF;
        return nb::make_tuple(to_numpy(std::move(cross), {nf, 3}), to_numpy(std::move(dbl), {nf}),
                              to_numpy(std::move(l2max), {nf}));
    });

    m.def("vertex_area_sums", [](In<i64> F, i64 nV, In<double> cross, In<double> dbl) {
        const i64 nF = F.shape(0);
        need(cross.shape(0) == (size_t)nF && dbl.shape(0) == (size_t)nF, "vertex_area_sums: shapes");
        const i64* f = F.data();
        for (i64 q = 0; q < 3 * nF; ++q) need(f[q] >= 0 && f[q] < nV, "vertex_area_sums: index out of range");
        std::vector<double> s((size_t)nV * 3), a(nV);
        {
            nb::gil_scoped_release nogil;
            hhj::vertex_area_sums(F.data(), nF, nV, cross.data(), dbl.data(), s.data(), a.data());
        }
        return nb::make_tuple(to_numpy(std::move(s), {(size_t)nV, 3}), to_numpy(std::move(a), {(size_t)nV}));
    });

    m.def("dihedral_magnitudes", [](In<double> N, In<i32> EF, In<i8> count) {
        need(N.ndim() == 2 && N.shape(1) == 3 && EF.ndim() == 2 && EF.shape(1) == 2 &&
             count.shape(0) == EF.shape(0), "dihedral_magnitudes: shapes");
        const i64 nE = EF.shape(0), nF = N.shape(0);
        for (i64 q = 0; q < 2 * nE; ++q) need(EF.data()[q] < nF, "dihedral_magnitudes: edge_faces out of range");
        std::vector<double> theta(nE);
        {
            nb::gil_scoped_release nogil;
            hhj::ThreadBudget tb(nE, 50000);
            hhj::dihedral_magnitudes(N.data(), EF.data(), count.data(), nE, theta.data(), tb.nt);
        }
        return to_numpy(std::move(theta), {(size_t)nE});
    });

    m.def("crease_cut", [](In<i64> F, i64 nV, In<i32> EF, In<i8> ELI, In<std::uint8_t> join, In<double> area) {
        need(F.ndim() == 2 && F.shape(1) == 3 && EF.ndim() == 2 && EF.shape(1) == 2 && ELI.ndim() == 2 &&
             ELI.shape(1) == 2, "crease_cut: shapes");
        const i64 nF = F.shape(0), nE = EF.shape(0);
        need(ELI.shape(0) == (size_t)nE && join.shape(0) == (size_t)nE && area.shape(0) == (size_t)nF,
             "crease_cut: join (#E,), area (#F,)");
        for (i64 q = 0; q < 3 * nF; ++q) need(F.data()[q] >= 0 && F.data()[q] < nV, "crease_cut: F out of range");
        for (i64 e = 0; e < nE; ++e)
            if (join.data()[e])
                for (int s = 0; s < 2; ++s)
                    need(EF.data()[2 * e + s] >= 0 && EF.data()[2 * e + s] < nF && ELI.data()[2 * e + s] >= 0 &&
                             ELI.data()[2 * e + s] < 3,
                         "crease_cut: a joined edge needs two faces");
        std::vector<i64> Fc((size_t)nF * 3), extra;
        {
            nb::gil_scoped_release nogil;
            hhj::crease_cut(F.data(), nF, nV, EF.data(), ELI.data(), nE, join.data(), area.data(), Fc.data(), extra);
        }
        const size_t k = extra.size();
        return nb::make_tuple(to_numpy(std::move(Fc), {(size_t)nF, 3}), to_numpy(std::move(extra), {k}));
    });

    m.def("edge_morton_order", [](In<double> V, In<i32> E) {
        need(V.ndim() == 2 && V.shape(1) == 3 && E.ndim() == 2 && E.shape(1) == 2, "edge_morton_order: shapes");
        const i64 nE = E.shape(0);
        std::vector<i64> perm(nE);
        {
            nb::gil_scoped_release nogil;
            hhj::ThreadBudget tb(0);
            hhj::edge_morton_order(V.data(), V.shape(0), E.data(), nE, perm.data());
        }
        return to_numpy(std::move(perm), {(size_t)nE});
    });

    m.def("hhj_system", [](In<double> V, In<i64> F, In<i32> FE, In<i32> EF, In<i8> ELI,
                           std::optional<In<unsigned char>> fixed, bool schwarz) {
        const i64 nF = F.shape(0), nE = EF.shape(0);
        need(FE.shape(0) == (size_t)nF && ELI.shape(0) == (size_t)nE, "hhj_system: inconsistent shapes");
        need(!fixed || fixed->shape(0) == (size_t)nE, "hhj_system: fixed must be (#E,)");
        need(nE < ((i64)1 << 31), "hhj_system: at most 2**31 - 1 edges");
        std::vector<std::int32_t> cols((size_t)nE * 5);
        std::vector<double> A((size_t)nE * 5), M, sin_min(nF);
        i64 n_jacobi = 0;
        {
            nb::gil_scoped_release nogil;
            hhj::ThreadBudget tb(nF);
            std::vector<double> Aloc((size_t)nF * 9);
            hhj::local_mass(V.data(), F.data(), nF, Aloc.data(), sin_min.data());
            hhj::assemble_ell(Aloc.data(), FE.data(), EF.data(), ELI.data(), nE, cols.data(), A.data(), tb.nt);
            if (schwarz) {
                std::vector<double> diag(nE);
                for (i64 e = 0; e < nE; ++e) diag[e] = A[5 * e];
                // the face inverses overwrite the local blocks (memory: one #F x 9 buffer)
                n_jacobi = hhj::face_schwarz(Aloc.data(), diag.data(), FE.data(),
                                             fixed ? fixed->data() : nullptr, nF, Aloc.data(), tb.nt);
                M.resize((size_t)nE * 5);
                hhj::assemble_ell(Aloc.data(), FE.data(), EF.data(), ELI.data(), nE, nullptr, M.data(), tb.nt);
            }
        }
        const size_t ne = nE;
        nb::object Mout = nb::none();
        if (schwarz) Mout = nb::cast(to_numpy(std::move(M), {ne, 5}));
        return nb::make_tuple(to_numpy(std::move(cols), {ne, 5}), to_numpy(std::move(A), {ne, 5}),
                              Mout, n_jacobi, to_numpy(std::move(sin_min), {(size_t)nF}));
    }, "V"_a, "F"_a, "FE"_a, "EF"_a, "ELI"_a, "fixed"_a.none(), "schwarz"_a);

    m.def("jump_apply", [](In<double> V, In<i64> F, In<i32> EF, In<i8> ELI, In<double> W) {
        const i64 nF = F.shape(0), nE = EF.shape(0);
        need(W.ndim() == 2 && W.shape(0) == V.shape(0), "jump_apply: W must be (#V, k)");
        const int k = (int)W.shape(1);
        std::vector<double> out((size_t)nE * k);
        {
            nb::gil_scoped_release nogil;
            hhj::ThreadBudget tb(nF);
            hhj::jump_apply(V.data(), F.data(), nF, EF.data(), ELI.data(), nE, W.data(), k, out.data(), tb.nt);
        }
        return to_numpy(std::move(out), {(size_t)nE, (size_t)k});
    });

    // int64 row pointers (scipy matrices) and int32 ones (the HHJ system: memory)
    m.def("block_pcg", &block_pcg_py<i64>);
    m.def("block_pcg32", &block_pcg_py<i32>);

    m.def("envelope_ldl_solve", [](In<i64> Ap, In<std::int32_t> Ai, In<double> Ax, In<double> R,
                                   double resid_rtol) {
        need(R.ndim() == 2, "envelope_ldl_solve: R must be (n, k)");
        const i64 n = R.shape(0);
        const int k = (int)R.shape(1);
        need(Ap.shape(0) == (size_t)n + 1 && Ai.shape(0) == Ax.shape(0) && Ap.data()[0] == 0 &&
             Ap.data()[n] == (i64)Ai.shape(0), "envelope_ldl_solve: CSR arrays do not match R");
        for (i64 i = 0; i < n; ++i) need(Ap.data()[i] <= Ap.data()[i + 1], "envelope_ldl_solve: indptr not monotone");
        std::vector<double> X((size_t)n * k);
        int status;
        {
            nb::gil_scoped_release nogil;
            status = hhj::envelope_ldl_solve(n, k, Ap.data(), Ai.data(), Ax.data(), R.data(), X.data(), resid_rtol);
        }
        return nb::make_tuple(to_numpy(std::move(X), {(size_t)n, (size_t)k}), status);
    });

    m.def("shape_operator_faces", [](In<double> V, In<i64> F, In<i32> FE, In<double> s) {
        const i64 nF = F.shape(0);
        need(s.ndim() == 2 && s.shape(1) == 3, "shape_operator_faces: s must be (#E, 3)");
        std::vector<double> S((size_t)nF * 9);
        {
            nb::gil_scoped_release nogil;
            hhj::ThreadBudget tb(nF);
            hhj::shape_operator_faces(V.data(), F.data(), FE.data(), nF, s.data(), S.data(), tb.nt);
        }
        return to_numpy(std::move(S), {(size_t)nF, 3, 3});
    });

    m.def("face_tensors", [](In<double> V, In<i64> F, In<i32> FE, In<double> s) {
        const i64 nF = F.shape(0);
        need(s.ndim() == 2, "face_tensors: s must be (#E, k)");
        const int k = (int)s.shape(1);
        std::vector<double> H((size_t)nF * k * 9);
        {
            nb::gil_scoped_release nogil;
            hhj::ThreadBudget tb(nF);
            hhj::face_tensors(V.data(), F.data(), FE.data(), nF, s.data(), k, H.data(), tb.nt);
        }
        return to_numpy(std::move(H), {(size_t)nF, (size_t)k, 3, 3});
    });

    m.def("principal_2x2", [](In<double> S, In<double> N) {
        const i64 n = N.shape(0);
        need(S.shape(0) == (size_t)n, "principal_2x2: shapes");
        std::vector<double> PD1((size_t)n * 3), PD2((size_t)n * 3), PV1(n), PV2(n);
        {
            nb::gil_scoped_release nogil;
            hhj::ThreadBudget tb(n);
            hhj::principal_2x2(S.data(), N.data(), n, PD1.data(), PD2.data(), PV1.data(), PV2.data(), tb.nt);
        }
        const size_t nn = n;
        return nb::make_tuple(to_numpy(std::move(PD1), {nn, 3}), to_numpy(std::move(PD2), {nn, 3}),
                              to_numpy(std::move(PV1), {nn}), to_numpy(std::move(PV2), {nn}));
    });

    m.def("recovery_weights", [](In<double> V, In<i64> F, In<i32> FE, In<i32> EF, double floor) {
        const i64 nF = F.shape(0), nE = EF.shape(0);
        need(FE.shape(0) == (size_t)nF && FE.shape(1) == 3 && EF.ndim() == 2 && EF.shape(1) == 2,
             "recovery_weights: shapes");
        std::vector<double> w(nF);
        {
            nb::gil_scoped_release nogil;
            hhj::ThreadBudget tb(nF);
            hhj::recovery_weights(V.data(), F.data(), nF, FE.data(), EF.data(), nE, floor, w.data(), tb.nt);
        }
        return to_numpy(std::move(w), {(size_t)nF});
    });

    m.def("intrinsic_patch_recovery", [](In<double> V, In<i64> F, In<double> S, In<double> N, In<double> w,
                                         In<unsigned char> ref, double h) {
        const i64 nF = F.shape(0), nV = V.shape(0);
        need(S.shape(0) == (size_t)nF && N.shape(0) == (size_t)nV && w.shape(0) == (size_t)nF &&
             ref.shape(0) == (size_t)nV, "intrinsic_patch_recovery: shapes");
        std::vector<double> X((size_t)nV * 3), rough(nV);
        {
            nb::gil_scoped_release nogil;
            hhj::ThreadBudget tb(nF);
            hhj::intrinsic_patch_recovery(V.data(), F.data(), nF, nV, S.data(), N.data(), w.data(), ref.data(),
                                          h, X.data(), rough.data(), tb.nt);
        }
        return nb::make_tuple(to_numpy(std::move(X), {(size_t)nV, 3}), to_numpy(std::move(rough), {(size_t)nV}));
    });

    m.def("vertex_components", [](In<i32> E, i64 nV) {
        need(E.ndim() == 2 && E.shape(1) == 2, "vertex_components: E must be (#E, 2)");
        const i64 nE = E.shape(0);
        for (i64 q = 0; q < 2 * nE; ++q) need(E.data()[q] >= 0 && E.data()[q] < nV, "vertex_components: index out of range");
        std::vector<std::int32_t> label;
        i64 n;
        {
            nb::gil_scoped_release nogil;
            n = hhj::vertex_groups(nV, E.data(), nE, label);
        }
        return nb::make_tuple(to_numpy(std::move(label), {(size_t)nV}), n);
    });

    m.def("transport_phases", [](In<double> N, In<i32> E) {
        const i64 nV = N.shape(0), nE = E.shape(0);
        need(N.ndim() == 2 && N.shape(1) == 3 && E.ndim() == 2 && E.shape(1) == 2, "transport_phases: shapes");
        for (i64 q = 0; q < 2 * nE; ++q) need(E.data()[q] >= 0 && E.data()[q] < nV, "transport_phases: index out of range");
        std::vector<double> ph((size_t)nE * 2);
        {
            nb::gil_scoped_release nogil;
            hhj::ThreadBudget tb(nE);
            hhj::transport_phases(N.data(), nV, E.data(), nE, ph.data(), tb.nt);
        }
        return to_numpy(std::move(ph), {(size_t)nE, 2});
    });

    m.def("boundary_normal_fits", [](In<double> X, In<i32> E, In<i64> verts, int rings, In<double> N0) {
        const i64 nV = X.shape(0), nE = E.shape(0), n = verts.shape(0);
        need(X.shape(1) == 3 && E.shape(1) == 2 && N0.shape(0) == (size_t)n && N0.shape(1) == 3,
             "boundary_normal_fits: shapes");
        need(rings >= 1, "boundary_normal_fits: rings >= 1");
        for (i64 q = 0; q < 2 * nE; ++q) need(E.data()[q] >= 0 && E.data()[q] < nV, "boundary_normal_fits: E out of range");
        for (i64 q = 0; q < n; ++q) need(verts.data()[q] >= 0 && verts.data()[q] < nV, "boundary_normal_fits: verts out of range");
        std::vector<double> N((size_t)n * 3);
        {
            nb::gil_scoped_release nogil;
            hhj::ThreadBudget tb(n * 64);
            hhj::boundary_normal_fits(X.data(), nV, E.data(), nE, verts.data(), n, rings, N0.data(), N.data(), tb.nt);
        }
        return to_numpy(std::move(N), {(size_t)n, 3});
    });

    m.def("adaptive_radius", [](In<double> V, In<i64> F, In<double> P, In<double> rough, double radius,
                                double gain, double power, double lo, double hi) {
        const i64 nF = F.shape(0), nV = V.shape(0);
        need(P.shape(0) == (size_t)nV && P.shape(1) == 3 && rough.shape(0) == (size_t)nV, "adaptive_radius: shapes");
        std::vector<double> r(nF);
        {
            nb::gil_scoped_release nogil;
            hhj::ThreadBudget tb(nF);
            hhj::adaptive_radius(V.data(), F.data(), nF, nV, P.data(), rough.data(), radius, gain, power, lo, hi,
                                 r.data(), tb.nt);
        }
        return to_numpy(std::move(r), {(size_t)nF});
    });

    m.def("intrinsic_smoothing", [](In<double> V, In<i64> F, In<i32> E, In<i32> EF, In<i8> ELI, In<double> C,
                                    In<double> mass, In<double> phase, In<double> rough,
                                    nb::ndarray<double, nb::c_contig, nb::device::cpu> X, double radius,
                                    double per_radius, double pilot_radius, double pilot_rtol, double gain,
                                    double power, double lo, double hi, int steps, std::vector<double> binom,
                                    double rtol, i64 maxiter) {
        const i64 nV = X.shape(0), nE = E.shape(0), nF = F.shape(0);
        need(V.shape(0) == (size_t)nV && X.ndim() == 2 && X.shape(1) == 3 && mass.shape(0) == (size_t)nV &&
             rough.shape(0) == (size_t)nV, "intrinsic_smoothing: X, mass, rough");
        need(EF.shape(0) == (size_t)nE && ELI.shape(0) == (size_t)nE && C.ndim() == 2 && C.shape(0) == (size_t)nF &&
             C.shape(1) == 3 && phase.ndim() == 2 && phase.shape(0) == (size_t)nE && phase.shape(1) == 2,
             "intrinsic_smoothing: topology shapes");
        need(nV < ((i64)1 << 31), "intrinsic_smoothing: at most 2**31 - 1 vertices");
        need(steps >= 1, "intrinsic_smoothing: steps >= 1");
        for (i64 q = 0; q < 3 * nF; ++q) need(F.data()[q] >= 0 && F.data()[q] < nV, "intrinsic_smoothing: F out of range");
        for (i64 q = 0; q < 2 * nE; ++q) need(E.data()[q] >= 0 && E.data()[q] < nV, "intrinsic_smoothing: E out of range");
        for (i64 q = 0; q < 2 * nE; ++q)
            need(EF.data()[q] < nF && ELI.data()[q] < 3, "intrinsic_smoothing: edge_faces out of range");
        std::vector<double> r(nF);
        int status;
        i64 iterations = 0, ngroups = 0;
        {
            nb::gil_scoped_release nogil;
            hhj::ThreadBudget tb(nV);
            // below the two-thread sweeps' size, h and z as two tasks (the same bits)
            const int tasks = tb.nt == 1 && tb.free_threads >= 2 && nV >= hhj::SMOOTHING_TASK_MIN ? 2 : 1;
            status = hhj::intrinsic_smoothing(V.data(), F.data(), nF, nV, E.data(), nE, EF.data(), ELI.data(),
                                              C.data(), mass.data(), phase.data(), rough.data(), radius,
                                              per_radius, pilot_radius, pilot_rtol, gain, power, lo, hi, steps,
                                              binom, rtol, maxiter, X.data(), r.data(), tb.nt, &iterations,
                                              &ngroups, tasks);
        }
        return nb::make_tuple(status, iterations, ngroups, to_numpy(std::move(r), {(size_t)nF}));
    });

    m.def("principal_hz", [](In<double> X, In<double> N) {
        const i64 n = X.shape(0);
        need(X.ndim() == 2 && X.shape(1) == 3 && N.ndim() == 2 && N.shape(0) == (size_t)n && N.shape(1) == 3,
             "principal_hz: X and N must be (n, 3)");
        std::vector<double> PD1((size_t)n * 3), PD2((size_t)n * 3), PV1(n), PV2(n);
        {
            nb::gil_scoped_release nogil;
            hhj::ThreadBudget tb(n);
            hhj::principal_hz(X.data(), N.data(), n, PD1.data(), PD2.data(), PV1.data(), PV2.data(), tb.nt);
        }
        const size_t nn = n;
        return nb::make_tuple(to_numpy(std::move(PD1), {nn, 3}), to_numpy(std::move(PD2), {nn, 3}),
                              to_numpy(std::move(PV1), {nn}), to_numpy(std::move(PV2), {nn}));
    });

    m.def("dropin_small", [](In<double> V, In<i64> F, In<double> N, In<double> cot, nb::tuple checks,
                             nb::tuple smoothing, std::vector<double> binom) {
        need(V.ndim() == 2 && V.shape(1) == 3 && F.ndim() == 2 && F.shape(1) == 3, "dropin_small: V, F shapes");
        const i64 nV = V.shape(0), nF = F.shape(0);
        need(N.ndim() == 2 && N.shape(0) == (size_t)nV && N.shape(1) == 3 && cot.ndim() == 2 &&
             cot.shape(0) == (size_t)nF && cot.shape(1) == 3, "dropin_small: N, cot shapes");
        need(nV > 0 && nF > 0 && nF < ((i64)1 << 24), "dropin_small: mesh size");
        for (i64 q = 0; q < 3 * nF; ++q) need(F.data()[q] >= 0 && F.data()[q] < nV, "dropin_small: F out of range");
        need(checks.size() == 11 && smoothing.size() == 10, "dropin_small: parameter tuples");
        hhj::SmallParams p;
        p.degenerate_rtol = nb::cast<double>(checks[0]);
        p.min_mesh_size = nb::cast<double>(checks[1]);
        p.folded_rtol = nb::cast<double>(checks[2]);
        p.quality_floor = nb::cast<double>(checks[3]);
        p.direct_rtol = nb::cast<double>(checks[4]);
        p.max_edges = nb::cast<i64>(checks[5]);
        p.estimate = nb::cast<bool>(checks[6]);
        p.fit_rings = nb::cast<int>(checks[7]);
        p.side_dot_min = nb::cast<double>(checks[8]);
        p.band_rings = nb::cast<int>(checks[9]);
        p.band_factor = nb::cast<double>(checks[10]);
        need(p.fit_rings >= 1 && p.band_rings >= 0, "dropin_small: rings");
        p.radius = nb::cast<double>(smoothing[0]);
        p.per_radius = nb::cast<double>(smoothing[1]);
        p.pilot_radius = nb::cast<double>(smoothing[2]);
        p.smoothing_rtol = nb::cast<double>(smoothing[3]);
        p.gain = nb::cast<double>(smoothing[4]);
        p.power = nb::cast<double>(smoothing[5]);
        p.lo = nb::cast<double>(smoothing[6]);
        p.hi = nb::cast<double>(smoothing[7]);
        p.steps = nb::cast<int>(smoothing[8]);
        p.maxiter = nb::cast<i64>(smoothing[9]);
        p.binom = std::move(binom);
        need(p.steps >= 1, "dropin_small: steps >= 1");
        std::vector<double> PD1((size_t)nV * 3), PD2((size_t)nV * 3), PV1(nV), PV2(nV);
        std::vector<unsigned char> bad(nV);
        int status;
        {
            nb::gil_scoped_release nogil;
            hhj::ThreadBudget tb(0);
            status = hhj::dropin_small(V.data(), nV, F.data(), nF, N.data(), cot.data(), p, PD1.data(), PD2.data(),
                                       PV1.data(), PV2.data(), bad.data());
        }
        const size_t nn = nV;
        return nb::make_tuple(status, to_numpy(std::move(PD1), {nn, 3}), to_numpy(std::move(PD2), {nn, 3}),
                              to_numpy(std::move(PV1), {nn}), to_numpy(std::move(PV2), {nn}),
                              to_numpy(std::move(bad), {nn}));
    });
}

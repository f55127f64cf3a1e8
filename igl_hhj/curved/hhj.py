"""The surface HHJ space of degree r on curved Lagrange triangles and its two
matrices (Walker 2023, §3–§5; eq. 3.8, 3.9, 3.14–3.16, 4.3, 4.7).

Space.  On a curved triangle with element map X: T̂ → T^m, J = ∂X/∂ξ (3×2),
G = JᵀJ, the HHJ functions are the Piola images (eq. 3.14)

    σ = J Σ̂ Jᵀ / det G,    Σ̂ ∈ P_r(T̂; S²) (symmetric 2×2 polynomials),

symmetric and tangential (σν = 0).  Their normal–normal trace on local edge j
(eq. 3.16) is ``σ^nn = (t̂_j^⊥ᵀ Σ̂ t̂_j^⊥) / |J t̂_j|²`` with t̂_j the reference
edge vector and t̂_j^⊥ its outward normal; |J t̂_j| = |dX/ds| is the speed of
the shared curved edge, the same from both sides.  With the reference basis

    Σ̂ = Σ_j p_j(ξ) S_j,   S_j = sym(t̂_a ⊗ t̂_b) / ((t̂_j^⊥·t̂_a)(t̂_j^⊥·t̂_b)),

(t̂_i^⊥ᵀ S_j t̂_i^⊥ = δ_ij) the trace on edge j is p_j|_E / |J t̂_j|², so the
nn-continuity (each element with its own conormal) is the continuity of the
scalar P_r polynomial p_j along edge j.  DOFs: p_j / l_j² (l_j the chord
length of edge j, so that a DOF is ≈ the nn-value itself, and exactly the flat
basis of :mod:`igl_hhj.hhj` for m = 1) at the r + 1 equispaced nodes of edge j
(shared by the two faces of the edge; r = 0: the midpoint), and at the P_r
nodes off edge j (interior to the face).  dim = (r+1)#E + 3 (dim P_r - r - 1) #F.
The face-interior DOFs couple only within their face and are condensed out
before the solve (:meth:`CurvedHHJ.solve`).

Matrices (reference-coordinate forms, w = quadrature weights on T̂):

* A[φ, ψ] = ∫_T σ_φ : σ_ψ dS = Σ_q w tr(Φ̂ G Ψ̂ G) / det G^{3/2}            (eq. 3.9)
* B[φ, v] = b_h(φ, v) = -Σ_T ∫_T φ : hess_Γ v + Σ_T ∫_∂T φ^nn n·∇_Γ v     (eq. 3.8)
  with φ : hess_Γ v dS = tr(Φ̂ (∂²v - Γ^γ ∂_γ v)) / √det G dξ (Γ^γ_{αβ} the
  Christoffel symbols G^{γδ} X_δ·X_{αβ}) and, on edge j,
  φ^nn n·∇_Γ v ds = p_j √det G / |J t̂_j|² (G⁻¹ t̂_j^⊥)·∇_ξ v dt.
  Summing each element's one-sided edge term gives the conormal jumps.
"""
from __future__ import annotations

from functools import cached_property

import numpy as np
import scipy.sparse as sp

from ..solvers import solve_spd

from .reference import (CORNERS, EDGE_OUTWARD, EDGE_TANGENTS, lagrange_basis, lagrange_nodes,
                        line_quadrature, triangle_quadrature)
from .surface import ElementGeometry, LagrangeSurface

__all__ = ["CurvedHHJ", "reference_tensors"]

CHUNK = 4096   # faces per vectorised batch (bounds the memory of the (faces × points × basis) arrays)


def _sym_outer(u, v):
    uv = np.outer(u, v)
    return 0.5 * (uv + uv.T)


def reference_tensors():
    """(3, 2, 2) the reference tensors S_j (dual to the reference edge normals)."""
    S = np.empty((3, 2, 2))
    for j in range(3):
        a, b = (j + 1) % 3, (j + 2) % 3
        ta, tb = EDGE_TANGENTS[a], EDGE_TANGENTS[b]
        S[j] = _sym_outer(ta, tb) / ((EDGE_OUTWARD[j] @ ta) * (EDGE_OUTWARD[j] @ tb))
    return S


def _scalar_nodes_on_edge(r):
    """For each local edge j: list of (scalar P_r node index, edge slot) of the nodes on edge j,
    slot 0..r counted from corner j+1 to corner j+2; and the list of the other node indices."""
    nodes = lagrange_nodes(r)
    on, off = [], []
    for j in range(3):
        A, B = CORNERS[(j + 1) % 3], CORNERS[(j + 2) % 3]
        d = B - A
        lst, rest = [], []
        for i, x in enumerate(nodes):
            rel = x - A
            cross = d[0] * rel[1] - d[1] * rel[0]
            if r > 0 and abs(cross) < 1e-12:
                s = (rel @ d) / (d @ d)
                lst.append((i, int(round(s * r))))
            else:
                rest.append(i)
        if r == 0:
            lst, rest = [(0, 0)], []
        on.append(sorted(lst, key=lambda p: p[1]))
        off.append(rest)
    return on, off


class CurvedHHJ:
    """HHJ space of degree ``r`` (default m − 1) on a :class:`LagrangeSurface`.

    Attributes
    ----------
    n_dofs : int
    dofs : (#F, nb) int64 global DOF of each local basis function
        (nb = 3 dim P_r; local function k = (j, i): p_j = L_i, i.e.
        Σ̂_k = L_i(ξ) S_j, ordered j-major).
    edge_dofs : (#E, r+1) global DOFs of each unique edge, from its lower to its higher vertex.
    """

    def __init__(self, surface: LagrangeSurface, degree=None, quad_degree=None):
        if not isinstance(surface, LagrangeSurface):
            raise TypeError(f"surface must be a LagrangeSurface, got {type(surface).__name__}")
        m = surface.order
        r = m - 1 if degree is None else int(degree)
        if r < 0 or r > 2:
            raise ValueError(f"HHJ degree must be 0, 1 or 2, got {r}")
        self.surface, self.r, self.m = surface, r, m
        self.quad_degree = int(quad_degree) if quad_degree is not None else 2 * r + 2 * m + 2
        self.scalar = lagrange_basis(r) if r > 0 else None
        self.nr = 1 if r == 0 else len(lagrange_nodes(r))
        self.S = reference_tensors()
        self.nb = 3 * self.nr
        self._number_dofs()

    # ---------------------------------------------------------------- DOFs
    def _number_dofs(self):
        mesh = self.surface.mesh
        r, nr, nF, nE = self.r, self.nr, mesh.n_faces, mesh.n_edges
        on, off = _scalar_nodes_on_edge(r)
        self.edge_dofs = np.arange(nE * (r + 1)).reshape(nE, r + 1)
        n_int = len(off[0])
        dofs = np.empty((nF, 3, nr), dtype=np.int64)
        Fc = mesh.F
        base = nE * (r + 1)
        for j in range(3):                     # 3 local edges: vectorised over faces
            e = mesh.face_edges[:, j]
            fwd = mesh.edges[e, 0] == Fc[:, (j + 1) % 3]
            for (i, slot) in on[j]:
                gslot = np.where(fwd, slot, r - slot)
                dofs[:, j, i] = self.edge_dofs[e, gslot]
            for k, i in enumerate(off[j]):
                dofs[:, j, i] = base + np.arange(nF) * 3 * n_int + j * n_int + k
        self.dofs = dofs.reshape(nF, self.nb)
        self.n_dofs = base + nF * 3 * n_int
        self.is_edge_dof = np.zeros(self.n_dofs, dtype=bool)
        self.is_edge_dof[:base] = True
        # basis scaling: functions of edge j carry the squared chord length l_j², so that
        # each DOF is ≈ the nn-trace itself (exactly it for m = 1: the flat basis of hhj.py)
        self.scale = np.repeat(mesh.edge_lengths ** 2, nr, axis=1)       # (#F, nb)
        edge_local = np.zeros((3, nr), dtype=bool)
        for j in range(3):
            for (i, _slot) in on[j]:
                edge_local[j, i] = True
        self.local_edge = np.flatnonzero(edge_local.ravel())             # local functions with edge DOFs
        self.local_interior = np.flatnonzero(~edge_local.ravel())        # face-interior DOFs
        self.n_edge_dofs = base

    def reference_basis(self, xi):
        """(q, nb, 2, 2) reference tensors Σ̂_k(ξ) = L_i(ξ) S_j."""
        L = np.ones((len(xi), 1)) if self.r == 0 else self.scalar.values(xi)      # (q, nr)
        return np.einsum("qi,jab->qjiab", L, self.S).reshape(len(xi), self.nb, 2, 2)

    # ---------------------------------------------------------------- evaluation
    def tensors(self, coeffs, faces, bary):
        """Evaluate σ = J Σ̂ Jᵀ / det G at points for DOF vectors ``coeffs`` (n_dofs, k).

        Returns (n, k, 3, 3)."""
        g = self.surface.geometry(faces, bary)
        faces = np.asarray(faces, dtype=np.int64)
        xi = np.asarray(bary, float)[:, 1:]
        Sig = self._per_point_basis(xi)                              # (n, nb, 2, 2)
        c = np.asarray(coeffs)[self.dofs[faces]] * self.scale[faces][:, :, None]   # (n, nb, k)
        Sh = np.einsum("nbk,nbde->nkde", c, Sig)
        J = g.J[:, 0][:, None]                                       # (n, 1, 3, 2)
        return (J @ Sh @ J.swapaxes(-1, -2)) / g.detG[:, 0, None, None, None]

    def _per_point_basis(self, xi):
        L = np.ones((len(xi), 1)) if self.r == 0 else self.scalar.values(xi)
        return np.einsum("qi,jab->qjiab", L, self.S).reshape(len(xi), self.nb, 2, 2)

    def nn_trace(self, coeffs, faces, local_edge, t):
        """σ^nn = n_fᵀ σ n_f on local edge ``local_edge`` of each face at edge parameter
        ``t`` (from corner j+1 to j+2), with each face's own conormal n_f (for tests).

        Returns (n, k)."""
        faces = np.asarray(faces, dtype=np.int64)
        j = np.asarray(local_edge)
        A, B = CORNERS[(j + 1) % 3], CORNERS[(j + 2) % 3]
        xi = A + np.asarray(t)[:, None] * (B - A)
        bary = np.column_stack([1 - xi.sum(1), xi])
        sig = self.tensors(coeffs, faces, bary)
        n = self.conormals(faces, j, xi)
        return np.einsum("ni,nkij,nj->nk", n, sig, n)

    def conormals(self, faces, j, xi):
        """(n, 3) unit outward conormals of local edge j at reference points xi (n, 2)."""
        bary = np.column_stack([1 - xi.sum(1), xi])
        g = self.surface.geometry(faces, bary)
        a = np.einsum("nde,ne->nd", g.Ginv[:, 0], EDGE_OUTWARD[j])
        n = np.einsum("nkd,nd->nk", g.J[:, 0], a)
        return n / np.linalg.norm(n, axis=1, keepdims=True)

    # ---------------------------------------------------------------- assembly
    @cached_property
    def matrices(self):
        """(A, B): A (n_dofs × n_dofs, SPD) and B (n_dofs × #nodes), sparse CSR."""
        surf = self.surface
        xi, w = triangle_quadrature(self.quad_degree)
        Sig = self.reference_basis(xi)                               # (q, nb, 2, 2)
        tg, wg = line_quadrature(self.r + self.m + 2)
        # per local edge: reference points, basis nn-factor, tangent / outward normal
        edge_xi, edge_nn = [], []
        for j in range(3):
            A0, B0 = CORNERS[(j + 1) % 3], CORNERS[(j + 2) % 3]
            exi = A0[None] + tg[:, None] * (B0 - A0)[None]
            Se = self.reference_basis(exi)
            edge_xi.append(exi)
            edge_nn.append(np.einsum("d,gbde,e->gb", EDGE_OUTWARD[j], Se, EDGE_OUTWARD[j]))
        nb, nn_ = self.nb, surf.elements.shape[1]
        rowsA, colsA, valsA, rowsB, colsB, valsB = [], [], [], [], [], []
        ie, ii = self.local_edge, self.local_interior
        cond_vals, Aii_inv, Aie = [], [], []
        for f0 in range(0, surf.n_faces, CHUNK):                      # batches of faces, not a per-element loop
            fs = slice(f0, min(f0 + CHUNK, surf.n_faces))
            X = surf.nodes[surf.elements[fs]]
            g = ElementGeometry(X, xi, self.m, second=True)
            nf, q = g.detG.shape
            GS = g.G[:, :, None] @ Sig[None]                           # (f, q, nb, 2, 2): G Σ̂_b
            wA = w[None] / g.detG ** 1.5
            P = (GS * wA[:, :, None, None, None]).transpose(0, 2, 1, 3, 4).reshape(nf, nb, 4 * q)
            Q = GS.swapaxes(-1, -2).transpose(0, 2, 1, 3, 4).reshape(nf, nb, 4 * q)
            Aloc = P @ Q.swapaxes(1, 2)                                # Σ_q w tr(GΣ̂_b GΣ̂_c)/detG^1.5
            # Christoffel symbols Γ^γ_{αβ} = G^{γδ} X_δ · X_{αβ}, covariant Hessian of N_a
            Gam = (g.Ginv @ g.J.swapaxes(-1, -2)) @ g.X2.reshape(nf, q, 3, 4)     # (f, q, 2, 4)
            Hc = g.d2N.reshape(1, q, nn_, 4) - g.dN[None] @ Gam                   # (f, q, n, 4)
            Hc *= (w[None] / g.sqrt_detG)[:, :, None, None]
            SigF = Sig.transpose(1, 0, 2, 3).reshape(nb, q * 4)
            Bloc = -(SigF @ Hc.transpose(0, 1, 3, 2).reshape(nf, q * 4, nn_))    # (f, nb, n)
            for j in range(3):                                       # 3 local edges
                ge = ElementGeometry(X, edge_xi[j], self.m)
                sp_ = np.einsum("fgkd,d->fgk", ge.J, EDGE_TANGENTS[j])
                speed2 = np.einsum("fgk,fgk->fg", sp_, sp_)
                a = np.einsum("fgde,e->fgd", ge.Ginv, EDGE_OUTWARD[j])
                dv = np.einsum("fgd,gnd->fgn", a, ge.dN)             # (G⁻¹ t̂^⊥)·∇_ξ N_a
                fac = wg[None] * ge.sqrt_detG / speed2
                Bloc += edge_nn[j].T @ (fac[:, :, None] * dv)
            sc = self.scale[fs]
            Aloc *= sc[:, :, None] * sc[:, None, :]
            Bloc *= sc[:, :, None]
            D = self.dofs[fs]
            rowsA.append(np.broadcast_to(D[:, :, None], Aloc.shape).ravel())
            colsA.append(np.broadcast_to(D[:, None, :], Aloc.shape).ravel())
            valsA.append(Aloc.ravel())
            Ni = surf.elements[fs]
            rowsB.append(np.broadcast_to(D[:, :, None], Bloc.shape).ravel())
            colsB.append(np.broadcast_to(Ni[:, None, :], Bloc.shape).ravel())
            valsB.append(Bloc.ravel())
            if ii.size:                                               # static condensation, per face
                Ai = np.linalg.inv(Aloc[:, ii][:, :, ii])
                Aei = Aloc[:, ii][:, :, ie]
                Aii_inv.append(Ai)
                Aie.append(Aei)
                cond_vals.append(Aloc[:, ie][:, :, ie] - Aei.swapaxes(1, 2) @ Ai @ Aei)
        if ii.size:
            self._Aii_inv = np.concatenate(Aii_inv)
            self._Aie = np.concatenate(Aie)
            De = self.dofs[:, ie]
            Sc = np.concatenate(cond_vals)
            self._A_condensed = sp.coo_matrix(
                (Sc.ravel(), (np.broadcast_to(De[:, :, None], Sc.shape).ravel(),
                              np.broadcast_to(De[:, None, :], Sc.shape).ravel())),
                shape=(self.n_edge_dofs, self.n_edge_dofs)).tocsr()
        A = sp.coo_matrix((np.concatenate(valsA), (np.concatenate(rowsA), np.concatenate(colsA))),
                          shape=(self.n_dofs, self.n_dofs)).tocsr()
        B = sp.coo_matrix((np.concatenate(valsB), (np.concatenate(rowsB), np.concatenate(colsB))),
                          shape=(self.n_dofs, surf.n_nodes)).tocsr()
        return A, B

    def solve(self, rhs, fixed=None, fixed_values=None, solver="direct", condense=True):
        """Solve ``A s = rhs`` (rhs (n_dofs, k)) with the DOFs ``fixed`` (bool, edge DOFs only)
        prescribed to ``fixed_values``.

        ``condense=True`` eliminates the face-interior DOFs first (they couple only
        within their face): the Schur complement on the edge DOFs,
        ``S = A_ee - A_ei A_ii⁻¹ A_ie``, assembled from 3(r+1)-square face blocks, is
        solved and the interior DOFs recovered face by face — the same solution,
        with a third (m = 3) to a half (m = 2) of the unknowns."""
        A, _ = self.matrices
        k = rhs.shape[1]
        s = np.zeros((self.n_dofs, k))
        if fixed is None:
            fixed = np.zeros(self.n_dofs, dtype=bool)
        if fixed.any():
            s[fixed] = fixed_values[fixed]
        if not condense or self.local_interior.size == 0:
            free = ~fixed
            r = rhs[free] - (A[free][:, fixed] @ s[fixed] if fixed.any() else 0.0)
            Af = A[free][:, free] if fixed.any() else A
            s[free] = solve_spd(Af, r, method=solver)
            return s
        ne = self.n_edge_dofs
        if fixed[ne:].any():
            raise ValueError("only edge DOFs can be fixed")
        Di = self.dofs[:, self.local_interior]                       # (#F, ni)
        De = self.dofs[:, self.local_edge]
        ri = rhs[Di]                                                 # (#F, ni, k)
        y = self._Aii_inv @ ri                                       # A_ii⁻¹ r_i
        rc = rhs[:ne].copy()
        np.add.at(rc, De.ravel(), -(self._Aie.swapaxes(1, 2) @ y).reshape(-1, k))
        S = self._A_condensed
        fe = fixed[:ne]
        free = ~fe
        if fe.any():
            r = rc[free] - S[free][:, fe] @ s[:ne][fe]
            se = s[:ne].copy()
            se[free] = solve_spd(S[free][:, free], r, method=solver)
        else:
            se = solve_spd(S, rc, method=solver)
        s[:ne] = se
        s[Di.ravel()] = (y - self._Aii_inv @ (self._Aie @ se[De])).reshape(-1, k)
        return s

    def boundary_edge_terms(self, edges, normal_data=None):
        """Loads of clamped boundary edges (eq. 5.19's Σ_c term, plus the plain part).

        For boundary edges ``edges`` returns (n_dofs, 3) with, for coordinate k,
        ``∫_E φ^nn (n^k - (n·ν̃) ν̃^k) ds``; ``normal_data`` (#N, 3) per-node ν̃
        (interpolated by the degree-m Lagrange basis along the edge, Walker's
        I_h^m ν).  Without data (None) the ν̃ term is dropped: the load then
        cancels B's one-sided boundary term (the plain assembly)."""
        Bm = lagrange_basis(self.m)

        def xi_term(j, fj, exi, ge, n):
            if normal_data is None:
                return n
            nt = np.einsum("ga,fak->fgk", Bm.values(exi), normal_data[self.surface.elements[fj]])
            nt /= np.linalg.norm(nt, axis=2, keepdims=True)
            return n - np.einsum("fgk,fgk->fg", n, nt)[..., None] * nt
        return self.boundary_edge_load(edges, 3, xi_term)

    def boundary_edge_load(self, edges, k, integrand):
        """``∫_E φ^nn g ds`` over the boundary edges ``edges`` (#e,) of the (#e,) faces
        holding them, for a k-vector field g given by ``integrand(j, faces, points, geometry,
        n)`` → (f, g, k) at the edge quadrature points (exact for degree r + m + 3 in the
        edge parameter; ``points`` (g, 3) reference barycentrics on local edge j, ``geometry``
        the :class:`ElementGeometry` there, ``n`` (f, g, 3) the unit outward conormal n̂).
        Returns (n_dofs, k); shared by :meth:`boundary_edge_terms` and
        :func:`igl_hhj.curved.hessian.conormal_load`."""
        surf = self.surface
        out = np.zeros((self.n_dofs, k))
        edges = np.asarray(edges, dtype=np.int64)
        if edges.size == 0:
            return out
        f, jloc = surf.boundary_face_and_local(edges)
        tg, wg = line_quadrature(self.r + self.m + 3)
        for j in range(3):                                           # 3 local edges: vectorised over faces
            sel = jloc == j
            if not sel.any():
                continue
            fj = f[sel]
            A0, B0 = CORNERS[(j + 1) % 3], CORNERS[(j + 2) % 3]
            exi = A0[None] + tg[:, None] * (B0 - A0)[None]
            X = surf.nodes[surf.elements[fj]]
            ge = ElementGeometry(X, exi, self.m)
            speed = np.linalg.norm(np.einsum("fgkd,d->fgk", ge.J, EDGE_TANGENTS[j]), axis=2)
            a = np.einsum("fgde,e->fgd", ge.Ginv, EDGE_OUTWARD[j])
            n = np.einsum("fgkd,fgd->fgk", ge.J, a)
            n /= np.linalg.norm(n, axis=2, keepdims=True)                 # unit outward conormal n̂
            g = integrand(j, fj, exi, ge, n)
            Se = self.reference_basis(exi)
            nnf = np.einsum("d,gbde,e->gb", EDGE_OUTWARD[j], Se, EDGE_OUTWARD[j])
            # φ^nn ds = p_j / |J t̂_j|² · |J t̂_j| dt
            loc = np.einsum("g,fg,gb,fgk->fbk", wg, 1.0 / speed, nnf, g) * self.scale[fj][:, :, None]
            np.add.at(out, self.dofs[fj].ravel(), loc.reshape(-1, k))
        return out

    def edge_dof_points(self, edges):
        """For boundary edges: (face, local edge, (r+1) reference points, DOF ids),
        the points where the edge DOFs p_j are nodal values."""
        surf = self.surface
        f, jloc = surf.boundary_face_and_local(np.asarray(edges, dtype=np.int64))
        on, _ = _scalar_nodes_on_edge(self.r)
        nodes = lagrange_nodes(self.r)
        xi = np.empty((len(f), self.r + 1, 2))
        ids = np.empty((len(f), self.r + 1), dtype=np.int64)
        for j in range(3):                                           # 3 local edges
            sel = jloc == j
            for (i, _slot) in on[j]:
                col = _slot
                xi[sel, col] = nodes[i]
                ids[sel, col] = self.dofs[f[sel], j * self.nr + i]
        return f, jloc, xi, ids

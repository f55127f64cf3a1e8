"""Curved Lagrange triangulations Γ^m of order m = 1, 2, 3 (Walker 2023, §3.1 / §4.1).

Each triangle ``T^m`` is the image of the reference triangle under the degree-m
Lagrange map ``X(ξ) = Σ_a N_a(ξ) x_a`` through its (m+1)(m+2)/2 nodes, listed in
gmsh's triangle3 / triangle6 / triangle10 order (see :mod:`.reference`).
The corner nodes carry the topology (a libigl :class:`~igl_hhj.mesh.TriangleMesh`
of the corner triangles); neighbouring elements must share the nodes of their
common edge.
"""
from __future__ import annotations

from functools import cached_property

import numpy as np

from ..mesh import TriangleMesh
from .reference import edge_node_slots, lagrange_basis, triangle_quadrature

__all__ = ["LagrangeSurface", "ElementGeometry"]

_ORDER_OF = {3: 1, 6: 2, 10: 3, 15: 4}


class ElementGeometry:
    """Geometry of the curved elements at reference points, vectorised over faces.

    Attributes (n = #faces in the batch, q = #points)
    ----------
    x : (n, q, 3) points; J : (n, q, 3, 2) ∂X/∂ξ; G : (n, q, 2, 2) metric JᵀJ;
    detG : (n, q); Ginv : (n, q, 2, 2); nu : (n, q, 3) unit normal
    (X_ξ1 × X_ξ2 normalised); dN : (q, nb, 2) reference gradients of the
    Lagrange basis (degree m); X2 : (n, q, 3, 2, 2) second derivatives (if asked).
    """

    def __init__(self, X, xi, order, second=False):
        B = lagrange_basis(order)
        self.N = B.values(xi)                       # (q, nb)
        self.dN = B.gradients(xi)                   # (q, nb, 2)
        self.x = np.einsum("qa,fak->fqk", self.N, X)
        self.J = np.einsum("qad,fak->fqkd", self.dN, X)
        self.G = np.einsum("fqkd,fqke->fqde", self.J, self.J)
        self.detG = self.G[..., 0, 0] * self.G[..., 1, 1] - self.G[..., 0, 1] ** 2
        Gi = np.empty_like(self.G)
        Gi[..., 0, 0] = self.G[..., 1, 1]
        Gi[..., 1, 1] = self.G[..., 0, 0]
        Gi[..., 0, 1] = Gi[..., 1, 0] = -self.G[..., 0, 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            self.Ginv = Gi / self.detG[..., None, None]
            c = np.cross(self.J[..., 0], self.J[..., 1])
            self.nu = c / np.linalg.norm(c, axis=-1, keepdims=True)
        if second:
            self.d2N = B.hessians(xi)               # (q, nb, 2, 2)
            self.X2 = np.einsum("qade,fak->fqkde", self.d2N, X)

    @property
    def sqrt_detG(self):
        return np.sqrt(self.detG)

    def surface_gradients(self):
        """(n, q, nb, 3): ∇_Γ N_a = J G⁻¹ ∇_ξ N_a at the points."""
        return np.einsum("fqkd,fqde,qae->fqak", self.J, self.Ginv, self.dN)


class LagrangeSurface:
    """A surface made of curved Lagrange triangles of order m ∈ {1, 2, 3}.

    Parameters
    ----------
    nodes : (#N, 3) array_like of float
        Node positions (corners, edge nodes, interior nodes — any numbering).
    elements : (#F, (m+1)(m+2)/2) array_like of int
        Node indices per triangle in gmsh's order (triangle3 / triangle6 /
        triangle10): 3 corners, then the interior nodes of edges 0→1, 1→2,
        2→0 in that direction, then (m = 3) the centroid node.  Corners must
        form a consistently oriented manifold triangle mesh; two triangles
        sharing an edge must share that edge's nodes.  Never reordered.

    Raises
    ------
    TypeError, ValueError
        Non-numeric input, wrong shapes, NaN/inf nodes, out-of-range or
        repeated indices, non-manifold or inconsistently oriented corner
        meshes, neighbours not sharing their edge nodes, and elements whose
        Jacobian degenerates or folds over (checked at quadrature points).
    """

    def __init__(self, nodes, elements):
        try:
            P = np.asarray(nodes)
        except Exception as exc:
            raise TypeError(f"nodes must be array-like: {exc}") from None
        if P.dtype == object or not (np.issubdtype(P.dtype, np.floating) or np.issubdtype(P.dtype, np.integer)):
            raise TypeError(f"nodes must be a numeric array, got dtype {P.dtype}")
        if P.ndim != 2 or P.shape[1] != 3:
            raise ValueError(f"nodes must have shape (#N, 3), got {P.shape}")
        P = np.ascontiguousarray(P, dtype=np.float64)
        if not np.isfinite(P).all():
            raise ValueError(f"nodes has NaN or inf at node {int(np.flatnonzero(~np.isfinite(P).all(1))[0])}")
        try:
            E = np.asarray(elements)
        except Exception as exc:
            raise TypeError(f"elements must be array-like: {exc}") from None
        if E.ndim != 2:
            raise ValueError(f"elements must be a 2-D array (#F, 3/6/10/15), got shape {E.shape}")
        if E.shape[1] not in _ORDER_OF:
            raise ValueError(f"elements must have 3, 6, 10 or 15 columns (triangle3/6/10/15, order 1/2/3/4), "
                             f"got {E.shape[1]}")
        if E.shape[0] == 0:
            raise ValueError("elements is empty")
        if not np.issubdtype(E.dtype, np.integer):
            if np.issubdtype(E.dtype, np.floating) and np.all(np.isfinite(E)) and np.all(E == np.round(E)):
                E = E.astype(np.int64)
            else:
                raise TypeError(f"elements must hold integer node indices, got dtype {E.dtype}")
        E = np.ascontiguousarray(E, dtype=np.int64)
        bad = (E < 0) | (E >= len(P))
        if bad.any():
            f = int(np.flatnonzero(bad.any(1))[0])
            raise ValueError(f"element {f} has node index {int(E[f][bad[f]][0])} out of range [0, {len(P)})")
        Es = np.sort(E, axis=1)
        rep = (Es[:, 1:] == Es[:, :-1]).any(1)
        if rep.any():
            raise ValueError(f"element {int(np.flatnonzero(rep)[0])} repeats a node index")
        self.nodes = P
        self.elements = E
        self.order = _ORDER_OF[E.shape[1]]
        self.nodes.setflags(write=False)
        self.elements.setflags(write=False)
        self.mesh = TriangleMesh(P, E[:, :3])     # topology of the corner triangles (validated)
        self._check_edge_nodes()
        self._check_jacobians()

    # ------------------------------------------------------------------ checks
    def _check_edge_nodes(self):
        m = self.order
        if m == 1:
            return
        mesh = self.mesh
        slots = edge_node_slots(m)
        ef, li = mesh.edge_faces, mesh.edge_local_index
        inner = np.flatnonzero((ef >= 0).all(1))
        if inner.size == 0:
            return
        S = np.array(slots)                                        # (3, m-1)
        a = self.elements[ef[inner, 0][:, None], S[li[inner, 0]]]  # positively oriented side
        b = self.elements[ef[inner, 1][:, None], S[li[inner, 1]]][:, ::-1]
        bad = (a != b).any(1)
        if bad.any():
            e = inner[np.flatnonzero(bad)[0]]
            raise ValueError(f"elements {int(ef[e, 0])} and {int(ef[e, 1])} share the edge "
                             f"{tuple(int(v) for v in mesh.edges[e])} but not its edge nodes "
                             f"({a[bad][0].tolist()} vs {b[bad][0].tolist()}): the curved mesh is not conforming")
        # interior nodes must not be corners of other elements / shared across different edges
        corner = np.zeros(len(self.nodes), dtype=bool)
        corner[self.elements[:, :3]] = True
        hit = corner[self.elements[:, 3:]]
        if hit.any():
            f = int(np.flatnonzero(hit.any(1))[0])
            raise ValueError(f"element {f} uses a corner node of the mesh as an edge/interior node")

    def _check_jacobians(self):
        xi, _ = triangle_quadrature(2 * self.order)
        xi = np.concatenate([xi, np.array([[0, 0], [1, 0], [0, 1.0]])])
        g = ElementGeometry(self.nodes[self.elements], xi, self.order)
        flat = self.mesh.face_normals
        ok = np.isfinite(g.detG) & (g.detG > 0)
        l2 = self.mesh.edge_lengths.max(axis=1) ** 2
        ok &= g.detG > (1e-12 * l2[:, None]) ** 2
        # inverted: the curved normal at the centroid turns against the corner triangle's
        # (elsewhere a coarse element of a strongly curved surface may legitimately exceed 90°)
        gc = ElementGeometry(self.nodes[self.elements], np.array([[1 / 3, 1 / 3]]), self.order)
        ok &= (np.einsum("fqk,fk->fq", np.nan_to_num(gc.nu), flat) > 0)
        if not ok.all():
            f = int(np.flatnonzero(~ok.all(1))[0])
            raise ValueError(f"element {f} is degenerate or folds over (its Jacobian vanishes or its "
                             "normal turns against the corner triangle's)")

    # ------------------------------------------------------------------ sizes
    @property
    def n_faces(self):
        return self.elements.shape[0]

    @property
    def n_nodes(self):
        return self.nodes.shape[0]

    @cached_property
    def h(self):
        """Longest corner-to-corner edge (the mesh size of Walker's tables)."""
        return self.mesh.max_edge_length

    @cached_property
    def boundary_nodes(self):
        """(#N,) bool: nodes on boundary edges (corners and edge nodes)."""
        mask = np.zeros(self.n_nodes, dtype=bool)
        e = np.flatnonzero(self.mesh.boundary_edges)
        mask[self.mesh.edges[e].ravel()] = True
        if self.order > 1:
            f, i = self.boundary_face_and_local(e)
            S = np.array(edge_node_slots(self.order))
            mask[self.elements[f[:, None], S[i]].ravel()] = True
        return mask

    def boundary_face_and_local(self, e):
        """For boundary edges e: their face and the local edge index in it."""
        ef, li = self.mesh.edge_faces[e], self.mesh.edge_local_index[e]
        col = (ef[:, 0] < 0).astype(int)
        r = np.arange(len(e))
        return ef[r, col], li[r, col]

    # ------------------------------------------------------------------ geometry
    def _check_points(self, faces, bary):
        faces = np.asarray(faces)
        bary = np.asarray(bary, dtype=np.float64)
        if not np.issubdtype(faces.dtype, np.integer):
            raise TypeError(f"faces must be integer indices, got dtype {faces.dtype}")
        if faces.ndim != 1 or bary.shape != (len(faces), 3):
            raise ValueError(f"faces must be (n,) and bary (n, 3), got {faces.shape} and {bary.shape}")
        if len(faces) and (faces.min() < 0 or faces.max() >= self.n_faces):
            raise ValueError(f"face index out of range [0, {self.n_faces})")
        return faces.astype(np.int64), bary

    def geometry(self, faces, bary, second=False):
        """:class:`ElementGeometry` at points given per point (q = 1 per face row)."""
        faces, bary = self._check_points(faces, bary)
        xi = bary[:, 1:]
        B = lagrange_basis(self.order)
        X = self.nodes[self.elements[faces]]                 # (n, nb, 3)
        g = ElementGeometry.__new__(ElementGeometry)
        N = B.values(xi)                                     # (n, nb)
        dN = B.gradients(xi)
        g.N, g.dN = N, dN
        g.x = np.einsum("na,nak->nk", N, X)[:, None]
        g.J = np.einsum("nad,nak->nkd", dN, X)[:, None]
        g.G = np.einsum("fqkd,fqke->fqde", g.J, g.J)
        g.detG = g.G[..., 0, 0] * g.G[..., 1, 1] - g.G[..., 0, 1] ** 2
        Gi = np.empty_like(g.G)
        Gi[..., 0, 0], Gi[..., 1, 1] = g.G[..., 1, 1], g.G[..., 0, 0]
        Gi[..., 0, 1] = Gi[..., 1, 0] = -g.G[..., 0, 1]
        g.Ginv = Gi / g.detG[..., None, None]
        c = np.cross(g.J[..., 0], g.J[..., 1])
        g.nu = c / np.linalg.norm(c, axis=-1, keepdims=True)
        return g

    def points(self, faces, bary):
        """(n, 3) points X_f(ξ) of the curved triangles at barycentric coordinates
        ``bary`` (n, 3) (w.r.t. corners 0, 1, 2) of faces ``faces`` (n,)."""
        faces, bary = self._check_points(faces, bary)
        N = lagrange_basis(self.order).values(bary[:, 1:])
        return np.einsum("na,nak->nk", N, self.nodes[self.elements[faces]])

    def normals(self, faces, bary):
        """(n, 3) unit normals ∂_1X × ∂_2X / |·| of the curved triangles (orientation of F)."""
        return self.geometry(faces, bary).nu[:, 0]

    def quadrature(self, degree=None):
        """Quadrature on the curved surface: Σ w g(x) ≈ ∫_Γ^m g dS.

        Parameters
        ----------
        degree : int, optional
            Exactness degree of the reference rule (default 2m + 2).

        Returns
        -------
        faces : (n,) int64, bary : (n, 3), weights : (n,) (reference weight × √det G).
        """
        if degree is None:
            degree = 2 * self.order + 2
        xi, w = triangle_quadrature(int(degree))
        nF, q = self.n_faces, len(w)
        g = ElementGeometry(self.nodes[self.elements], xi, self.order)
        W = w[None] * g.sqrt_detG
        faces = np.repeat(np.arange(nF), q)
        bary = np.tile(np.column_stack([1 - xi.sum(1), xi]), (nF, 1))
        return faces, bary, W.ravel()

    def area(self, degree=None):
        """Area of Γ^m by :meth:`quadrature`."""
        return float(self.quadrature(degree)[2].sum())

    def interpolate(self, values, faces, bary):
        """Evaluate the degree-m nodal interpolant of per-node ``values`` (#N, ...) at points."""
        faces, bary = self._check_points(faces, bary)
        values = np.asarray(values, dtype=np.float64)
        if values.shape[0] != self.n_nodes:
            raise ValueError(f"values must have one row per node ({self.n_nodes}), got {values.shape[0]}")
        N = lagrange_basis(self.order).values(bary[:, 1:])
        V = values[self.elements[faces]]
        return np.einsum("na,na...->n...", N, V)

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_projection(cls, V, F, order, project, interpolant="walker"):
        """Curved surface of order m from a flat mesh and a closest-point map.

        Parameters
        ----------
        V : (#V, 3), F : (#F, 3)
            Flat triangulation Γ^1 whose vertices lie on Γ (consistently oriented).
        order : {1, 2, 3}
        project : callable (n, 3) → (n, 3)
            The map F_T of Walker §3.1 from the flat triangles onto Γ (e.g. a
            closest-point projection); applied to points of the flat edges and
            triangles.
        interpolant : {"walker", "nodal"}
            ``"walker"`` (default): Walker's modified interpolant F^m = 𝓘_h^{1,m} F
            (eq. 4.14 with the moments of eq. 4.2): vertex values, edge moments
            against P_{m-2}, face moments against P_{m-3} of the projected
            flat triangle.  Walker requires it for m = r + 1 (our case: HHJ of
            degree r = m − 1).  ``"nodal"``: standard nodal interpolation
            (projected Lagrange nodes).

        Returns
        -------
        LagrangeSurface, with nodes numbered: vertices (as V), then m − 1 nodes
        per unique edge of ``igl.unique_edge_map`` order (from its lower to
        its higher vertex), then (m = 3) one node per face.
        """
        from .interpolation import projected_nodes
        nodes, elements = projected_nodes(V, F, order, project, interpolant)
        return cls(nodes, elements)

    @classmethod
    def from_parametrization(cls, V, F, order, element_map, interpolant="walker"):
        """Like :meth:`from_projection`, for an element-wise map onto Γ.

        ``element_map(faces (n,), bary (n, 3)) -> (n, 3)`` maps the point with
        barycentric coordinates ``bary`` of flat triangle ``faces`` onto Γ (the
        map F_T of Walker §3.1; it must agree on shared edges), e.g. a chart
        composed with a curved-boundary ("Lenoir") map of the planar domain."""
        from .interpolation import mapped_nodes
        nodes, elements = mapped_nodes(TriangleMesh(V, F), order, element_map, interpolant)
        return cls(nodes, elements)

    @classmethod
    def from_meshio(cls, mesh):
        """Curved surface from a ``meshio.Mesh`` (or a path meshio can read, e.g. a gmsh ``.msh``).

        Uses the first cell block of type triangle10, triangle6 or triangle
        (the highest order present).  meshio keeps gmsh's node order for
        these types.  meshio is an optional dependency, imported lazily."""
        if isinstance(mesh, (str, bytes)) or hasattr(mesh, "__fspath__"):
            try:
                import meshio
            except ImportError as exc:  # pragma: no cover - depends on the environment
                raise ImportError("reading mesh files needs meshio: pip install meshio") from exc
            mesh = meshio.read(mesh)
        if not hasattr(mesh, "points") or not hasattr(mesh, "cells"):
            raise TypeError(f"expected a meshio.Mesh or a file path, got {type(mesh).__name__}")
        blocks = {}
        for cb in mesh.cells:
            t = getattr(cb, "type", None)
            if t in ("triangle", "triangle6", "triangle10"):
                blocks.setdefault(t, []).append(np.asarray(cb.data))
        for t in ("triangle10", "triangle6", "triangle"):
            if t in blocks:
                return cls(np.asarray(mesh.points, dtype=np.float64)[:, :3] if np.asarray(mesh.points).shape[1] >= 3
                           else np.column_stack([mesh.points, np.zeros(len(mesh.points))]),
                           np.concatenate(blocks[t]))
        raise ValueError("the mesh has no triangle, triangle6 or triangle10 cells")

    def to_meshio(self):
        """A ``meshio.Mesh`` with one triangle3/6/10 block (meshio imported lazily)."""
        import meshio
        t = {1: "triangle", 2: "triangle6", 3: "triangle10"}[self.order]
        return meshio.Mesh(np.array(self.nodes), [(t, np.array(self.elements))])

    def __repr__(self):
        return f"LagrangeSurface(order={self.order}, faces={self.n_faces}, nodes={self.n_nodes})"

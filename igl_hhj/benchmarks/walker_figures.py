"""Walker's Figs. 3–6 (Walker 2023, §6): the four test surfaces at m = 1, k = 1, coloured by
the discrete Gauss curvature κ_h^g = det(S_h + ν⊗ν) (eq. 6.1), and a zoom with the
principal directions as line segments — red d_1 (minimum curvature), black d_2
(maximum), as in the paper's captions.

Run::

    python -m igl_hhj.benchmarks.walker_figures [--out demos/images] [--surfaces saddle ...]

Writes ``walker_fig3_saddle.png``, ``walker_fig4_dumbbell.png``, ``walker_fig5_torus.png``,
``walker_fig6_genus3.png``: the mesh sequence, boundary data and shape operator are
those of :mod:`.walker_tables` (k = 1: 1792, 2432, 7616, 11176 triangles); the zooms
are the regions the captions name (saddle: a corner region, dumbbell: the top curved
edge, torus: the inner hole, genus 3: the edge of the right hole).  Rendered headless
by polyscope (EGL), composed with a colour bar by matplotlib, stored as full-colour PNGs.
"""
from __future__ import annotations

import argparse
import os

import numpy as np

__all__ = ["FIGURES", "figure_data", "render_figure", "main"]

# figure number, camera of the full view (eye, target) and of the zoom (eye, target, radius of
# the region whose directions are drawn)
FIGURES = {
    "saddle": (3, ((1.9, -1.1, 2.3), (0.5, 0.5, 0.1)), ((0.5, 0.05, 1.0), (0.5, 0.45, 0.2), 0.3)),
    "dumbbell": (4, ((0.0, -3.2, 3.2), (0.0, 0.0, 0.0)), ((0.0, -0.35, 1.45), (0.0, 0.3, 0.35), 0.45)),
    "torus": (5, ((0.0, -2.2, 2.0), (0.0, 0.0, 0.0)), ((0.0, -0.25, 0.9), (0.0, 0.0, 0.0), 0.6)),
    "genus3": (6, ((2.7, -2.9, 2.5), (0.0, 0.0, 0.0)), ((1.5, -0.4, 1.2), (1.0, 0.0, 0.0), 0.7)),
}


def figure_data(name, level=1, seed=0):
    """Mesh, κ_h^g and principal directions of Walker's figure for ``name`` (m = 1).

    Returns dict: ``V`` (#V, 3), ``F`` (#F, 3), ``kg`` (#F,) κ_h^g, ``d1`` / ``d2`` (#F, 3)
    unit minimum / maximum curvature directions, ``k1`` / ``k2`` (#F,) min / max curvature,
    ``kg_exact`` (#F,) the exact Gauss curvature at the face centroids' projections."""
    import igl

    from ..curvature import principal_from_shape_operator, shape_operator
    from ..surfaces.boundary_data import walker_boundary_data
    from .walker_tables import BOUNDARY, surface_levels
    surface, seq = surface_levels(name, level + 1, seed)
    V, F = seq[level]
    S = shape_operator(V, F, **walker_boundary_data(V, F, surface, BOUNDARY[name]))
    N = igl.per_face_normals(V, F, np.array([0.0, 0.0, 1.0]))
    kg = np.linalg.det(S + N[:, :, None] * N[:, None, :])
    PD1, PD2, PV1, PV2 = principal_from_shape_operator(S, N)     # PV1 ≥ PV2
    C = surface.project(V[F].mean(axis=1))
    Se = surface.shape_operator(C)
    Ne = surface.normal(C)
    kge = np.linalg.det(Se + Ne[:, :, None] * Ne[:, None, :])
    return {"V": V, "F": F, "kg": kg, "d1": PD2, "d2": PD1, "k1": PV2, "k2": PV1, "kg_exact": kge}


def _render(ps, eye, target, size):
    ps.look_at(eye, target)
    return np.asarray(ps.screenshot_to_buffer(transparent_bg=False, include_UI=False))[..., :3]


def render_figure(name, path, size=(760, 600), data=None):
    """Render Walker's figure for ``name`` into ``path`` (full-colour PNG). Returns the data dict."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..viewer import init
    from ..viewer.render import save_png
    fig_no, (eye, target), (zeye, ztarget, radius) = FIGURES[name]
    d = figure_data(name) if data is None else data
    V, F, kg = d["V"], d["F"], d["kg"]
    lo, hi = np.percentile(kg, [1, 99])
    vmax = max(abs(lo), abs(hi))
    ps = init("openGL3_egl")
    ps.remove_all_structures()
    ps.set_window_size(*size)
    ps.set_ground_plane_mode("none")
    ps.set_up_dir("z_up")
    ps.set_automatically_compute_scene_extents(False)
    ps.set_length_scale(float(np.linalg.norm(np.ptp(V, axis=0))))
    lo_b, hi_b = V.min(axis=0), V.max(axis=0)
    ps.set_bounding_box(lo_b, hi_b)
    m = ps.register_surface_mesh("mesh", V, F, smooth_shade=False, edge_width=0.0)
    m.add_scalar_quantity("kg", kg, defined_on="faces", cmap="coolwarm", vminmax=(-vmax, vmax), enabled=True)
    full = _render(ps, eye, target, size)
    # zoom: mesh edges and the principal directions of the faces near the target
    m.set_edge_width(1.0)
    C = V[F].mean(axis=1)
    near = np.flatnonzero(np.linalg.norm(C - np.asarray(ztarget), axis=1) < radius)
    e = np.linalg.norm(V[F[:, 0]] - V[F[:, 1]], axis=1).mean()
    half = 0.3 * e
    for label, dirs, colour in (("d1", d["d1"], (0.85, 0.0, 0.0)), ("d2", d["d2"], (0.0, 0.0, 0.0))):
        lift = 1e-3 * e * np.cross(V[F[near, 1]] - V[F[near, 0]], V[F[near, 2]] - V[F[near, 0]])
        lift /= np.linalg.norm(lift, axis=1, keepdims=True) / (0.02 * e)
        P = np.concatenate([C[near] - half * dirs[near] + lift, C[near] + half * dirs[near] + lift])
        n = len(near)
        E = np.column_stack([np.arange(n), np.arange(n) + n])
        cn = ps.register_curve_network(label, P, E, radius=0.0012, color=colour)
        cn.set_radius(0.025 * e, relative=False)
    zoom = _render(ps, zeye, ztarget, size)
    ps.remove_all_structures()
    H, W = full.shape[:2]
    fig = plt.figure(figsize=(2 * W / 100, H / 100 + 0.6), dpi=100)
    ax1 = fig.add_axes([0.0, 0.0, 0.5, H / (H + 60)])
    ax2 = fig.add_axes([0.5, 0.0, 0.5, H / (H + 60)])
    for ax, img in ((ax1, full), (ax2, zoom)):
        ax.imshow(img)
        ax.set_axis_off()
    ax1.set_title(f"κ_h^g (m = 1, k = 1, {len(F)} triangles)", fontsize=11)
    ax2.set_title("zoom: red d₁ (min. curvature), black d₂ (max. curvature)", fontsize=11)
    cax = fig.add_axes([0.03, 0.08, 0.012, 0.6 * H / (H + 60)])
    sm = plt.cm.ScalarMappable(cmap="coolwarm", norm=matplotlib.colors.Normalize(-vmax, vmax))
    fig.colorbar(sm, cax=cax)
    cax.tick_params(labelsize=9)
    fig.suptitle(f"Walker Fig. {fig_no}: {name}", fontsize=12, y=0.995)
    fig.canvas.draw()
    img = np.asarray(fig.canvas.buffer_rgba())[..., :3]
    plt.close(fig)
    if not save_png(path, img):
        raise RuntimeError("writing the figure needs Pillow")
    return d


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", default="benchmark-results", help="output folder (default ./benchmark-results/)")
    p.add_argument("--surfaces", nargs="+", default=list(FIGURES), choices=list(FIGURES))
    p.add_argument("--size", nargs=2, type=int, default=[760, 600], metavar=("W", "H"), help="size of each panel")
    a = p.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    for name in a.surfaces:
        path = os.path.join(a.out, f"walker_fig{FIGURES[name][0]}_{name}.png")
        d = render_figure(name, path, tuple(a.size))
        err = np.abs(d["kg"] - d["kg_exact"])
        print(f"{name}: {len(d['F'])} triangles, κ_h^g in [{d['kg'].min():.3g}, {d['kg'].max():.3g}] "
              f"(exact at centroids [{d['kg_exact'].min():.3g}, {d['kg_exact'].max():.3g}]), "
              f"mean |κ_h^g - κ^g| {err.mean():.3g}; wrote {path}")


if __name__ == "__main__":
    main()

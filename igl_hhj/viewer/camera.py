"""Where the camera looks from: the best view of a mesh, the rotation that shows it from a
given side, and the orthographic framing of the screenshots and the window."""
from __future__ import annotations

import numpy as np

from .values import _check


VIEWS = ("auto", "+x", "-x", "+y", "-y", "+z", "-z")
"""Named ``view=`` directions (the side the camera looks from); a 3-vector works too."""


def _fibonacci_sphere(n):
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    r = np.sqrt(1.0 - z * z)
    phi = np.pi * (3.0 - np.sqrt(5.0)) * i
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def best_view_direction(V, F, *, n_directions=400, max_faces=50_000) -> np.ndarray:
    """Unit direction from which the mesh shows its largest projected area.

    The projected area seen from ``d`` is ``½ Σ_T |T| |n_T · d|`` (closed
    surfaces); it is maximised over ``n_directions`` near-uniform directions (a Fibonacci sphere, plus the axes; at most ``max_faces`` faces,
    evenly subsampled, enter the sum).  Of ``d`` and ``-d``: on an open
    surface the side that sees clearly more of it (25 %), otherwise the view
    from above (+y, the usual "up" of scanned models), then from the front (+z).

    Parameters
    ----------
    V : (#V, 3) array_like, F : (#F, 3) array_like int

    Returns
    -------
    (3,) float64 unit vector (the side the camera looks from).

    Examples
    --------
    >>> import numpy as np
    >>> from igl_hhj import viewer
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]]); F = np.array([[0, 1, 2]])
    >>> np.round(viewer.best_view_direction(V, F), 2).tolist()   # a triangle in the xy plane
    [0.0, 0.0, 1.0]
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F)
    step = max(1, len(F) // int(max_faces))
    T = V[F[::step]]
    N = np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0])          # 2 |T| n_T
    D = _fibonacci_sphere(int(n_directions))
    D = np.vstack([np.eye(3), D[D[:, 2] >= 0]])               # the axes are candidates too
    seen = N @ D.T                                            # (#T, #D) 2 |T| n_T · d
    score = np.abs(seen).sum(axis=0)
    k = int(np.flatnonzero(score >= score.max() * (1 - 1e-9))[0])
    d = D[k]
    front, back = np.clip(seen[:, k], 0, None).sum(), np.clip(-seen[:, k], 0, None).sum()
    if max(front, back) > 1.25 * min(front, back):        # an open surface: look at its larger side
        flip = back > front
    else:                                                  # closed: from above (+y), then from the front (+z)
        flip = d @ np.array([0.1, 1.0, 0.5]) < 0
    if flip:
        d = -d
    return d / np.linalg.norm(d)


def view_rotation(view, V=None, F=None, *, landscape=False) -> np.ndarray:
    """(3, 3) rotation ``R``: ``V @ R.T`` is seen from ``view`` by the screenshots' camera
    (which looks down -z with y up).

    Parameters
    ----------
    view : {"auto", "+x", "-x", "+y", "-y", "+z", "-z"} or (3,) direction
        The side the camera looks from; "auto" is :func:`best_view_direction`
        of ``(V, F)``.  The picture's "up" is world +y projected into the view
        (+z or -z when looking along y).
    landscape : bool, turn the picture a quarter turn when the mesh ``V``
        would be taller than wide (copies laid side by side fit better).

    Returns
    -------
    (3, 3) float64 orthogonal, det +1; rows: picture right, up, towards the camera.

    Examples
    --------
    >>> from igl_hhj import viewer
    >>> viewer.view_rotation("+z").tolist() == [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    True
    """
    if isinstance(view, str):
        _check(view, "view", VIEWS)
        if view == "auto":
            if V is None or F is None:
                raise ValueError("view='auto' needs the mesh (V, F)")
            d = best_view_direction(V, F)
        else:
            d = np.zeros(3)
            d["xyz".index(view[1])] = 1.0 if view[0] == "+" else -1.0
    else:
        d = np.asarray(view, dtype=np.float64).reshape(-1)
        if d.shape != (3,) or not np.all(np.isfinite(d)) or not np.linalg.norm(d) > 0:
            raise ValueError(f"view must be one of {VIEWS} or a nonzero 3-vector, got {view!r}")
        d = d / np.linalg.norm(d)
    up = np.array([0.0, 1.0, 0.0])
    if abs(d[1]) > 0.95:                       # looking along y: the front (+z) at the picture's bottom
        up = np.array([0.0, 0.0, -np.sign(d[1])])
    u = up - (up @ d) * d
    u /= np.linalg.norm(u)
    r = np.cross(u, d)
    R = np.stack([r, u, d])
    if landscape and V is not None:            # a quarter turn in the picture if it is taller than wide
        P = np.asarray(V, dtype=np.float64) @ R[:2].T
        if np.ptp(P[:, 1]) > np.ptp(P[:, 0]):
            R = np.stack([u, -r, d])
    R[np.abs(R) < 1e-15] = 0.0
    return R


def _rotation_for(view, V, F):
    """None (no rotation) or the (3, 3) display rotation of ``view`` (also accepts a matrix)."""
    if view is None:
        return None
    if not isinstance(view, str) and np.shape(view) == (3, 3):
        return np.asarray(view, dtype=np.float64)
    return view_rotation(view, V, F)


def _union_bounds(*boxes):
    """Bounding box (2, 3) of several (2, 3) boxes (None entries ignored; None if all are)."""
    boxes = [b for b in boxes if b is not None]
    if not boxes:
        return None
    boxes = np.stack(boxes)
    return np.stack([boxes[:, 0].min(axis=0), boxes[:, 1].max(axis=0)])


def _frame(ps, bounds, width, height, margin=0.04, top_px=0, left_px=0):
    """Orthographic camera on +z (looking down -z, y up) framing the box ``bounds``:
    its x or y extent, whichever is binding, fills the picture up to ``margin``,
    leaving ``top_px`` pixels free at the top (titles) and ``left_px`` at the
    left (polyscope's panel in the interactive window).

    Orthographic so that copies laid side by side are seen from the same
    direction.  polyscope's own home view frames the bounding-box diagonal,
    which leaves wide pictures mostly empty and crops tall objects.  In
    polyscope's orthographic mode the visible half-height is
    ``2 tan(fov/2) × length_scale`` (measured), so the length scale sets the zoom.

    Returns
    -------
    ((cx, cy), wpp): the world point at the picture's centre and the world
    length of one pixel.
    """
    lo, hi = np.asarray(bounds[0], dtype=np.float64), np.asarray(bounds[1], dtype=np.float64)
    centre, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    diag = float(np.linalg.norm(hi - lo)) or 1.0
    tan_v = np.tan(np.radians(ps.get_vertical_fov_degrees()) / 2.0)
    free_h, free_w = max(height - top_px, 1), max(width - left_px, 1)
    wpp = (1.0 + margin) * 2.0 * max(half[1] / free_h, half[0] / free_w, 1e-9 * diag / height)
    half_height = 0.5 * height * wpp
    scale = half_height / (2.0 * tan_v)
    ps.set_automatically_compute_scene_extents(False)   # hidden structures must not count
    ps.set_bounding_box(lo, hi)
    ps.set_length_scale(scale)
    ps.set_view_projection_mode("orthographic")
    target = centre + np.array([-0.5 * left_px * wpp, 0.5 * top_px * wpp, 0.0])
    # clip planes are multiples of the length scale: keep the camera just in front of the box
    ps.look_at(target + np.array([0.0, 0.0, half[2] + 0.5 * scale]), target)
    return (float(target[0]), float(target[1])), wpp

"""Every constant of the drop-in is defined once, in igl_hhj.constants; the modules that use
them import it (and keep the old names: ``igl_hhj.mesh.DEGENERATE_AREA_RTOL`` etc.)."""
import ast
import importlib
from pathlib import Path

import igl_hhj
from igl_hhj import constants

PACKAGE = Path(igl_hhj.__file__).resolve().parent

OLD_HOMES = {
    "mesh": ("DEGENERATE_AREA_RTOL", "COORDINATE_MAX", "MIN_MESH_SIZE", "FOLDED_NORMAL_RTOL"),
    "solvers": ("DEFAULT_RTOL", "AUTO_DIRECT_MAX", "DIRECT_MAX", "PROBE_ITER", "CG_MAXITER", "SLIVER_ANGLE",
                "SLIVER_MAX_FRACTION", "LDL_MAX", "ENVELOPE_MAX", "DIRECT_RESIDUAL_RTOL"),
    "boundary_estimation": ("BOUNDARY_TREATMENTS", "FIT_RINGS", "SIDE_DOT_MIN"),
    "recovery": ("QUALITY_FLOOR", "SMOOTHING_PER_RADIUS", "BOUNDARY_LENGTH_FACTOR", "BOUNDARY_BAND_RINGS",
                 "SMOOTHING_STEPS", "SMOOTHING_ORDER"),
    "intrinsic": ("SMOOTHING_STEPS", "SMOOTHING_ORDER", "ADAPTIVE_GAIN", "ADAPTIVE_POWER", "ADAPTIVE_RANGE",
                  "SMOOTHING_MAXITER", "PILOT_RADIUS", "SPLIT_MIN_VERTICES"),
}


def test_each_constant_is_assigned_in_constants_only():
    names = set(constants.__all__)
    elsewhere = []
    for p in PACKAGE.rglob("*.py"):
        if p.name == "constants.py":
            continue
        for node in ast.parse(p.read_text(encoding="utf-8")).body:
            targets = node.targets if isinstance(node, ast.Assign) else \
                [node.target] if isinstance(node, ast.AnnAssign) else []
            elsewhere += [f"{p.relative_to(PACKAGE)}: {t.id}" for t in targets
                          if isinstance(t, ast.Name) and t.id in names]
    assert not elsewhere, f"drop-in constants assigned outside igl_hhj/constants.py: {elsewhere}"


def test_old_names_are_the_constants():
    for module, names in OLD_HOMES.items():
        mod = importlib.import_module(f"igl_hhj.{module}")
        for n in names:
            assert getattr(mod, n) is getattr(constants, n), f"igl_hhj.{module}.{n}"

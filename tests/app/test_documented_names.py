"""Every documented name of igl_hhj still imports: the README's, the docs pages', the API
reference's and every module's ``__all__``.

``documented_names.txt`` is the list as it was before the code-motion refactor "one readable
house" (main at 86525f9, collected by the rules below): moving code must keep each of these
paths working.  The few names deliberately removed with it are in :data:`REMOVED`, each with
its reason.  The names documented now are collected again on every run, so a page or an
``__all__`` cannot name something that does not exist.
"""
from __future__ import annotations

import ast
import importlib
import re
from pathlib import Path

import pytest

from conftest import ROOT

FROZEN = Path(__file__).with_name("documented_names.txt")

REMOVED = {
    # dotted name: why it is gone (docs/changelog.md)
    "igl_hhj.mesh.topology_reference": "a numpy reference only the tests used: tests/mesh/reference_topology.py",
    "igl_hhj.features.dihedral_magnitudes_reference":
        "a numpy reference only the tests used: tests/vertex_stage/reference_creases.py",
    **{f"igl_hhj.intrinsic.{n}": "the numpy reference of the recovery, only the tests used it: "
       "tests/vertex_stage/reference_intrinsic.py (igl_hhj.intrinsic is the compiled vertex stage)"
       for n in ("corner_components", "recover", "roughness", "principal", "vertex_stage_reference")},
    "igl_hhj.recovery.vertex_confidence": "dead code: no caller",
    "igl_hhj.curved.display.show_field": "moved to igl_hhj.viewer.show_curved_field (the curved layer "
       "no longer imports the viewer; docs/changelog.md)",
    "igl_hhj.kernels.lumped_vertex_recovery": "dead code: one test called it (its C++ went with it)",
    **{name: "the compiled twin of the ambient recovery, which only the non-default comparison option "
       "vertex_shape_operator(recovery='patch') used (now served by the numpy ambient recovery; "
       "measurement in docs/design.md)"
       for name in ("igl_hhj.kernels.patch_recovery", "igl_hhj.kernels.tangent_projection6",
                    "igl_hhj.kernels.smooth_vertex_tensors", "igl_hhj.recovery.recover_and_smooth",
                    "igl_hhj.recovery.patch_recover", "igl_hhj.recovery.smooth_recovered")},
}

DOTTED = re.compile(r"igl_hhj(?:\.[A-Za-z_][A-Za-z0-9_]*)+")
FROM = re.compile(r"from (igl_hhj(?:\.[a-z_0-9]+)*) import \(?([A-Za-z_0-9, \n]+)\)?")


def documented_now():
    """The dotted names of the README, docs/*.md, docs/*.rst and every ``__all__``."""
    files = [ROOT / "README.md", *sorted((ROOT / "igl_hhj" / "docs").glob("*.md")),
             *sorted((ROOT / "igl_hhj" / "docs").glob("*.rst"))]
    out = set()
    for f in files:
        text = f.read_text(encoding="utf-8")
        out.update(m.rstrip(".") for m in DOTTED.findall(text))
        for mod, names in FROM.findall(text):
            out.update(f"{mod}.{(n.split() or [''])[0]}" for n in names.replace("\n", " ").split(",") if n.split())
    pkg = ROOT / "igl_hhj"
    for p in pkg.rglob("*.py"):
        parts = p.relative_to(ROOT).with_suffix("").parts
        mod = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        for node in ast.parse(p.read_text(encoding="utf-8")).body:
            if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "__all__" for t in node.targets):
                out.update(f"{mod}.{n}" for n in ast.literal_eval(node.value))
    out.discard("igl_hhj.benchmarks.NAME")          # the placeholder of `python -m igl_hhj.benchmarks.NAME`
    return out


def resolve(dotted):
    """The object named by ``dotted``: the longest importable module prefix, then attributes."""
    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        name = ".".join(parts[:i])
        try:
            obj = importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name != name:          # a real import error inside the module
                raise
            continue
        for a in parts[i:]:
            obj = getattr(obj, a)
        return obj
    raise ImportError(dotted)


def _unresolved(names):
    bad = []
    for n in sorted(names):
        try:
            resolve(n)
        except Exception as exc:  # noqa: BLE001 - reported below
            bad.append(f"{n}: {type(exc).__name__}: {exc}")
    return bad


@pytest.mark.slow
def test_names_documented_before_the_refactor_still_import():
    frozen = set(FROZEN.read_text(encoding="utf-8").split())
    assert not set(REMOVED) - frozen, "REMOVED names a name that was never documented"
    bad = _unresolved(frozen - set(REMOVED))
    assert not bad, "documented names that no longer import:\n" + "\n".join(bad)


@pytest.mark.slow
def test_names_documented_now_import():
    bad = _unresolved(documented_now() - set(REMOVED))
    assert not bad, "the docs or an __all__ name what does not exist:\n" + "\n".join(bad)
    assert not set(REMOVED) & documented_now(), "a removed name is still documented"


def test_the_check_can_fail():
    assert _unresolved({"igl_hhj.curvature.no_such_function"})
    assert not _unresolved({"igl_hhj.curvature.principal_curvature", "igl_hhj.principal_curvature"})

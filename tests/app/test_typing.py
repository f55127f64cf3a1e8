"""The public API is typed for its users (issues 14 and 26): mypy passes on the whole
package (the [tool.mypy] config of pyproject.toml), the package ships a ``py.typed``
marker (PEP 561), and a user's script sees the real signatures and return types of the
lazily imported public names, not ``Any`` (mypy is in the test extra; a cold run takes
10-20 s)."""
import ast
import os
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _mypy(*args, cwd):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    return subprocess.run([sys.executable, "-m", "mypy", *args], cwd=cwd, capture_output=True, text=True,
                          timeout=600, env=env)


@pytest.mark.slow
def test_mypy_on_the_package():
    pytest.importorskip("mypy")
    files = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["mypy"]["files"]
    assert files == ["igl_hhj"], "mypy checks the whole package"
    res = _mypy("--no-error-summary", cwd=ROOT)
    assert res.returncode == 0, res.stdout[-4000:] + res.stderr[-2000:]


def test_py_typed_is_shipped():
    """PEP 561: without the marker mypy reports igl_hhj as untyped ("missing library stubs
    or py.typed marker") and every public name as Any.  scikit-build-core copies every
    file of ``wheel.packages`` into the wheel except ``wheel.exclude`` (the installed
    wheel's RECORD lists e.g. docs/api.rst), so the marker must not be excluded."""
    import fnmatch
    marker = ROOT / "igl_hhj" / "py.typed"
    assert marker.is_file()
    sk = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["scikit-build"]
    assert "igl_hhj" in sk["wheel"]["packages"]
    assert not any(fnmatch.fnmatch("igl_hhj/py.typed", pat) for pat in sk["wheel"].get("exclude", []))
    tracked = subprocess.run(["git", "ls-files", "--error-unmatch", "igl_hhj/py.typed"], cwd=ROOT,
                             capture_output=True, text=True)
    if tracked.returncode not in (0, 1) or "not a git repository" in tracked.stderr:
        pytest.skip("not a git checkout")
    assert tracked.returncode == 0, "igl_hhj/py.typed is not tracked by git (an sdist would miss it)"


def test_type_checking_imports_cover_the_lazy_names():
    """Every lazily resolved name of igl_hhj/__init__.py is imported under TYPE_CHECKING
    (and so has its real type for mypy/IDEs), and nothing else is."""
    import igl_hhj
    tree = ast.parse((ROOT / "igl_hhj" / "__init__.py").read_text())
    blocks = [n for n in tree.body if isinstance(n, ast.If) and getattr(n.test, "id", None) == "TYPE_CHECKING"]
    assert len(blocks) == 1
    names = {a.asname or a.name for node in ast.walk(blocks[0]) if isinstance(node, ast.ImportFrom)
             for a in node.names}
    assert names == set(igl_hhj._LAZY_MODULES) | set(igl_hhj._LAZY_ATTRS)
    assert set(igl_hhj.__all__) <= names


USER_SCRIPT = '''\
import numpy as np
import igl_hhj
from igl_hhj import viewer
from igl_hhj.surfaces import icosphere

V, F = icosphere(2)
reveal_type(igl_hhj.principal_curvature(V, F))
reveal_type(igl_hhj.shape_operator(V, F))
reveal_type(igl_hhj.surface_hessian(V, F, V[:, 0]))
reveal_type(igl_hhj.face_mean_curvature(V, F))
reveal_type(igl_hhj.face_gaussian_curvature(V, F))
reveal_type(igl_hhj.face_principal_curvature(V, F))
reveal_type(igl_hhj.biharmonic_solve(V, F, 1.0))
reveal_type(igl_hhj.validate_mesh(V, F))
reveal_type(igl_hhj.boundary_treatment(V, F))
reveal_type(igl_hhj.TriangleMesh(V, F))
reveal_type(igl_hhj.curvature_of(V, F))
reveal_type(igl_hhj.curvature_of(V, F, kind="gauss", per="face"))
reveal_type(igl_hhj.curvature_of(V, F, kind="directions"))
reveal_type(viewer.register_curvature)
reveal_type(igl_hhj.viewer.to_image)
reveal_type(igl_hhj.viewer.register_curvature(V, F))
reveal_type(igl_hhj.viewer.register_result("bunny_H.ply"))
reveal_type(igl_hhj.viewer.screenshot)
reveal_type(igl_hhj.mesh_io.read_mesh("bunny.off"))
reveal_type(igl_hhj.mesh_io.read_mesh_file("bunny.glb").split)
reveal_type(igl_hhj.mesh_io.read_curvature("bunny_H.vtp").estimate)
reveal_type(igl_hhj.mesh_io.write_curvature)
reveal_type(igl_hhj.vtk_files.write_vtk)
reveal_type(igl_hhj.polygon_io.split_polygons([0, 1, 2, 3], [0, 4]))
reveal_type(igl_hhj.baselines.estimate("hhj_vertex", V, F))
reveal_type(igl_hhj.baselines.hhj_vertex(V, F).H)
reveal_type(igl_hhj.baselines.libigl_quadric(V, F))
reveal_type(igl_hhj.mesh_report.mesh_report(V, F))
reveal_type(igl_hhj.regge.gauss_curvature(V, F))
reveal_type(igl_hhj.repair.repair_mesh(V, F))
reveal_type(igl_hhj.surfaces.icosphere(2))
reveal_type(igl_hhj.convergence.eoc([1.0, 0.5], [0.2, 0.1]))
PD1, PD2, PV1, PV2, bad = igl_hhj.principal_curvature(V, F)
reveal_type(PV1)
reveal_type(bad)
igl_hhj.curvature_of(igl_hhj.TriangleMesh(V, F), "mean")   # README's old mistake: "mean" is not F
igl_hhj.principal_curvature(V, F, radius="5")   # a user's mistake mypy must catch
'''

F64 = "NDArray[float64]"


def _normalised(t):
    """A revealed type without the spellings that differ between mypy / numpy versions:
    ``builtins.`` prefixes, ndarray's shape parameter (``Any``, ``tuple[Any, ...]``),
    sized integers as ``signedinteger[_64Bit]``."""
    t = t.replace("builtins.", "")
    t = re.sub(r"numpy\.(un)?signedinteger\[numpy\._typing\._nbit_base\._(\d+)Bit\]",
               lambda m: f"numpy.{'u' if m[1] else ''}int{m[2]}", t)
    return re.sub(r"numpy\.ndarray\[(?:[^\[\],]|\[[^\[\]]*\])*, numpy\.dtype\[numpy\.(\w+)\]\]", r"NDArray[\1]", t)


def _revealed(stdout):
    out = {}
    for line in stdout.splitlines():
        if ": note: Revealed type is " in line:
            lineno = int(line.split(":")[1])
            out[lineno] = _normalised(line.split("Revealed type is ", 1)[1].strip().strip('"'))
    return out


@pytest.mark.slow
def test_user_script_sees_the_real_types(tmp_path):
    """mypy on a user's script (outside the repository, default settings) that imports
    igl_hhj like any installed package: the public functions have their annotated
    signatures and return types through the lazy ``__getattr__`` and the
    ``with_large_call_heap`` decorator."""
    pytest.importorskip("mypy")
    script = tmp_path / "user_script.py"
    script.write_text(USER_SCRIPT)
    (tmp_path / "mypy.ini").write_text("[mypy]\n")
    res = _mypy("--config-file", str(tmp_path / "mypy.ini"), "--cache-dir", str(tmp_path / "cache"),
                "--no-error-summary", "--show-error-codes", str(script), cwd=tmp_path)
    lines = USER_SCRIPT.splitlines()
    revealed = {lines[n - 1].split("reveal_type(", 1)[1][:-1]: t for n, t in _revealed(res.stdout).items()}
    assert "py.typed" not in res.stdout and "import-untyped" not in res.stdout, res.stdout
    errors = [ln for ln in res.stdout.splitlines() if ": error:" in ln]
    # exactly two errors: "mean" as F and radius="5" (arg-type), on the last two lines
    assert len(errors) == 2, res.stdout
    assert f":{len(lines) - 1}:" in errors[0] and "curvature_of" in errors[0], res.stdout
    assert f":{len(lines)}:" in errors[1] and "arg-type" in errors[1], res.stdout
    assert len(revealed) == USER_SCRIPT.count("reveal_type("), res.stdout
    assert not [k for k, t in revealed.items() if t == "Any"], revealed

    assert revealed["igl_hhj.principal_curvature(V, F)"] == f"tuple[{F64}, {F64}, {F64}, {F64}, list[int]]"
    for call in ("igl_hhj.shape_operator(V, F)", "igl_hhj.surface_hessian(V, F, V[:, 0])",
                 "igl_hhj.face_mean_curvature(V, F)", "igl_hhj.face_gaussian_curvature(V, F)",
                 "igl_hhj.curvature_of(V, F)", 'igl_hhj.curvature_of(V, F, kind="gauss", per="face")', "PV1"):
        assert revealed[call] == F64, (call, revealed[call])
    assert revealed["igl_hhj.face_principal_curvature(V, F)"] == f"tuple[{F64}, ...]"
    assert revealed["igl_hhj.biharmonic_solve(V, F, 1.0)"] == f"tuple[{F64}, {F64}]"
    assert revealed['igl_hhj.curvature_of(V, F, kind="directions")'] == f"tuple[{F64}, {F64}]"
    assert revealed["igl_hhj.validate_mesh(V, F)"] == f"tuple[{F64}, NDArray[int64]]"
    assert revealed["igl_hhj.boundary_treatment(V, F)"] == "str"
    assert revealed["igl_hhj.TriangleMesh(V, F)"] == "igl_hhj.mesh.TriangleMesh"
    assert revealed["bad"] == "list[int]"
    assert revealed["viewer.register_curvature"].endswith("-> igl_hhj.viewer.registration.Registration")
    assert revealed["igl_hhj.viewer.to_image"].endswith("-> NDArray[uint8]")
    # submodule entry points, reached as attributes of igl_hhj (the lazy __getattr__)
    for call in ('igl_hhj.viewer.register_curvature(V, F)', 'igl_hhj.viewer.register_result("bunny_H.ply")'):
        assert revealed[call] == "igl_hhj.viewer.registration.Registration", (call, revealed[call])
    assert revealed["igl_hhj.viewer.screenshot"].endswith("-> str")
    assert revealed['igl_hhj.mesh_io.read_mesh("bunny.off")'] == f"tuple[{F64}, NDArray[int64], list[str]]"
    assert revealed['igl_hhj.mesh_io.read_mesh_file("bunny.glb").split'] == "igl_hhj.polygon_io.PolygonSplit"
    assert revealed['igl_hhj.mesh_io.read_curvature("bunny_H.vtp").estimate'] == "igl_hhj.results.CurvatureEstimate"
    assert "quantity: str =" in revealed["igl_hhj.mesh_io.write_curvature"]
    assert "point_data: typing.Mapping[str, Any] | None =" in revealed["igl_hhj.vtk_files.write_vtk"]
    assert revealed["igl_hhj.polygon_io.split_polygons([0, 1, 2, 3], [0, 4])"] == \
        "tuple[NDArray[int64], NDArray[int64], igl_hhj.polygon_io.PolygonSplit]"
    for call in ('igl_hhj.baselines.estimate("hhj_vertex", V, F)', "igl_hhj.baselines.libigl_quadric(V, F)"):
        assert revealed[call] == "igl_hhj.results.CurvatureEstimate", (call, revealed[call])
    assert revealed["igl_hhj.baselines.hhj_vertex(V, F).H"] == F64
    assert revealed["igl_hhj.mesh_report.mesh_report(V, F)"] == "igl_hhj.mesh_report.MeshReport"
    assert revealed["igl_hhj.regge.gauss_curvature(V, F)"] == F64
    assert revealed["igl_hhj.repair.repair_mesh(V, F)"] == "igl_hhj.repair.RepairedMesh"
    assert revealed["igl_hhj.surfaces.icosphere(2)"] == f"tuple[{F64}, NDArray[int64]]"
    assert revealed["igl_hhj.convergence.eoc([1.0, 0.5], [0.2, 0.1])"] == F64


def test_decorated_functions_keep_their_signature():
    """``runtime.with_large_call_heap`` is ``Callable[P, R] -> Callable[P, R]`` and keeps
    the run-time signature too (``inspect`` follows ``__wrapped__``); V and F reach the
    heap scope positionally or by keyword."""
    import inspect

    import igl_hhj
    from igl_hhj import runtime
    from igl_hhj.surfaces import icosphere
    sig = inspect.signature(igl_hhj.principal_curvature)
    assert list(sig.parameters)[:4] == ["V", "F", "radius", "useKring"]
    hints = runtime.with_large_call_heap.__annotations__
    assert str(hints["fn"]).startswith("Callable[_P, _R]") and str(hints["return"]).startswith("Callable[_P, _R]")
    seen = []

    def probe(V, F=None, *, k=1):
        return V, F, k
    wrapped = runtime.with_large_call_heap(probe)
    original = runtime.large_call_heap

    def spy(n):
        seen.append(n)
        return original(n)
    runtime.large_call_heap = spy
    try:
        V, F = icosphere(1)
        assert wrapped(V, F, k=2) == (V, F, 2)
        assert wrapped(V=V, F=F) == (V, F, 1)
        assert wrapped(V) == (V, None, 1)
    finally:
        runtime.large_call_heap = original
    assert seen == [len(F), len(F), 0]


def test_public_functions_are_annotated():
    import inspect

    import igl_hhj
    from igl_hhj import baselines, convergence, interop, mesh_io, mesh_report, polygon_io, regge, repair, viewer
    from igl_hhj.surfaces import icosphere
    functions = [mesh_io.read_mesh, mesh_io.read_mesh_file, mesh_io.read_curvature, polygon_io.split_polygons,
                 polygon_io.read_polygon_mesh, baselines.estimate, baselines.hhj_vertex, baselines.hhj_face,
                 baselines.libigl_quadric, baselines.libigl_cotan, baselines.heine, mesh_report.mesh_report,
                 regge.gauss_curvature, repair.repair_mesh, icosphere, viewer.register_result,igl_hhj.shape_operator, igl_hhj.surface_hessian, igl_hhj.principal_curvature,
                 igl_hhj.face_principal_curvature, igl_hhj.face_mean_curvature, igl_hhj.face_gaussian_curvature,
                 igl_hhj.curvature_of, igl_hhj.biharmonic_solve, igl_hhj.validate_mesh, igl_hhj.boundary_treatment,
                 convergence.eoc, convergence.plot_convergence, mesh_io.write_curvature,
                 interop.mesh_arrays, interop.to_trimesh, interop.to_pyvista, interop.to_meshio,
                 viewer.register_curvature, viewer.register_comparison, viewer.register_scalars,
                 viewer.screenshot, viewer.to_image, viewer.view_rotation, viewer.best_view_direction]
    for fn in functions:
        sig = inspect.signature(fn)
        assert sig.return_annotation is not inspect.Signature.empty, fn.__qualname__

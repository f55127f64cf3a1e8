"""The package's layers import downward only, and no module imports itself through others.

Every import of every module of ``igl_hhj`` is read with ``ast`` -- module-level,
function-level (lazy) and ``TYPE_CHECKING`` imports alike -- and mapped to the module it
loads.  The layers, bottom to top (``docs/design.md``, "Layers"):

0. runtime: the compiled core, its thread runtime and wrappers, the constants, the errors;
1. mesh: the validated mesh and what is computed on its topology alone;
2. numerics: solvers, the HHJ element, boundary treatment, vertex stage, creases;
3. pipeline: the drop-in's sequence, its small-mesh path, the repair;
4. public: the curvature functions and the other finite-element modules, exact surfaces;
5. io: readers, writers, reports, mesh objects of other libraries;
6. app: viewer, batch, command line, demos, benchmarks (and the package's lazy façade).

A module may import modules of its own layer or below; the import graph has no cycle.
"""
from __future__ import annotations

import ast
import functools
from pathlib import Path

import pytest

import igl_hhj

PACKAGE = Path(igl_hhj.__file__).resolve().parent

LAYERS = ("runtime", "mesh", "numerics", "pipeline", "public", "io", "app")

MODULE_LAYER = {
    # a name covers the module and, for a package, its submodules (longest prefix wins)
    "igl_hhj._hhj_core": "runtime",
    "igl_hhj.constants": "runtime",
    "igl_hhj.errors": "runtime",
    "igl_hhj.runtime": "runtime",
    "igl_hhj.kernels": "runtime",
    "igl_hhj.mesh": "mesh",
    "igl_hhj.mesh_objects": "mesh",
    "igl_hhj.components": "mesh",
    "igl_hhj.solvers": "numerics",
    "igl_hhj.hhj": "numerics",
    "igl_hhj.boundary": "numerics",
    "igl_hhj.boundary_estimation": "numerics",
    "igl_hhj.recovery": "numerics",
    "igl_hhj.intrinsic": "numerics",
    "igl_hhj.intrinsic_numpy": "numerics",
    "igl_hhj.creases": "numerics",
    "igl_hhj.pipeline": "pipeline",
    "igl_hhj.small_mesh": "pipeline",
    "igl_hhj.repair": "pipeline",
    "igl_hhj.curvature": "public",
    "igl_hhj.features": "public",
    "igl_hhj.biharmonic": "public",
    "igl_hhj.regge": "public",
    "igl_hhj.curved": "public",
    "igl_hhj.baselines": "public",
    "igl_hhj.convergence": "public",
    "igl_hhj.surfaces": "public",
    "igl_hhj.interop": "io",
    # the application half's new shared modules (branch house-app): the result type that I/O
    # and the baselines share, and the captured output of the readers
    "igl_hhj.results": "public",
    "igl_hhj.capture": "io",
    "igl_hhj.mesh_io": "io",
    "igl_hhj.polygon_io": "io",
    "igl_hhj.vtk_files": "io",
    "igl_hhj.mesh_report": "io",
    "igl_hhj.viewer": "app",
    "igl_hhj.batch": "app",
    "igl_hhj.tiled": "app",            # one mesh larger than memory, in tiles on Dask
    "igl_hhj.cli": "app",
    "igl_hhj.demos": "app",
    "igl_hhj.benchmarks": "app",
    "igl_hhj.docs": "app",             # the Sphinx configuration (igl_hhj/docs/conf.py)
    # the package itself: its __getattr__ imports any submodule on first use, so importing
    # it (``import igl_hhj``) stands for the whole package: an application-layer import
    "igl_hhj": "app",
}

ALLOWED_UPWARD: dict[tuple[str, str], str] = {
    # (importer, imported): why.  Only lazy (function-level) imports of optional extras in
    # the application layer belong here; none is needed today.
}

PENDING_APP_HALF: set[tuple[str, str]] = {
    # Import edges waiting for a pending refactor to remove them (none today: both halves of
    # the layering landed together).  An entry here must name the branch that removes it.
}


def _modules():
    """name -> path of every module of the package (the compiled core has no source)."""
    out = {}
    for p in PACKAGE.rglob("*.py"):
        parts = p.relative_to(PACKAGE.parent).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = p
    return out


MODULES = _modules()


def layer_of(name):
    """The layer of module ``name``: its own entry or its package's (the longest prefix;
    the package root ``igl_hhj`` covers only itself)."""
    best = max((k for k in MODULE_LAYER if name == k or (k != "igl_hhj" and name.startswith(k + "."))),
               key=len, default=None)
    return None if best is None else MODULE_LAYER[best]


def _target(base, name):
    """The module that ``from base import name`` loads: the submodule ``base.name`` if there
    is one (or the compiled core), else ``base`` itself, or for the package's lazy names
    (``from igl_hhj import principal_curvature``) the module that defines them."""
    full = f"{base}.{name}"
    if full in MODULES or full == "igl_hhj._hhj_core":
        return full
    if base == "igl_hhj":
        if name in igl_hhj._LAZY_ATTRS:
            return f"igl_hhj.{igl_hhj._LAZY_ATTRS[name]}"
    return base


def imports_of(module):
    """[(imported module, line, lazy)] for every igl_hhj import in ``module``'s source."""
    path = MODULES[module]
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    out = []

    def visit(node, lazy):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name == "igl_hhj" or a.name.startswith("igl_hhj."):
                    out.append((a.name, node.lineno, lazy))
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = ".".join(base[:len(base) - (node.level - 1)] + ([node.module] if node.module else []))
            elif node.module and (node.module == "igl_hhj" or node.module.startswith("igl_hhj.")):
                base = node.module
            else:
                return
            out.extend((_target(base, a.name), node.lineno, lazy) for a in node.names)
        elif isinstance(node, (ast.expr, ast.Pass, ast.Break, ast.Continue)):
            return                      # no statement (hence no import) below an expression
        else:
            lazy = lazy or isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
            for child in ast.iter_child_nodes(node):
                visit(child, lazy)

    visit(tree, False)
    return out


@functools.cache
def import_graph():
    """{importer: {imported: (line, lazy)}} over the package (the façade's own lazy
    imports are its purpose and are not edges)."""
    graph = {}
    for m in MODULES:
        if m == "igl_hhj":
            continue
        for t, line, lazy in imports_of(m):
            if t != m:
                graph.setdefault(m, {}).setdefault(t, (line, lazy))
    return graph


def _cycles(graph):
    """Strongly connected components with more than one module (Tarjan, iterative)."""
    index, low, on, stack, out, counter = {}, {}, set(), [], [], [0]
    nodes = sorted(set(graph) | {t for ts in graph.values() for t in ts})
    for root in nodes:
        if root in index:
            continue
        work = [(root, iter(sorted(graph.get(root, ()))))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph.get(w, ())))))
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.append(sorted(comp))
    return out


def test_every_module_has_a_layer():
    missing = sorted(m for m in MODULES if layer_of(m) is None)
    assert not missing, f"add these modules to MODULE_LAYER (tests/core/test_layers.py): {missing}"


def test_imports_go_downward_only():
    rank = {name: i for i, name in enumerate(LAYERS)}
    upward = []
    for m, targets in import_graph().items():
        for t, (line, lazy) in targets.items():
            lm, lt = layer_of(m), layer_of(t)
            if lm is None or lt is None or rank[lt] <= rank[lm]:
                continue
            if (m, t) in ALLOWED_UPWARD or (m, t) in PENDING_APP_HALF:
                continue
            upward.append(f"{m}:{line} ({lm}) imports {t} ({lt}){' inside a function' if lazy else ''}")
    assert not upward, "imports from a lower layer up to a higher one:\n" + "\n".join(sorted(upward))


def test_no_import_cycles():
    graph = {m: {t: v for t, v in ts.items() if (m, t) not in PENDING_APP_HALF}
             for m, ts in import_graph().items()}
    cycles = _cycles(graph)
    assert not cycles, "import cycles (function-level imports included): " + "; ".join(
        " <-> ".join(c) for c in cycles)


def test_exceptions_are_still_needed():
    """Every allowed or pending edge still exists: an edge the code no longer has is
    removed from the lists (they only ever shrink)."""
    graph = import_graph()
    stale = [e for e in list(ALLOWED_UPWARD) + sorted(PENDING_APP_HALF) if e[1] not in graph.get(e[0], {})]
    assert not stale, f"remove these entries from tests/core/test_layers.py, the import is gone: {stale}"


def test_the_checker_sees_lazy_imports_and_cycles():
    # the test can fail: a function-level import is an edge, and a cycle is found
    src = ast.parse("def f():\n    from .mesh import TriangleMesh\n")
    assert any(isinstance(n, ast.ImportFrom) for n in ast.walk(src))
    assert _cycles({"a": {"b": (1, True)}, "b": {"a": (2, True)}}) == [["a", "b"]]
    assert _cycles({"a": {"b": (1, False)}, "b": {}}) == []
    assert layer_of("igl_hhj.regge.curvature") == "public" and layer_of("igl_hhj.viewer.x") == "app"
    assert layer_of("igl_hhj.no_such_module") is None         # a new module must be placed


def test_the_dropin_path_does_not_import_the_numpy_element():
    """The drop-in's production path (its modules and everything they import) never loads
    the numpy HHJ element igl_hhj.hhj (the readable reference; its clamped load and the
    generic SPD solve live in igl_hhj.boundary and igl_hhj.solvers)."""
    graph = import_graph()
    seen, todo = set(), ["igl_hhj.pipeline"]
    while todo:
        m = todo.pop()
        if m not in seen:
            seen.add(m)
            todo.extend(graph.get(m, ()))
    assert "igl_hhj.hhj" not in seen and "igl_hhj.intrinsic" in seen, sorted(seen)

"""Sphinx configuration of the igl_hhj documentation (built by tests/app/test_docs.py with -W).

Pages are Markdown (MyST) or reStructuredText; the pictures are referenced where they
live, in ``demos/images/`` of the source tree (``../../demos/images/NAME.png`` from
here), and Sphinx copies them into the build's ``_images/``.  Build:
``python -m sphinx -W -b html igl_hhj/docs build/html``.
"""
project = "igl_hhj"
author = "igl_hhj contributors"
extensions = ["sphinx.ext.autodoc", "sphinx.ext.napoleon", "sphinx.ext.mathjax", "myst_parser"]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_custom_sections = [("Files", "params_style"), ("Repairs", "notes_style")]
autodoc_typehints = "description"
autodoc_member_order = "bysource"
# $...$ / $$...$$ math in the Markdown pages (rendered by MathJax); heading anchors so
# that links like results.md#noisy-scans-and-open-meshes resolve
myst_enable_extensions = ["dollarmath"]
myst_heading_anchors = 3
html_theme = "furo"
html_title = "igl_hhj"
# code blocks wrap long lines rather than run off the right edge (_static/custom.css)
html_static_path = ["_static"]
html_css_files = ["custom.css"]
exclude_patterns = ["_build"]
# the (string) annotations keep numpy's alias names, where the expanded ArrayLike union would
# fill several lines (api.rst gives curvature_of one signature instead of its overloads)
autodoc_type_aliases = {"ArrayLike": "numpy.typing.ArrayLike", "NDArray": "numpy.typing.NDArray"}


SINGLE_SIGNATURE = {"igl_hhj.curvature": {"curvature_of"}}
"""Overloaded functions the API page shows with their one implementation signature (the
parameter types under it): autodoc would open their entry with every ``@overload`` (they
exist for type checkers: ``kind="directions"`` returns a pair)."""


def setup(app):
    from sphinx.pycode import ModuleAnalyzer
    analyze = ModuleAnalyzer.analyze

    def without_overloads(self):
        analyze(self)
        for name in SINGLE_SIGNATURE.get(self.modname, ()):
            self.overloads.pop(name, None)

    ModuleAnalyzer.analyze = without_overloads

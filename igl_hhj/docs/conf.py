"""Sphinx configuration of the igl_hhj API reference (built by tests/test_docs.py with -W)."""
project = "igl_hhj"
author = "igl_hhj contributors"
extensions = ["sphinx.ext.autodoc", "sphinx.ext.napoleon"]
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_custom_sections = [("Files", "params_style"), ("Repairs", "notes_style")]
autodoc_typehints = "description"
autodoc_member_order = "bysource"
html_theme = "alabaster"
exclude_patterns = ["_build"]
# the (string) annotations keep numpy's alias names: curvature_of's overloads are shown
# as signatures, where the expanded ArrayLike union would fill several lines
autodoc_type_aliases = {"ArrayLike": "numpy.typing.ArrayLike", "NDArray": "numpy.typing.NDArray"}

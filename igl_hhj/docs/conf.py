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

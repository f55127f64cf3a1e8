"""Curvature of a mesh: HHJ (left) beside libigl's principal_curvature (right), same colours.

Thin wrapper: the demo lives in igl_hhj/demos/compare_curvature.py and is also installed as
``igl-hhj demo compare_curvature``.  Run ``python demos/compare_curvature.py --help`` for what it shows.
"""
import sys

from igl_hhj.demos import run

if __name__ == "__main__":
    sys.exit(run("compare_curvature", sys.argv[1:], prog="compare_curvature.py"))

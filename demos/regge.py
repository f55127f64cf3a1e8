"""Gauss curvature from edge lengths alone (Regge, k = 0) beside HHJ and the exact K.

Thin wrapper: the demo lives in igl_hhj/demos/regge.py and is also installed as
``igl-hhj demo regge``.  Run ``python demos/regge.py --help`` for what it shows.
"""
import sys

from igl_hhj.demos import run

if __name__ == "__main__":
    sys.exit(run("regge", sys.argv[1:], prog="regge.py"))

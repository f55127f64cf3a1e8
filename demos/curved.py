"""Curved triangles: Walker's HHJ shape operator on geometry of degree m = 1, 2, 3.

Thin wrapper: the demo lives in igl_hhj/demos/curved.py and is also installed as
``igl-hhj demo curved``.  Run ``python demos/curved.py --help`` for what it shows.
"""
import sys

from igl_hhj.demos import run

if __name__ == "__main__":
    sys.exit(run("curved", sys.argv[1:], prog="curved.py"))

"""HHJ mean curvature converges under refinement; the cotangent formula and Heine's P1 map do not.

Thin wrapper: the demo lives in igl_hhj/demos/refinement.py and is also installed as
``igl-hhj demo refinement``.  Run ``python demos/refinement.py --help`` for what it shows.
"""
import sys

from igl_hhj.demos import run

if __name__ == "__main__":
    sys.exit(run("refinement", sys.argv[1:], prog="refinement.py"))

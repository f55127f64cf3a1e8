"""Mixed P1 biharmonic solver (Stein et al.) on a manufactured problem: solution, error, rates.

Thin wrapper: the demo lives in igl_hhj/demos/biharmonic.py and is also installed as
``igl-hhj demo biharmonic``.  Run ``python demos/biharmonic.py --help`` for what it shows.
"""
import sys

from igl_hhj.demos import run

if __name__ == "__main__":
    sys.exit(run("biharmonic", sys.argv[1:], prog="biharmonic.py"))

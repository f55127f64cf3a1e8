"""From a mesh file to a curvature picture and saved results, step by step.

Thin wrapper: the demo lives in igl_hhj/demos/quickstart.py and is also installed as
``igl-hhj demo quickstart``.  Run ``python demos/quickstart.py --help`` for what it shows.
"""
import sys

from igl_hhj.demos import run

if __name__ == "__main__":
    sys.exit(run("quickstart", sys.argv[1:], prog="quickstart.py"))

"""Sharp features: libigl, HHJ without and HHJ with crease handling, on a CAD part.

Thin wrapper: the demo lives in igl_hhj/demos/features.py and is also installed as
``igl-hhj demo features``.  Run ``python demos/features.py --help`` for what it shows.
"""
import sys

from igl_hhj.demos import run

if __name__ == "__main__":
    sys.exit(run("features", sys.argv[1:], prog="features.py"))

"""Open surfaces need boundary data: HHJ shape operator without data, clamped, simply supported.

Thin wrapper: the demo lives in igl_hhj/demos/boundary_data.py and is also installed as
``igl-hhj demo boundary_data``.  Run ``python demos/boundary_data.py --help`` for what it shows.
"""
import sys

from igl_hhj.demos import run

if __name__ == "__main__":
    sys.exit(run("boundary_data", sys.argv[1:], prog="boundary_data.py"))

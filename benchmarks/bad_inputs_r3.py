"""Issue 47's bad inputs (round 3: the checks a surveyor makes before trusting an input), re-run through
``qgis_process`` on fresh copies of a finished workspace (``make demo``), and classified exactly as
``benchmarks/bad_inputs.py`` does (clean, ok, unclear, traceback, silently wrong, unclean, refused, lost data).

    python benchmarks/bad_inputs_r3.py [--workspace build/demo-workspace] [--before /tmp/wt-before] [--cases a,b]

The cases live beside this script in ``bad_inputs_r3_*.py`` (one module per group of the issue's items), each
registering its cases with ``bad_inputs.case`` and describing the run with ``bad_inputs.Spec``.
"""
import glob
import importlib
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import bad_inputs  # noqa: E402

bad_inputs.CASES.clear()  # round 3's cases only
for _path in sorted(glob.glob(os.path.join(HERE, "bad_inputs_r3_*.py"))):
    importlib.import_module(os.path.splitext(os.path.basename(_path))[0])
bad_inputs.CASES.sort(key=lambda c: c["item"])

if __name__ == "__main__":
    bad_inputs.main()

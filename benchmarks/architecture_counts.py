"""The counts issue 35 tracks, printed for core/ as it is now (run: python benchmarks/architecture_counts.py).

- functions and methods of core/ taking more than 8 parameters (self/cls not counted, *args/**kwargs counted once);
- underscore names imported from another module of the plugin (``from .x import _y``);
- modules outside ``core/io`` that open a file with ``gdal.Open`` / ``gdal.OpenEx`` (the goal: none; rasters are
  read through ``core.io.raster.RasterFile``, vectors through ``core.io.vector``);
- stage modules (``core/*/stage.py``) over 150 lines.

Static (ast), no imports of the plugin; prints a table and the worst offenders.
"""
import argparse
import ast
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from tests.test_architecture import _parameter_count as _parameters  # noqa: E402  (the test's own count)


def _sources(base):
    for folder, dirs, files in os.walk(base):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        for name in sorted(files):
            if name.endswith(".py"):
                yield os.path.join(folder, name)


def counts(root=ROOT, limit=8):
    core = os.path.join(root, "core")
    wide, private, readers, stages = [], [], [], []
    for path in _sources(core):
        rel = os.path.relpath(path, root)
        with open(path, encoding="utf-8") as fh:
            text = fh.read()
        tree = ast.parse(text, rel)
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and _parameters(node) > limit:
                wide.append((_parameters(node), f"{rel}:{node.lineno} {node.name}"))
            elif isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").startswith("core")):
                for alias in node.names:
                    if alias.name.startswith("_") and not alias.name.startswith("__"):
                        private.append(f"{rel}:{node.lineno} {node.module or '.'}.{alias.name}")
            elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in
                  ("Open", "OpenEx") and isinstance(node.func.value, ast.Name) and node.func.value.id == "gdal"):
                if not rel.replace(os.sep, "/").startswith("core/io/"):
                    readers.append(rel)
        if os.path.basename(path) == "stage.py":
            lines = text.count("\n")
            if lines > 150:
                stages.append((lines, rel))
    return {"wide": sorted(wide, reverse=True), "private": private, "readers": sorted(set(readers)),
            "stages": sorted(stages, reverse=True)}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--root", default=ROOT, help="the plugin folder (another checkout for a 'before' figure)")
    ap.add_argument("--show", type=int, default=10, help="offenders listed per count")
    args = ap.parse_args()
    c = counts(args.root)
    rows = [("functions over 8 parameters in core", len(c["wide"]), "<= 8"),
            ("underscore names imported across modules", len(c["private"]), "0"),
            ("core modules outside core/io calling gdal.Open", len(c["readers"]), "0"),
            ("stage modules over 150 lines", len(c["stages"]), "-")]
    print(f"{'count':45s} {'now':>5s}  goal")
    for name, value, goal in rows:
        print(f"{name:45s} {value:5d}  {goal}")
    for key, title in (("wide", "widest functions"), ("private", "private imports"), ("readers", "raster readers"),
                       ("stages", "long stage modules")):
        print(f"\n{title}:")
        for item in c[key][:args.show]:
            print("  ", *(item if isinstance(item, tuple) else (item,)))
    return 0


if __name__ == "__main__":
    sys.exit(main())

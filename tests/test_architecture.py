"""The structure of core/ (docs/architecture.md): one-way imports, short functions, one error base.

Static checks over the source (ast), no imports of the plugin: they fail with the offending module, line or
cycle named."""
import ast
import os

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CORE = os.path.join(ROOT, "core")
MAX_FUNCTION_LINES = 120
MAX_CLASS_LINES = 400
# the rooms in the order data flows; a room may import only rooms before it (and itself)
LAYERS = [["common"], ["geometry"], ["project"], ["io"], ["prepare"], ["align"], ["georef"], ["dense"], ["ortho", "terrain", "spectral"],
          ["report"], ["pipeline"]]


def _modules():
    for folder, _, files in os.walk(CORE):
        for f in sorted(files):
            if f.endswith(".py"):
                path = os.path.join(folder, f)
                rel = os.path.relpath(path, ROOT)[:-3].replace(os.sep, ".")
                name = rel[: -len(".__init__")] if rel.endswith(".__init__") else rel
                with open(path, encoding="utf-8") as fh:
                    yield name, path, ast.parse(fh.read(), path), f == "__init__.py"


def _imports(name, tree, is_pkg):
    """(line, imported core module) for every import in the module, in functions too."""
    package = name if is_pkg else name.rsplit(".", 1)[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
                if mod.startswith("archaeoortho."):
                    mod = mod[len("archaeoortho."):]
            if mod == "core" or mod.startswith("core."):
                if node.module is None or mod == "core":  # from . import x / from core import x
                    for a in node.names:
                        yield node.lineno, f"{mod}.{a.name}"
                else:
                    yield node.lineno, mod
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("core."):
                    yield node.lineno, a.name


def _graph():
    mods = {name: (path, tree, is_pkg) for name, path, tree, is_pkg in _modules()}
    graph = {}
    for name, (path, tree, is_pkg) in mods.items():
        deps = set()
        for line, mod in _imports(name, tree, is_pkg):
            while mod not in mods and "." in mod:  # 'from .x import name' where name is not a module
                mod = mod.rsplit(".", 1)[0]
            if mod in mods and mod != name:
                deps.add((mod, line))
        graph[name] = deps
    return mods, graph


def _room(module):
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def test_core_imports_no_qgis_or_qt():
    bad = []
    for name, path, tree, _ in _modules():
        for node in ast.walk(tree):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else (
                [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            bad += [f"{path}:{node.lineno} imports {n}" for n in names
                    if n.split(".")[0] in ("qgis", "PyQt5", "PyQt6", "PySide6", "sip")]
    assert not bad, "\n".join(bad)


def test_no_import_cycle_in_core():
    _, graph = _graph()
    colour, stack, cycles = {}, [], []

    def visit(n):
        colour[n] = 1
        stack.append(n)
        for m, _ in sorted(graph[n]):
            if colour.get(m) == 1:
                cycles.append(" -> ".join(stack[stack.index(m):] + [m]))
            elif not colour.get(m):
                visit(m)
        stack.pop()
        colour[n] = 2

    for n in sorted(graph):
        if not colour.get(n):
            visit(n)
    assert not cycles, "import cycles in core/:\n" + "\n".join(cycles)


def test_rooms_import_only_upstream():
    rank = {room: i for i, layer in enumerate(LAYERS) for room in layer}
    mods, graph = _graph()
    bad = []
    for name, deps in graph.items():
        r = _room(name)
        if r not in rank:
            continue
        for dep, line in deps:
            d = _room(dep)
            if d in rank and d != r and rank[d] >= rank[r]:
                bad.append(f"{mods[name][0]}:{line}: {name} ({r}) imports {dep} ({d})")
    assert not bad, "imports against the flow:\n" + "\n".join(sorted(bad))


def test_no_long_function_or_class_in_core():
    long = []
    for _, path, tree, _ in _modules():
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                n = node.end_lineno - node.lineno + 1
                limit = MAX_CLASS_LINES if isinstance(node, ast.ClassDef) else MAX_FUNCTION_LINES
                if n > limit:
                    long.append(f"{os.path.relpath(path, ROOT)}:{node.lineno} {node.name}: {n} lines (> {limit})")
    assert not long, "\n".join(long)


MAX_PARAMETERS = 8
# functions of core/ that may take more than MAX_PARAMETERS (issue 35: at most 8 of them), each with the reason
WIDE_ALLOWED = {}  # "core/room/module.py:function": "why its parameters cannot be grouped"


def _parameter_count(node):
    a = node.args
    names = [p.arg for p in a.posonlyargs + a.args + a.kwonlyargs]
    if names and names[0] in ("self", "cls"):
        names = names[1:]
    return len(names) + (a.vararg is not None) + (a.kwarg is not None)


def test_functions_take_at_most_8_parameters():
    """What travels together is one typed object (an options dataclass, a named group), not a long list of
    arguments; benchmarks/architecture_counts.py prints the widest."""
    wide = []
    for _, path, tree, _ in _modules():
        rel = os.path.relpath(path, ROOT).replace(os.sep, "/")
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and _parameter_count(node) > MAX_PARAMETERS:
                if f"{rel}:{node.name}" not in WIDE_ALLOWED:
                    wide.append(f"{rel}:{node.lineno} {node.name}: {_parameter_count(node)} parameters")
    assert len(WIDE_ALLOWED) <= 8
    assert not wide, f"functions over {MAX_PARAMETERS} parameters:\n" + "\n".join(wide)


def test_only_core_io_opens_files_with_gdal():
    """One reader: rasters through core.io.raster.RasterFile (DsmReader for heights), vectors through
    core.io.vector; no other module of core/ calls gdal.Open or gdal.OpenEx."""
    bad = []
    for name, path, tree, _ in _modules():
        if _room(name) == "io":
            continue
        for node in ast.walk(tree):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                    and node.func.attr in ("Open", "OpenEx", "OpenShared") and isinstance(node.func.value, ast.Name)
                    and node.func.value.id == "gdal"):
                bad.append(f"{os.path.relpath(path, ROOT)}:{node.lineno} gdal.{node.func.attr}")
    assert not bad, "files opened with GDAL outside core/io:\n" + "\n".join(bad)


MAX_STAGE_LINES = 150


def test_stage_modules_are_thin():
    """A stage module is its entry point: options, checks, recording, calls into its room's algorithm modules
    (the algorithms, loops and diagnoses live there)."""
    long = []
    for name, path, _, _ in _modules():
        if name.endswith(".stage"):
            with open(path, encoding="utf-8") as fh:
                n = fh.read().count("\n")
            if n > MAX_STAGE_LINES:
                long.append(f"{os.path.relpath(path, ROOT)}: {n} lines (> {MAX_STAGE_LINES})")
    assert not long, "stage modules that are not thin:\n" + "\n".join(long)


def test_every_core_error_derives_from_the_one_base():
    """Every class named *Error in core/ has ArchaeoOrthoError among its bases (directly or through another
    core error), so the faces catch one base."""
    classes = {}
    for _, path, tree, _ in _modules():
        for node in ast.walk(tree):
            if isinstance(node, ast.ClassDef):
                bases = [b.id if isinstance(b, ast.Name) else b.attr if isinstance(b, ast.Attribute) else ""
                         for b in node.bases]
                classes.setdefault(node.name, (path, node.lineno, bases))

    def derives(name, seen=()):
        if name == "ArchaeoOrthoError":
            return True
        if name not in classes or name in seen:
            return False
        return any(derives(b, seen + (name,)) for b in classes[name][2])

    bad = [f"{os.path.relpath(p, ROOT)}:{line} {n}({', '.join(b)})" for n, (p, line, b) in classes.items()
           if n.endswith("Error") and n != "ArchaeoOrthoError" and not derives(n)]
    assert not bad, "errors outside the ArchaeoOrthoError family:\n" + "\n".join(bad)


@pytest.mark.parametrize("room", ["prepare", "align", "georef", "dense", "ortho", "terrain", "report"])
def test_each_stage_room_has_options_and_stage(room):
    for f in ("options.py", "stage.py"):
        assert os.path.isfile(os.path.join(CORE, room, f)), f"core/{room}/{f} missing"


# the faces and the QGIS floor under them: a package may import only the packages listed (and itself, core, qgis)
FACES = {"processing_provider": {"qgisio"}, "ui": {"qgisio"}, "qgisio": set()}


def _package_imports(package):
    """(path, line, imported top-level plugin package) for every import in package/*.py, in functions too."""
    for path in sorted(os.path.join(ROOT, package, f) for f in os.listdir(os.path.join(ROOT, package))
                       if f.endswith(".py")):
        with open(path, encoding="utf-8") as fh:
            tree = ast.parse(fh.read(), path)
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                if node.level == 1:
                    top = package
                elif node.level == 2:
                    top = (node.module or "").split(".")[0]
                else:
                    mod = node.module or ""
                    top = mod.split(".")[1] if mod.startswith("archaeoortho.") else ""
                if node.level == 2 and not node.module:  # from .. import x
                    for a in node.names:
                        yield path, node.lineno, a.name
                elif top:
                    yield path, node.lineno, top


def test_faces_import_only_core_and_the_qgis_floor():
    """processing_provider/ and ui/ never import each other (a headless qgis_process run pulls nothing from ui/):
    what both need lives in qgisio/, which imports neither face and no widget."""
    bad = []
    for package, allowed in FACES.items():
        for path, line, top in _package_imports(package):
            if top in FACES and top != package and top not in allowed:
                bad.append(f"{os.path.relpath(path, ROOT)}:{line}: {package} imports {top}")
    for path in sorted(os.listdir(os.path.join(ROOT, "qgisio"))):
        if path.endswith(".py"):
            with open(os.path.join(ROOT, "qgisio", path), encoding="utf-8") as fh:
                if "QtWidgets" in fh.read():
                    bad.append(f"qgisio/{path}: imports widgets (QtWidgets): they belong in ui/")
    assert not bad, "imports across the faces:\n" + "\n".join(bad)


def test_no_private_name_imported_across_core_modules():
    """A name another module needs is public (issue 35): `from .surface import _Dsm` hid an interface."""
    bad = []
    for name, path, tree, _ in _modules():
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").startswith("core")):
                bad += [f"{os.path.relpath(path, ROOT)}:{node.lineno}: {node.module or '.'}.{a.name}" for a in node.names
                        if a.name.startswith("_") and not a.name.startswith("__")]
    assert not bad, "underscore names imported across modules (make them public):\n" + "\n".join(bad)

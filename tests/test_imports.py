"""A name is imported from the module that defines it: no module passes on another module's names.

Checked over the plugin's Python (core/, processing_provider/, ui/, tests/, benchmarks/, sample/, plugin.py):
``from M import n`` and ``m.n`` (m a plugin module imported under a name) must find ``n`` defined in M (a def,
a class or an assignment there), or ``n`` is a submodule of M; a name M itself imported from another plugin
module is a re-export and fails.  Names from outside the plugin (numpy, qgis, the standard library) are not
checked.  ``__all__`` in core/ lists only the module's own names.
"""
import ast
import os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TREES = ["core", "processing_provider", "ui", "tests", "benchmarks", "sample"]
PACKAGE = "archaeoortho"  # the plugin folder's name when QGIS (and some tests) import it


def _module_name(path):
    rel = os.path.relpath(path, ROOT)[:-3].replace(os.sep, ".")
    return "" if rel == "__init__" else rel[:-len(".__init__")] if rel.endswith(".__init__") else rel


def _sources():
    paths = [os.path.join(ROOT, "plugin.py"), os.path.join(ROOT, "__init__.py")]
    for top in TREES:
        for folder, dirs, files in os.walk(os.path.join(ROOT, top)):
            dirs[:] = [d for d in dirs if not d.startswith((".", "__"))]
            paths += [os.path.join(folder, f) for f in files if f.endswith(".py")]
    return {_module_name(p): p for p in paths if os.path.isfile(p)}


MODULES = _sources()
TREES_BY_MODULE = {m: ast.parse(open(p, encoding="utf-8").read(), p) for m, p in MODULES.items()}


def _is_package(m):
    return m == "" or MODULES.get(m, "").endswith("__init__.py")


def _source_of(module, node):
    """The plugin module an ImportFrom reads from ('' = the plugin package), or None for an outside one."""
    if node.level:
        base = module.split(".") if _is_package(module) else module.split(".")[:-1]
        base = base[:len(base) - (node.level - 1)] if node.level > 1 else base
        name = ".".join([p for p in base if p] + ([node.module] if node.module else []))
    else:
        name = node.module or ""
        if name == PACKAGE or name.startswith(PACKAGE + "."):
            name = name[len(PACKAGE) + 1:]
        elif name.split(".")[0] not in {m.split(".")[0] for m in MODULES if m}:
            return None
    return name if name in MODULES else None


def _module_level(node):
    """The nodes of the module's own namespace: everything but the insides of functions and classes."""
    for child in ast.iter_child_nodes(node):
        yield child
        if not isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef, ast.Lambda)):
            yield from _module_level(child)


def _bindings(module):
    """(names the module defines at module level, {name: source module} of the names it imports from plugin
    modules, lazy imports in functions included)."""
    tree = TREES_BY_MODULE[module]
    defined = set()
    for node in _module_level(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            defined.add(node.name)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            defined.add(node.id)
    imported = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and _source_of(module, node) is not None:
            imported.update({a.asname or a.name: _source_of(module, node) for a in node.names})
    return defined, imported


BINDINGS = {m: _bindings(m) for m in MODULES}


def _submodule(source, name):
    return (f"{source}.{name}" if source else name) in MODULES


def _defined_in(source, name):
    defined, imported = BINDINGS[source]
    return name in defined or name not in imported  # a name from outside the plugin is not checked


def _violations(module):
    out, aliases = [], {}
    tree = TREES_BY_MODULE[module]
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            source = _source_of(module, node)
            if source is None:
                continue
            for a in node.names:
                if _submodule(source, a.name):
                    aliases[a.asname or a.name] = f"{source}.{a.name}" if source else a.name
                elif a.name != "*" and not _defined_in(source, a.name):
                    out.append(f"{MODULES[module]}:{node.lineno}: {a.name} from {source or PACKAGE}, which imports it from "
                               f"{BINDINGS[source][1][a.name]}")
        elif isinstance(node, ast.Import):
            for a in node.names:
                name = a.name[len(PACKAGE) + 1:] if a.name.startswith(PACKAGE + ".") else a.name
                if a.asname and name in MODULES:
                    aliases[a.asname] = name
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in aliases:
            source = aliases[node.value.id]
            if not _submodule(source, node.attr) and not _defined_in(source, node.attr):
                out.append(f"{MODULES[module]}:{node.lineno}: {node.value.id}.{node.attr} ({source}), which imports it from "
                           f"{BINDINGS[source][1][node.attr]}")
    return out


def test_every_name_is_imported_from_the_module_that_defines_it():
    bad = [v for m in sorted(MODULES) for v in _violations(m)]
    assert not bad, "re-exported names (import them from the module that defines them):\n" + "\n".join(bad)


def test_core_all_lists_only_own_names():
    bad = []
    for m, tree in TREES_BY_MODULE.items():
        if not m.startswith("core"):
            continue
        for node in tree.body:
            if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "__all__" for t in node.targets):
                bad += [f"{MODULES[m]}: {e.value}" for e in node.value.elts
                        if e.value in BINDINGS[m][1] and e.value not in BINDINGS[m][0]]
    assert not bad, "__all__ re-exports:\n" + "\n".join(bad)


def test_the_check_sees_a_re_export():
    """The rule itself on a known case: core.io.gcp imports CRSError from core.geometry.crs (for its own use)."""
    assert BINDINGS["core.io.gcp"][1]["CRSError"] == "core.geometry.crs"
    assert not _defined_in("core.io.gcp", "CRSError") and _defined_in("core.geometry.crs", "CRSError")

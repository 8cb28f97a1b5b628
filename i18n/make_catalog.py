"""Write ui/catalog.py: the algorithms' class-attribute strings (DISPLAY, HELP, GROUP) and the values of their
choices marked for pylupdate5.

``self.tr(self.DISPLAY)`` translates at run time, but pylupdate5 only collects string literals inside
tr()/translate() calls, so the names and help texts of the Processing algorithms would never reach the
.ts files.  This script reads processing_provider/*.py (with ``ast``, nothing is imported) and writes
them as QT_TRANSLATE_NOOP(<class name>, <text>) entries, the contexts AlgorithmBase.tr() uses.  The options of
the choices (the core's values "auto", "half", "feather" ..., CHOICE_LISTS) go into the "Choices" context, which
processing_provider/params.option_label translates them in.

The core's own messages (issue 48 item 6: progress and log lines, the adjustment's diagnosis; qgisio's messages to a
core Progress too) are English text
built with f-strings in core/, which has no Qt.  Their templates (each f-string's replacement fields as ``{}``)
go into qgisio/core_messages.py, context "CoreMessages", which qgisio/messages.translate_message matches a message
against and translates; the report's headings and figure labels (``ctx.t("...")`` / ``t("...")`` in core/report)
go into ui/catalog.py, context "Report", which core/report/labels.py reads from the .ts file.

    python3 i18n/make_catalog.py          # rewrite ui/catalog.py and qgisio/core_messages.py
    python3 i18n/make_catalog.py --check  # exit 1 when either is out of date

Run it before ``pylupdate5`` (make transup); tests/test_ui_i18n.py checks that it is up to date.
"""
import ast
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ATTRIBUTES = ("DISPLAY", "HELP", "GROUP")
TARGET = os.path.join(ROOT, "ui", "catalog.py")
MESSAGES_TARGET = os.path.join(ROOT, "qgisio", "core_messages.py")
MESSAGES_CONTEXT = "CoreMessages"  # qgisio/messages.CONTEXT
REPORT_CONTEXT = "Report"  # core/report/labels.CONTEXT
# the calls whose text argument is a core message: Progress.report(fraction, text), .info(text), .warning(text),
# the adjustment's run.warn(text); and any call's message=text (an outlier's message, the diagnosis)
MESSAGE_CALLS = {"report": 1, "info": 0, "warning": 0, "warn": 0}
REPORT_CALLS = ("t",)  # core/report: ctx.t("heading"), t("figure label")
CHOICES_CONTEXT = "Choices"  # processing_provider/params.CHOICES_CONTEXT
# the lists of choice options shown translated (module- or class-level tuples or lists of strings; of pairs, the
# label: the second item).  Camera models (COLMAP's names) and the DSM engine (cpu, cuda) are names, not words.
CHOICE_LISTS = (
    ("processing_provider/params.py", ("PAIRINGS", "MAPPERS", "INTRINSICS", "QUALITIES", "BLENDINGS",
                                       "INTERPOLATIONS")),
    ("core/prepare/options.py", ("FIDUCIAL_TYPES", "LAYOUT_NAMES")),
    ("core/georef/targets/options.py", ("PLAIN_KINDS",)),
    ("core/terrain/options.py", ("VISUALISATIONS",)),
    ("core/prepare/band_radiometry.py", ("MODES",)),
)


def collect(root=ROOT):
    """[(context, text)] in file and class order, without repeats."""
    folder = os.path.join(root, "processing_provider")
    out = []
    for name in sorted(os.listdir(folder)):
        if not name.endswith(".py"):
            continue
        with open(os.path.join(folder, name), encoding="utf-8") as f:
            tree = ast.parse(f.read(), name)
        for node in tree.body:
            if not isinstance(node, ast.ClassDef):
                continue
            for stmt in node.body:
                if not (isinstance(stmt, ast.Assign) and len(stmt.targets) == 1
                        and isinstance(stmt.targets[0], ast.Name) and stmt.targets[0].id in ATTRIBUTES):
                    continue
                if isinstance(stmt.value, ast.Constant) and isinstance(stmt.value.value, str) and stmt.value.value:
                    # GROUP is translated in AlgorithmBase's context (see AlgorithmBase.group)
                    ctx = "AlgorithmBase" if stmt.targets[0].id == "GROUP" else node.name
                    item = (ctx, stmt.value.value)
                    if item not in out:
                        out.append(item)
    return out + [item for item in collect_choices(root) if item not in out]


def collect_choices(root=ROOT):
    """[("Choices", option)] of CHOICE_LISTS, without repeats."""
    out = []
    for rel, names in CHOICE_LISTS:
        with open(os.path.join(root, rel), encoding="utf-8") as f:
            tree = ast.parse(f.read(), rel)
        found = {}
        constants = {n.targets[0].id: n.value.value for n in tree.body  # module constants: CROSS = "cross"
                 if isinstance(n, ast.Assign) and len(n.targets) == 1 and isinstance(n.targets[0], ast.Name)
                 and isinstance(n.value, ast.Constant) and isinstance(n.value.value, str)}
        for node in ast.walk(tree):
            if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
                target, value = node.targets[0].id, node.value
            elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name) and node.value is not None:
                target, value = node.target.id, node.value
            else:
                continue
            if target in names and isinstance(value, (ast.Tuple, ast.List)):
                found[target] = [_option(e, constants) for e in value.elts]
        for name in names:
            if name not in found:
                raise SystemExit(f"{rel}: no list of options {name} (i18n/make_catalog.py CHOICE_LISTS)")
            for option in found[name]:
                if option and (CHOICES_CONTEXT, option) not in out:
                    out.append((CHOICES_CONTEXT, option))
    return out


def _option(node, names=None):
    """An option's text: a string (or a module constant's), or the last item of a (value, label) pair."""
    if isinstance(node, (ast.Tuple, ast.List)) and node.elts:
        node = node.elts[-1]
    if isinstance(node, ast.Name):
        return (names or {}).get(node.id)
    return node.value if isinstance(node, ast.Constant) and isinstance(node.value, str) else None


def _core_files(root, folder="core", needle=None):
    """(relative path, syntax tree) of the .py files under ``folder`` (those whose text matches ``needle``)."""
    for dirpath, dirnames, names in os.walk(os.path.join(root, folder)):
        dirnames[:] = sorted(d for d in dirnames if d != "__pycache__")
        for name in sorted(names):
            if name.endswith(".py"):
                path = os.path.join(dirpath, name)
                with open(path, encoding="utf-8") as f:
                    text = f.read()
                if needle is None or needle.search(text):
                    yield os.path.relpath(path, root), ast.parse(text, path)


def message_template(node):
    """The text of a string literal or f-string as a format template: each replacement field ``{}`` (its format
    spec dropped), literal braces doubled; a sum of such parts; None for anything else."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value.replace("{", "{{").replace("}", "}}")
    if isinstance(node, ast.JoinedStr):
        return "".join(v.value.replace("{", "{{").replace("}", "}}") if isinstance(v, ast.Constant) else "{}"
                       for v in node.values)
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        a, b = message_template(node.left), message_template(node.right)
        return a + b if a is not None and b is not None else None
    return None


def _is_words(template):
    """A message a user reads: words, not only fields and punctuation ("{}: {}")."""
    return "%s" not in template and sum(c.isalpha() for c in template.replace("{}", "")) >= 3  # (not a logger's)


def collect_messages(root=ROOT):
    """[template] of the core's messages (MESSAGE_CALLS, message=...), and of qgisio's to a core Progress (saving a
    web reference layer), in file order, without repeats."""
    out = []
    needle = re.compile(r"\.(report|info|warning|warn)\(|message=")  # the files that may hold one: a third
    trees = list(_core_files(root, "core", needle)) + [
        (rel, tree) for rel, tree in _core_files(root, "qgisio", needle) if rel != os.path.relpath(MESSAGES_TARGET, root)]
    for _rel, tree in trees:
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call):
                continue
            args = []
            name = node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")
            if name in MESSAGE_CALLS and len(node.args) > MESSAGE_CALLS[name]:
                args.append(node.args[MESSAGE_CALLS[name]])
            args += [k.value for k in node.keywords if k.arg == "message"]
            for arg in args:
                text = message_template(arg)
                if text and _is_words(text) and text not in out:
                    out.append(text)
    return out


def _row_labels(node):
    """The labels of ("Label", value) pairs in ``node`` (a list of rows, one row): a capitalised literal."""
    pairs = node.elts if isinstance(node, (ast.List, ast.Tuple)) else []
    if isinstance(node, ast.Tuple) and len(node.elts) == 2:
        pairs = [node]
    return [p.elts[0] for p in pairs if isinstance(p, ast.Tuple) and len(p.elts) == 2
            and isinstance(p.elts[0], ast.Constant) and isinstance(p.elts[0].value, str) and p.elts[0].value[:1].isupper()]


def collect_report(root=ROOT):
    """[("Report", text)] of the report's headings and labels in core/report: t("...") / ctx.t("..."), embed()'s
    alt text and caption, table()'s headings and the sections' ("Label", value) rows of kv()."""
    out = []
    sections = os.path.join("core", "report", "sections")
    for rel, tree in _core_files(root, os.path.join("core", "report")):
        for node in ast.walk(tree):
            texts = []
            if isinstance(node, ast.Call) and node.args:
                name = node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")
                if name in REPORT_CALLS:
                    texts = list(node.args[:1])
                elif name == "embed":  # embed(fig, alt, caption): translated inside
                    texts = list(node.args[1:3])
                elif name == "table" and isinstance(node.args[0], (ast.List, ast.Tuple)):  # table(headings, rows)
                    texts = list(node.args[0].elts)
                if rel.startswith(sections):  # kv([...]), rows.append(("Label", value))
                    texts += [label for arg in node.args for label in _row_labels(arg)]
            elif isinstance(node, (ast.Assign, ast.AnnAssign)) and rel.startswith(sections) and node.value is not None:
                texts = _row_labels(node.value)  # info = [("File", ...)]
            for arg in texts:
                if isinstance(arg, ast.Constant) and isinstance(arg.value, str) and _is_words(arg.value):
                    if (REPORT_CONTEXT, arg.value) not in out:
                        out.append((REPORT_CONTEXT, arg.value))
    return out


def render(items):
    lines = [
        '"""Strings of the Processing algorithms\' class attributes (DISPLAY, HELP, GROUP) and of their choices\' options',
        '(context "Choices"), marked for pylupdate5.',
        "",
        "Generated by i18n/make_catalog.py: do not edit by hand.  Nothing imports this module.",
        '"""',
        "from qgis.PyQt.QtCore import QT_TRANSLATE_NOOP",
        "",
        "STRINGS = (",
    ]
    for ctx, text in items:
        lines.append(f"    QT_TRANSLATE_NOOP({ctx!r}, {_literal(text)}),")
    lines.append(")")
    return "\n".join(lines) + "\n"


def _literal(text):
    """One double-quoted literal: pylupdate5 reads neither adjacent literals nor parenthesised ones."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


def render_messages(templates):
    lines = [
        '"""The core\'s messages as templates (each f-string\'s fields as {}), context "CoreMessages", marked for',
        "pylupdate5; qgisio/messages.translate_message matches a message against them.",
        "",
        "Generated by i18n/make_catalog.py: do not edit by hand.",
        '"""',
        "from qgis.PyQt.QtCore import QT_TRANSLATE_NOOP",
        "",
        "TEMPLATES = (",
    ]
    for text in templates:
        lines.append(f"    QT_TRANSLATE_NOOP({MESSAGES_CONTEXT!r}, {_literal(text)}),")
    lines.append(")")
    return "\n".join(lines) + "\n"


def main(argv):
    strings = collect()
    outputs = {TARGET: render(strings + [i for i in collect_report() if i not in strings]),
               MESSAGES_TARGET: render_messages(collect_messages())}
    if "--check" in argv:
        stale = [t for t, text in outputs.items()
                 if (open(t, encoding="utf-8").read() if os.path.exists(t) else "") != text]
        for t in stale:
            print(f"{t} is out of date: run python3 i18n/make_catalog.py", file=sys.stderr)
        return 1 if stale else 0
    for target, text in outputs.items():
        with open(target, "w", encoding="utf-8") as f:
            f.write(text)
        print(f"{target}: {text.count('QT_TRANSLATE_NOOP(')} strings")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

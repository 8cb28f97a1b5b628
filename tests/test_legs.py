"""The CI split (tests/legs.py) is complete and names only what exists: a new test file that nobody placed, a
one-leg entry whose test was renamed, or a platform check moved to one leg fails here, on every leg."""
import ast
import os

from tests import legs

HERE = os.path.dirname(os.path.abspath(__file__))


def _test_files():
    return sorted(f for f in os.listdir(HERE) if f.startswith("test_") and f.endswith(".py"))


def _test_functions(filename):
    with open(os.path.join(HERE, filename), encoding="utf-8") as fh:
        tree = ast.parse(fh.read(), filename)
    names = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.name.startswith("test"):
            names.add(node.name)
        elif isinstance(node, ast.ClassDef) and node.name.startswith("Test"):
            names.update(f"{node.name}::{f.name}" for f in node.body
                         if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef)) and f.name.startswith("test"))
    return names


def test_every_test_file_is_placed_and_nothing_else():
    files = _test_files()
    missing = [f for f in files if f not in legs.FILES]
    stale = [f for f in legs.FILES if f not in files]
    assert not missing, f"test files not placed in tests/legs.py FILES (say what they exercise): {missing}"
    assert not stale, f"tests/legs.py FILES names files that do not exist: {stale}"
    bad = {f: a for f, a in legs.FILES.items() if a not in legs.ASPECTS}
    assert not bad, f"unknown aspects (use one of {legs.ASPECTS}): {bad}"


def test_every_one_leg_entry_names_an_existing_test_with_a_reason():
    for key, why in legs.ONE_LEG.items():
        filename, _, test = key.partition("::")
        assert filename in legs.FILES, f"ONE_LEG {key}: no such test file"
        assert not test or test in _test_functions(filename), f"ONE_LEG {key}: no test {test} in {filename}"
        assert isinstance(why, str) and len(why) > 20, f"ONE_LEG {key}: say why once is enough"


def test_platform_checks_run_on_every_leg():
    for f in legs.PLATFORM_ONLY_EVERY_LEG:
        assert f in legs.FILES, f
        assert legs.FILES[f] != "core", f"{f} is a platform check, not core"
        assert not [k for k in legs.ONE_LEG if k == f or k.startswith(f + "::")], f"{f} must run on every leg"


def test_one_leg_reads_node_ids_as_pytest_writes_them():
    key = next(iter(legs.ONE_LEG), None)
    if key is None:
        assert not legs.one_leg("tests/test_align.py::test_x")
        return
    filename, _, test = key.partition("::")
    assert legs.one_leg(f"tests/{filename}::{test}")
    assert legs.one_leg(f"tests/{filename}::{test}[param-1]")
    assert not legs.one_leg(f"tests/{filename}::{test}_other")
    assert not legs.one_leg("tests/test_legs.py::test_one_leg_reads_node_ids_as_pytest_writes_them")


def test_the_costliest_files_exist_and_come_first():
    assert len(set(legs.SLOWEST_FIRST)) == len(legs.SLOWEST_FIRST)
    assert all(f in legs.FILES for f in legs.SLOWEST_FIRST), [f for f in legs.SLOWEST_FIRST if f not in legs.FILES]
    first = legs.SLOWEST_FIRST[0]
    assert legs.slowest_first(f"tests/{first}::test_x") < legs.slowest_first("tests/test_gcp.py::test_x")


def test_every_test_the_edit_loop_leaves_out_exists():
    for key in legs.EDIT_LOOP_LEAVES_OUT:
        filename, _, test = key.partition("::")
        assert filename in legs.FILES, f"EDIT_LOOP_LEAVES_OUT {key}: no such test file"
        assert test in _test_functions(filename), f"EDIT_LOOP_LEAVES_OUT {key}: no test {test} in {filename}"
    key = next(iter(legs.EDIT_LOOP_LEAVES_OUT))
    assert not legs.in_edit_loop(f"tests/{key}[param-1]")
    assert legs.in_edit_loop("tests/test_legs.py::test_every_test_the_edit_loop_leaves_out_exists")

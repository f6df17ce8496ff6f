"""The type stubs (python/ssx/_ssx.pyi) name exactly what the compiled module has: a method added to
the module without its stub, or a stub left behind, fails here."""
import ast
import pathlib

import ssx

STUB = pathlib.Path(ssx.__file__).with_name("_ssx.pyi")


def stub_names():
    tree = ast.parse(STUB.read_text())
    top, methods = set(), set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            top.add(node.name)
        if isinstance(node, ast.ClassDef) and node.name == "Environment":
            methods = {n.name for n in node.body if isinstance(n, ast.FunctionDef) and not n.name.startswith("_")}
        if isinstance(node, ast.AnnAssign):
            top.add(node.target.id)
    return {n for n in top if not n.startswith("_") or n == "__version__"}, methods


def test_the_stubs_name_every_function_class_and_method_and_no_more():
    top, methods = stub_names()
    assert top == {n for n in dir(ssx._ssx) if not n.startswith("_")} | {"__version__"}
    assert methods == {n for n in dir(ssx._ssx.Environment) if not n.startswith("_")}


def test_every_public_function_and_method_has_a_docstring_in_the_stubs():
    tree = ast.parse(STUB.read_text())
    env = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Environment")
    functions = [n for n in tree.body if isinstance(n, ast.FunctionDef)]
    undocumented = [n.name for n in functions + [env] if ast.get_docstring(n) is None]
    assert undocumented == []

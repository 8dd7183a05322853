"""The hand-written stubs (_specdeform.pyi) name what the compiled module has, with the same
parameters, and the package exports all of it."""

import ast
import inspect
import pathlib
import re

import specdeform
from specdeform import _specdeform

STUB = ast.parse((pathlib.Path(_specdeform.__file__).parent / "_specdeform.pyi").read_text())


def stub_parameters(function: ast.FunctionDef) -> list[str]:
    args = function.args
    names = [a.arg for a in args.posonlyargs + args.args]
    if args.kwonlyargs:
        names += ["*"] + [a.arg for a in args.kwonlyargs]
    return [n for n in names if n != "self"]


def bound_parameters(function) -> list[str]:
    """Parameter names from pybind11's signature line, e.g. 'f(a: int, *, b: str = 1) -> None'."""
    signature = function.__doc__.splitlines()[0]
    inside = signature[signature.index("(") + 1 : signature.rindex(")")]
    names = [re.split(r"[:=]", p)[0].strip() for p in re.split(r", (?![^\[]*\])", inside)]
    return [n for n in names if n and n != "self" and not n.startswith("**")]


def members(node: ast.ClassDef) -> dict[str, ast.FunctionDef]:
    return {f.name: f for f in node.body if isinstance(f, ast.FunctionDef)}


def test_every_name_has_a_stub_and_every_stub_a_name():
    stubbed = {n.name for n in STUB.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    stubbed |= {n.target.id for n in STUB.body if isinstance(n, ast.AnnAssign)}
    compiled = {n for n in dir(_specdeform) if not n.startswith("__") or n == "__version__"}
    assert stubbed == compiled
    assert set(specdeform.__all__) == {n for n in compiled if not n.startswith("_")} | {
        "Scene", "read_scene", "__version__"}


def test_function_parameters_match():
    for node in STUB.body:
        if isinstance(node, ast.FunctionDef):
            assert stub_parameters(node) == bound_parameters(getattr(_specdeform, node.name)), \
                node.name


def test_class_members_match():
    for node in STUB.body:
        if not isinstance(node, ast.ClassDef) or node.name.endswith("Error"):
            continue
        cls = getattr(_specdeform, node.name)
        compiled = {n for n in vars(cls) if not n.startswith("__")}
        stubbed = set(members(node)) - {"__init__"}
        assert stubbed == compiled, node.name
        for name, function in members(node).items():
            if inspect.isroutine(getattr(cls, name)) and name != "__init__":
                assert stub_parameters(function) == bound_parameters(getattr(cls, name)), name


def test_deformer_keywords_are_the_options(bar):
    init = members(next(n for n in STUB.body if getattr(n, "name", "") == "SpectralDeformer"))
    keywords = stub_parameters(init["__init__"])
    explicit = bound_parameters(specdeform.SpectralDeformer.__init__)
    assert keywords[: len(explicit)] == explicit
    options = specdeform.SpectralDeformer(*bar, solver="spatial").options
    assert keywords[len(explicit) :] == list(options)

"""The type stubs (__init__.pyi) describe the package as it is: the same functions with the same
parameters, the same classes with the same public members."""

import ast
import inspect
from pathlib import Path

import pytest

import robocal

STUB = Path(robocal.__file__).with_suffix(".pyi")


@pytest.fixture(scope="module")
def stub():
    assert STUB.is_file(), f"no type stubs installed at {STUB}"
    return ast.parse(STUB.read_text())


def stub_functions(tree):
    return {n.name: n for n in tree.body if isinstance(n, ast.FunctionDef)}


def stub_classes(tree):
    return {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}


def params(fn: ast.FunctionDef):
    a = fn.args
    return [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs]


def test_every_public_name_has_a_stub(stub):
    names = set(stub_functions(stub)) | set(stub_classes(stub)) | {
        t.id for n in stub.body if isinstance(n, ast.AnnAssign) for t in [n.target]}
    missing = [n for n in robocal.__all__ if n not in names]
    assert not missing, missing


@pytest.mark.parametrize("name", ["calibrate", "calibrate_files", "calibrate_constraints", "plan_constraints",
                                  "evaluate", "compensate", "simulate", "plan",
                                  "iso9283_plan", "iso9283_evaluate"])
def test_function_signatures_match(stub, name):
    fn = stub_functions(stub)[name]
    runtime = [p for p in inspect.signature(getattr(robocal, name)).parameters]
    assert params(fn) + ([fn.args.kwarg.arg] if fn.args.kwarg else []) == runtime


@pytest.mark.parametrize("name", ["Simulation", "Plan", "PlanQuality", "Iso9283Plan"])
def test_class_members_match(stub, name):
    cls = stub_classes(stub)[name]
    members = set()
    for n in cls.body:
        if isinstance(n, ast.FunctionDef):
            members.add(n.name)
        elif isinstance(n, ast.AnnAssign):
            members.add(n.target.id)
    runtime = {m for m in dir(getattr(robocal, name)) if not m.startswith("_")}
    assert {m for m in members if not m.startswith("_")} == runtime


def test_docstrings(stub):
    for f in (robocal.simulate, robocal.plan, robocal.iso9283_plan):
        assert "CLI" in f.__doc__ and len(f.__doc__) > 500
    for cls in (robocal.Simulation, robocal.Plan, robocal.PlanQuality, robocal.Iso9283Plan):
        assert cls.__doc__
        for m in dir(cls):
            if not m.startswith("_"):
                assert getattr(cls, m).__doc__, f"{cls.__name__}.{m} has no docstring"

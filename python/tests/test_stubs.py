"""The shipped stubs (`ttalloc/__init__.pyi`) describe the built module: the same public
names, the same members per class, the same parameter names per function and method."""

import ast
import inspect
from pathlib import Path

import ttalloc
import ttalloc._native as native

STUB = Path(ttalloc.__file__).with_name("__init__.pyi")
#: Dunders a stub states on purpose (the others are Python's own).
STATED_DUNDERS = {"__getitem__", "__contains__"}


def stub_tree():
    tree = ast.parse(STUB.read_text())
    funcs = {n.name: n for n in tree.body if isinstance(n, ast.FunctionDef)}
    classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}
    return funcs, classes


def params(fn: ast.FunctionDef) -> list[str]:
    names = [a.arg for a in fn.args.posonlyargs + fn.args.args + fn.args.kwonlyargs]
    return [n for n in names if n != "self"]


def runtime_params(obj) -> list[str]:
    return [p for p in inspect.signature(obj).parameters if p != "self"]


def public(names) -> set[str]:
    return {n for n in names if not n.startswith("_") or n in STATED_DUNDERS}


def test_the_stub_is_shipped_with_py_typed():
    assert STUB.is_file()
    assert STUB.with_name("py.typed").is_file()


def test_stub_names_are_the_modules_public_names():
    funcs, classes = stub_tree()
    assert set(funcs) | set(classes) == set(ttalloc.__all__)
    assert set(ttalloc.__all__) == public(vars(native))


def test_function_parameters_match():
    funcs, _ = stub_tree()
    for name, fn in funcs.items():
        assert params(fn) == runtime_params(getattr(ttalloc, name)), name


def test_class_members_and_method_parameters_match():
    _, classes = stub_tree()
    for name, cls in classes.items():
        runtime = getattr(ttalloc, name)
        members = {
            n.name: n for n in cls.body if isinstance(n, ast.FunctionDef)
        }
        if issubclass(runtime, BaseException):
            assert not members, name
            continue
        assert public(members) == public(vars(runtime)), name
        for m, fn in members.items():
            attr = inspect.getattr_static(runtime, m)
            is_property = any(
                isinstance(d, ast.Name) and d.id == "property" for d in fn.decorator_list
            )
            assert is_property == inspect.isgetsetdescriptor(attr), f"{name}.{m}"
            if not is_property:
                assert params(fn) == runtime_params(getattr(runtime, m)), f"{name}.{m}"

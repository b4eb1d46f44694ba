"""The type stubs (.pyi) declare what the modules export: every public name of
scanfit, scanfit.sums and scanfit.dask, every public method and property of
their classes, and the keyword arguments of the Python-level functions."""

import ast
import inspect
from pathlib import Path

import pytest

import scanfit
import scanfit.sums

PKG = Path(scanfit.__file__).parent


def stub(name):
    path = PKG / f"{name}.pyi"
    assert path.exists(), f"{path} is missing (the package must ship its type stubs)"
    tree = ast.parse(path.read_text())
    top = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            top[node.name] = {
                n.name: n for n in node.body if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))
            }
        elif isinstance(node, ast.FunctionDef):
            top[node.name] = node
        elif isinstance(node, (ast.AnnAssign, ast.Assign)):
            t = node.target if isinstance(node, ast.AnnAssign) else node.targets[0]
            top[getattr(t, "id", "")] = node
    return top


def public(cls):
    return {n for n in dir(cls) if not n.startswith("_")}


@pytest.mark.parametrize("module,name", [(scanfit.sums, "sums"), (scanfit, "__init__")])
def test_every_export_and_method_is_in_the_stub(module, name):
    declared = stub(name)
    for export in module.__all__:
        if export == "__version__":
            continue
        assert export in declared, f"{name}.pyi lacks {export}"
        obj = getattr(module, export)
        if inspect.isclass(obj) and not issubclass(obj, Exception):
            missing = public(obj) - set(declared[export])
            assert not missing, f"{name}.pyi: {export} lacks {sorted(missing)}"


def test_the_dask_stub_has_the_functions_keywords():
    pytest.importorskip("dask")
    import scanfit.dask as sd

    declared = stub("dask")
    for fn in sd.__all__:
        node = declared[fn]
        stub_args = [a.arg for a in node.args.args + node.args.kwonlyargs]
        assert stub_args == list(inspect.signature(getattr(sd, fn)).parameters), fn


def test_the_stubbed_keyword_defaults_match_the_native_signatures():
    # fit_surface and mba: the stub's parameters in the native order
    declared = stub("__init__")
    for fn in ("fit_surface", "mba"):
        node = declared[fn]
        names = [a.arg for a in node.args.args]
        assert names == list(inspect.signature(getattr(scanfit, fn)).parameters), fn

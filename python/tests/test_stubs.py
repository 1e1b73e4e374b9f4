"""The type stubs match the native module: every function and method of `_core.pyi` has the
real signature (names, kinds, defaults), and everything public in `_core` has a stub."""

import ast
import inspect
import pathlib

import pytest

from hdi_tribology import _core

STUB = pathlib.Path(_core.__file__).with_name("_core.pyi")
if not STUB.exists():  # an installed package keeps the stub beside its sources
    STUB = pathlib.Path(__file__).resolve().parents[1] / "hdi_tribology" / "_core.pyi"

KINDS = {
    "posonly": inspect.Parameter.POSITIONAL_ONLY,
    "args": inspect.Parameter.POSITIONAL_OR_KEYWORD,
    "kwonly": inspect.Parameter.KEYWORD_ONLY,
}


def _stub_params(fn: ast.FunctionDef, method: bool):
    a = fn.args
    params = []
    positional = [(p, "posonly") for p in a.posonlyargs] + [(p, "args") for p in a.args]
    defaults = [None] * (len(positional) - len(a.defaults)) + list(a.defaults)
    for (p, kind), d in zip(positional, defaults):
        params.append((p.arg, KINDS[kind], d))
    if a.vararg is not None:
        params.append((a.vararg.arg, inspect.Parameter.VAR_POSITIONAL, None))
    for p, d in zip(a.kwonlyargs, a.kw_defaults):
        params.append((p.arg, KINDS["kwonly"], d))
    if a.kwarg is not None:
        params.append((a.kwarg.arg, inspect.Parameter.VAR_KEYWORD, None))
    if method and params and params[0][0] in ("self", "cls"):
        params = params[1:]
    return params


def _check(stub_fn: ast.FunctionDef, real, method: bool, where: str):
    try:
        sig = inspect.signature(real)
    except (ValueError, TypeError):
        pytest.fail(f"{where}: the native object has no signature to check")
    real_params = [p for p in sig.parameters.values() if p.name not in ("self", "cls")]
    stub = _stub_params(stub_fn, method)
    assert [p[0] for p in stub] == [p.name for p in real_params], where
    for (name, kind, default), p in zip(stub, real_params):
        # PyO3 gives `/`-less signatures: positional-or-keyword either way
        assert kind == p.kind, f"{where}({name}): {kind} in the stub, {p.kind} natively"
        assert (default is None) == (p.default is inspect.Parameter.empty), f"{where}({name})"
        if default is not None and p.default is not ...:
            assert ast.literal_eval(default) == p.default, f"{where}({name})"


def test_the_stub_matches_the_native_module():
    tree = ast.parse(STUB.read_text())
    stubbed = set()
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            stubbed.add(node.name)
            _check(node, getattr(_core, node.name), False, node.name)
        elif isinstance(node, ast.ClassDef) and hasattr(_core, node.name):
            stubbed.add(node.name)
            cls = getattr(_core, node.name)
            for item in node.body:
                if not isinstance(item, ast.FunctionDef):
                    continue
                where = f"{node.name}.{item.name}"
                assert hasattr(cls, item.name), where
                decorators = {getattr(d, "id", None) for d in item.decorator_list}
                if "property" in decorators or item.name.startswith("__"):
                    continue
                _check(item, getattr(cls, item.name), "staticmethod" not in decorators, where)
        elif isinstance(node, (ast.AnnAssign,)) and isinstance(node.target, ast.Name):
            stubbed.add(node.target.id)
    public = {n for n in dir(_core) if not n.startswith("_")} | {"__version__"}
    # the native Drive is wrapped by hdi_tribology.Drive (a Python class, its own stub)
    missing = public - stubbed - {"Drive"}
    assert not missing, f"no stub for {sorted(missing)}"

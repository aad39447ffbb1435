"""The type stub and the extension agree: every public function and method the stub declares
has the extension's parameters, in order, with the same kinds and defaults (what `help()` and
editors show comes from the extension, what type checkers see from the stub)."""

import ast
import inspect
import re
from pathlib import Path

import pytest

import ridi

STUB = Path(ridi.__file__).with_name("_ridi.pyi")


def stub_functions():
    """`(qualified name, ast.FunctionDef)` for each function and method of the stub, but
    properties and dunders other than `__init__`."""
    tree = ast.parse(STUB.read_text())
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            yield node.name, node
        elif isinstance(node, ast.ClassDef):
            for item in node.body:
                if not isinstance(item, ast.FunctionDef):
                    continue
                decorators = {ast.unparse(d) for d in item.decorator_list}
                if "property" in decorators:
                    continue
                if item.name.startswith("__") and item.name != "__init__":
                    continue
                yield f"{node.name}.{item.name}", item


def plain(kind):
    # Methods show `self` positional-only in the extension's signature, and the stub marks
    # no parameter so: the two kinds are one here.
    if kind == inspect.Parameter.POSITIONAL_ONLY:
        return inspect.Parameter.POSITIONAL_OR_KEYWORD
    return kind


def stub_parameters(fn):
    """`(name, kind, default)` per parameter, `self` left out; a default as its Python value."""
    a = fn.args
    positional = a.posonlyargs + a.args
    defaults = [inspect.Parameter.empty] * (len(positional) - len(a.defaults)) + [
        ast.literal_eval(d) for d in a.defaults
    ]
    keyword = inspect.Parameter.POSITIONAL_OR_KEYWORD
    out = [(p.arg, keyword, d) for p, d in zip(positional, defaults)]
    for p, d in zip(a.kwonlyargs, a.kw_defaults):
        default = inspect.Parameter.empty if d is None else ast.literal_eval(d)
        out.append((p.arg, inspect.Parameter.KEYWORD_ONLY, default))
    return [p for p in out if p[0] != "self"]


def runtime_parameters(qualname):
    if qualname.endswith(".__init__"):
        # A class built in Rust documents its constructor on the class itself.
        obj = getattr(ridi, qualname.split(".")[0])
    else:
        obj = ridi
        for part in qualname.split("."):
            obj = getattr(obj, part)
    params = inspect.signature(obj).parameters.values()
    return [(p.name, plain(p.kind), p.default) for p in params if p.name != "self"]


FUNCTIONS = list(stub_functions())


def test_the_stub_declares_every_public_name():
    tree = ast.parse(STUB.read_text())
    declared = {getattr(n, "name", None) for n in tree.body} | {
        t.id
        for n in tree.body
        if isinstance(n, (ast.Assign, ast.AnnAssign))
        for t in (n.targets if isinstance(n, ast.Assign) else [n.target])
        if isinstance(t, ast.Name)
    }
    public = {n for n in dir(ridi) if not n.startswith("_")} - {"annotations"}
    assert public <= declared, f"not in the stub: {sorted(public - declared)}"


@pytest.mark.parametrize("qualname,fn", FUNCTIONS, ids=[q for q, _ in FUNCTIONS])
def test_the_stub_and_the_extension_have_one_signature(qualname, fn):
    runtime = runtime_parameters(qualname)
    for name, _, default in runtime:
        # A default pyo3 cannot print (a Rust path) shows as `...` to `help()`.
        assert default is not Ellipsis, f"{qualname}: `{name}` shows its default as `...`"
    assert runtime == stub_parameters(fn)


@pytest.mark.parametrize("name", sorted(n for n in dir(ridi) if not n.startswith("_")))
def test_every_public_name_has_its_docstring(name):
    obj = getattr(ridi, name)
    if callable(obj):
        assert (obj.__doc__ or "").strip(), f"ridi.{name} has no docstring for help()"


def test_the_stubs_orientation_sources_are_the_ones_taken(seq):
    init = dict(stub_functions())["Sequence.__init__"]
    arg = next(a for a in init.args.kwonlyargs if a.arg == "orientation_source")
    stubbed = {c.value for c in ast.walk(arg.annotation) if isinstance(c, ast.Constant)}
    args = {
        "time": seq.time, "gyro": seq.gyro, "acce": seq.acce, "gravity": seq.gravity,
        "orientation": seq.orientation,
    }
    with pytest.raises(ValueError) as refused:
        ridi.Sequence(**args, orientation_source="compass")
    taken = set(re.findall(r"'([a-z-]+)'", str(refused.value).split("expected one of")[1]))
    assert stubbed == taken


def test_the_stubs_formats_are_the_ones_taken():
    # `Format` of the stub against the names `format=` takes (ridi_data::Format::ALL's keys).
    tree = ast.parse(STUB.read_text())
    alias = next(n for n in tree.body if isinstance(n, ast.Assign)
                 and any(getattr(t, "id", None) == "Format" for t in n.targets))
    stubbed = [c.value for c in ast.walk(alias.value) if isinstance(c, ast.Constant)]
    with pytest.raises(ValueError) as refused:
        ridi.read("anything", format="csv")
    taken = re.findall(r"'([a-z-]+)'", str(refused.value).split("expected one of")[1])
    assert stubbed == taken

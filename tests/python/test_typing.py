"""The package is typed (PEP 561): py.typed ships beside the modules, and every public function and
method of the names in cadclash.__all__ annotates its parameters and return value."""
import inspect
import pathlib

import cadclash


def _public_callables():
    for name in cadclash.__all__:
        obj = getattr(cadclash, name)
        if inspect.isclass(obj):
            for attr, member in vars(obj).items():
                if attr.startswith("_"):
                    continue
                if isinstance(member, (classmethod, staticmethod)):
                    member = member.__func__
                elif isinstance(member, property):
                    member = member.fget
                if inspect.isfunction(member):
                    yield f"{name}.{attr}", member
        elif inspect.isfunction(obj):
            yield name, obj


def test_py_typed_ships_with_the_package():
    assert (pathlib.Path(cadclash.__file__).parent / "py.typed").is_file()


def test_every_public_callable_is_annotated():
    missing = []
    checked = 0
    for qualname, f in _public_callables():
        checked += 1
        sig = inspect.signature(f)
        missing += [f"{qualname}({p.name})" for p in sig.parameters.values()
                    if p.name not in ("self", "cls") and p.annotation is inspect.Parameter.empty]
        if sig.return_annotation is inspect.Signature.empty:
            missing.append(f"{qualname} -> ?")
    assert checked > 20  # the package's functions and methods were found
    assert missing == []

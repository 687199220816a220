"""ancfdrv.records.record against the standard library's dataclass it stands in for: the
same classes made both ways behave the same (construction, defaults, factories,
__post_init__, errors, repr, equality, hashing, frozen assignment, replace, asdict,
pickling), and no record of the package compiles source when it is defined."""
from __future__ import annotations

import ast
import dataclasses
import pickle
import subprocess
import sys
from dataclasses import FrozenInstanceError, dataclass, field

import pytest

from ancfdrv.records import record


def _pair(**options):
    """The same class body made by dataclass and by record, with the same name."""
    made = []
    for decorate in (dataclass, record):
        class Part:
            name: str
            size: float = 1.0
            tags: list = field(default_factory=list)
            hidden: int = field(default=0, repr=False, compare=False)
            cache: dict = field(default_factory=dict, init=False, repr=False, compare=False)

            def __post_init__(self) -> None:
                if self.size < 0:
                    raise ValueError("size must be >= 0")
                object.__setattr__(self, "area", self.size ** 2)

        made.append(decorate(**options)(Part))
    return made


@record
class Point:
    x: float
    y: float = 0.0


@record(frozen=True)
class Key:
    name: str
    index: int = 0


OPTIONS = [{}, {"eq": False}, {"eq": False, "repr": False}, {"frozen": True},
           {"frozen": True, "eq": False}, {"frozen": True, "eq": False, "repr": False}]


@pytest.mark.parametrize("options", OPTIONS)
def test_construction_and_methods_match_dataclass(options):
    std, rec = _pair(**options)
    for args, kwargs in [(("a",), {}), (("a", 2.0), {}), (("a",), {"tags": [1]}),
                         ((), {"name": "b", "size": 3.0, "hidden": 4})]:
        s, r = std(*args, **kwargs), rec(*args, **kwargs)
        assert vars(s) == vars(r)          # the fields, the factory's and __post_init__'s
        if options.get("repr", True):
            assert repr(s) == repr(r)
        assert (s == std(*args, **kwargs)) == (r == rec(*args, **kwargs))
        assert (s == s) and (r == r)
    # a factory makes a new object per instance
    assert rec("a").tags is not rec("a").tags and rec("a").cache is not rec("a").cache
    assert (rec.__hash__ is None) == (std.__hash__ is None)
    if std.__hash__ is not None and options.get("eq", True):   # frozen: the fields' hash
        with pytest.raises(TypeError, match="unhashable type: 'list'"):
            hash(rec("a"))
        std_hash, rec_hash = std.__hash__, rec.__hash__
        assert std_hash(std("a", 2.0, None)) == rec_hash(rec("a", 2.0, None))
    with pytest.raises(ValueError, match="size must be"):
        rec("a", -1.0)
    assert dataclasses.is_dataclass(rec)
    assert [f.name for f in dataclasses.fields(rec)] == [f.name for f in dataclasses.fields(std)]
    assert dataclasses.asdict(rec("a", 2.0)) == dataclasses.asdict(std("a", 2.0))
    assert vars(dataclasses.replace(rec("a"), size=5.0)) == vars(std("a", 5.0))


@pytest.mark.parametrize("args, kwargs, message", [
    ((), {}, "missing 1 required positional argument: 'name'"),
    (("a", 1.0, [], 0, 9), {}, "takes from 2 to 5 positional arguments but 6 were given"),
    (("a",), {"colour": 1}, "unexpected keyword argument 'colour'"),
    (("a",), {"name": "b"}, "multiple values for argument 'name'"),
    (("a",), {"cache": {}}, "unexpected keyword argument 'cache'"),
])
def test_bad_arguments_raise_as_dataclass(args, kwargs, message):
    std, rec = _pair()
    with pytest.raises(TypeError, match=message):
        std(*args, **kwargs)
    with pytest.raises(TypeError, match=message):
        rec(*args, **kwargs)


def test_equality_is_per_class_and_field():
    assert Point(1.0, 2.0) == Point(1.0, 2.0) and Point(1.0) != Point(1.0, 2.0)
    assert Point(1.0).__eq__((1.0, 0.0)) is NotImplemented
    assert Point.__hash__ is None                       # eq without frozen: unhashable
    with pytest.raises(TypeError):
        hash(Point(1.0))
    std, rec = _pair(eq=False)
    r = rec("a")
    assert r != rec("a") and r == r and hash(r) == object.__hash__(r)


def test_frozen_records_refuse_assignment_and_hash_their_fields():
    key = Key("boom", 2)
    with pytest.raises(FrozenInstanceError, match="cannot assign to field 'index'"):
        key.index = 3
    with pytest.raises(FrozenInstanceError, match="cannot delete field 'name'"):
        del key.name
    assert {Key("boom", 2): 1}[Key("boom", 2)] == 1
    assert hash(key) == hash(("boom", 2))


def test_records_pickle():
    for value in (Point(1.5, -2.0), Key("jib", 1)):
        assert pickle.loads(pickle.dumps(value)) == value


def test_no_record_of_the_package_compiles_source_at_import():
    """Every dataclass of the package is a record: once all its modules are imported (a
    fresh interpreter) no __repr__, __eq__, __setattr__ or __hash__ is source compiled
    (co_filename '<string>'), and an __init__ only where the import itself made an
    instance (the scene keys' Key and the kinds' Kind: 2 of 75 records)."""
    probe = """
import dataclasses, importlib, pkgutil, ancfdrv
compiled, records = [], 0
for info in pkgutil.walk_packages(ancfdrv.__path__, "ancfdrv."):
    if info.name.startswith("ancfdrv._kernel"):
        continue
    module = importlib.import_module(info.name)
    for value in vars(module).values():
        if (isinstance(value, type) and dataclasses.is_dataclass(value)
                and value.__module__ == info.name):
            records += 1
            for name in ("__repr__", "__eq__", "__setattr__", "__hash__", "__init__"):
                code = getattr(value.__dict__.get(name), "__code__", None)
                if code is not None and code.co_filename == "<string>":
                    compiled.append(f"{value.__qualname__}.{name}")
print(records, compiled)
"""
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         check=True).stdout.split(" ", 1)
    records, compiled = int(out[0]), ast.literal_eval(out[1])
    assert records > 60
    assert all(name.endswith(".__init__") for name in compiled), compiled
    assert len(compiled) <= 5, compiled


def test_init_is_compiled_once_on_first_use():
    @record
    class Part:
        name: str
        size: float = 1.0

    stub = Part.__init__
    assert stub.__code__.co_filename != "<string>"
    assert vars(Part("a")) == {"name": "a", "size": 1.0}
    assert Part.__init__ is not stub and Part.__init__.__code__.co_filename == "<string>"
    compiled = Part.__init__
    Part("b", 2.0)
    assert Part.__init__ is compiled

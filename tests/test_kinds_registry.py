"""The registry of kinds (issue 36, "One kind, one module"; SPEC section 9): every kind is
declared once, in its module of python/ancfdrv/system/kinds/, and generic code asks the
registry instead of naming concrete classes.

- a ratchet: the checks on concrete kinds outside system/kinds/ (``isinstance``/``issubclass``
  on a kind's class, ``type(x) is <class>``, a ``.type``/``.kind``/``.formulation``
  compared with a kind's name or set kind) are counted from the sources with the ast module
  and may only go down;
- the registry lists every kind, each kind's keys are the general schema's group (each key
  spelled once), and ``System.add(group, **values)`` builds the same body as the typed
  method (same coordinates, same mass matrix);
- the typed methods (System.beam, ...) take exactly their kind's keys and API keywords (their
  signatures and docstrings are made from the kind), accept a key the old hand-written
  signatures missed and refuse an unknown one with the namelist's message."""
from __future__ import annotations

import ast
import inspect
import textwrap
from pathlib import Path

import numpy as np
import pytest

import ancfdrv
from ancfdrv.errors import InputError
from ancfdrv.io.schema import GENERAL_SCHEMA, REQUIRED, Key
from ancfdrv.system import Box, Rectangle, System
from ancfdrv.system.registry import kind, kind_of, kinds
from ancfdrv.system.system import _typed

PACKAGE = Path(ancfdrv.__file__).resolve().parent
KINDS_DIR = PACKAGE / "system" / "kinds"

#: checks on concrete kinds outside system/kinds/ (issue 36 item 2: 90 by this count before
#: the registry, 0 since): generic code asks a body or the registry, never its class
MAX_CONCRETE_CHECKS = 0

#: the kinds' groups, in registration order (system/kinds/__init__.py)
GROUPS = ["beam", "cable", "force_element", "plate", "leaf", "rigid_body"]


def _concrete_classes() -> set[str]:
    names = set()
    for k in kinds():
        names.add(k.body_class.__name__)
        stack = list(k.body_class.__subclasses__())
        while stack:
            cls = stack.pop()
            names.add(cls.__name__)
            stack += cls.__subclasses__()
    return names


def _kind_words() -> set[str]:
    words = {k.group for k in kinds()}
    for k in kinds():
        words |= set(k.adders)
    return words


def _names(node: ast.AST) -> list[str]:
    """The class names an isinstance's second argument (a name, an attribute, a tuple)."""
    if isinstance(node, ast.Tuple):
        return [n for elt in node.elts for n in _names(elt)]
    if isinstance(node, ast.Name):
        return [node.id]
    if isinstance(node, ast.Attribute):
        return [node.attr]
    return []


def _strings(node: ast.AST) -> list[str]:
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return [node.value]
    if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
        return [s for elt in node.elts for s in _strings(elt)]
    return []


def concrete_checks(source: str, classes: set[str], words: set[str]) -> list[int]:
    """The lines of the checks on concrete kinds in one module's source."""
    lines = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and \
                node.func.id in ("isinstance", "issubclass") and len(node.args) == 2:
            if set(_names(node.args[1])) & classes:
                lines.append(node.lineno)
        elif isinstance(node, ast.Compare):
            sides = [node.left, *node.comparators]
            typed = any(isinstance(s, ast.Call) and isinstance(s.func, ast.Name) and
                        s.func.id == "type" for s in sides)
            if typed and any(set(_names(s)) & classes for s in sides):
                lines.append(node.lineno)
                continue
            attribute = any(isinstance(s, ast.Attribute) and
                            s.attr in ("type", "kind", "formulation") for s in sides)
            if attribute and any(set(_strings(s)) & words for s in sides):
                lines.append(node.lineno)
    return lines


def count_concrete_checks() -> dict[str, list[int]]:
    classes, words = _concrete_classes(), _kind_words()
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        if KINDS_DIR in path.parents:
            continue
        found = concrete_checks(path.read_text(), classes, words)
        if found:
            out[str(path.relative_to(PACKAGE))] = found
    return out


def test_the_counter_finds_each_form_of_check():
    source = ("isinstance(b, Beam)\nisinstance(b, (Ground, kinds.Plate))\ntype(b) is Leaf\n"
              "s.kind == 'ffr'\nj.type in ('cable', 'x')\nisinstance(b, Ground)\n"
              "j.type == 'revolute'\nb.name == 'beam'\n")
    assert concrete_checks(source, {"Beam", "Plate", "Leaf"}, {"ffr", "cable"}) == \
        [1, 2, 3, 4, 5]


def test_checks_on_concrete_kinds_only_go_down():
    found = count_concrete_checks()
    total = sum(map(len, found.values()))
    assert total <= MAX_CONCRETE_CHECKS, found


def test_the_registry_lists_every_kind():
    assert [k.group for k in kinds()] == GROUPS
    assert {k.body_class.__name__ for k in kinds()} == \
        {"Beam", "Cable", "ForceElement", "Plate", "Leaf", "RigidBody"}
    for k in kinds():
        assert kind(k.group) is k
        assert callable(getattr(System, k.api))
    sets = {name for k in kinds() for name in k.adders}
    assert sets == {"ffr", "continuum", "cubic", "cable", "plate"}
    assert kind("joint") is None and kind_of(System().ground) is None


def test_each_kind_module_stands_alone():
    """No kind module imports another (each is a kind's whole Python side)."""
    modules = {p.stem for p in KINDS_DIR.glob("*.py") if p.stem != "__init__"}
    assert modules == {"beam", "cable", "plate", "rigid_body", "force_element"}
    for path in KINDS_DIR.glob("*.py"):
        if path.stem == "__init__":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level == 1:
                assert node.module is None or node.module.split(".")[0] not in modules, path
                assert not {a.name for a in node.names} & modules, path


def test_each_kind_key_is_in_the_general_schema_once():
    """The general schema's group of a kind is the kind's own key table (one spelling)."""
    for k in kinds():
        assert GENERAL_SCHEMA[k.group] is k.keys
        assert list(GENERAL_SCHEMA).count(k.group) == 1
    # a kind's key appears in no other group of the general schema by identity
    for k in kinds():
        for group, keys in GENERAL_SCHEMA.items():
            if group != k.group:
                assert not {id(x) for x in keys.values()} & {id(x) for x in k.keys.values()}
    groups = list(GENERAL_SCHEMA)
    assert groups[0] == "material" and groups[1:1 + len(GROUPS)] == GROUPS


def _mass_and_q(system: System) -> tuple[np.ndarray, np.ndarray]:
    model = system.assemble(effects=())
    mass = model.mass_matrix().toarray()
    return model.q0.copy(), mass


def _close(a: np.ndarray, b: np.ndarray) -> None:
    assert a.shape == b.shape
    assert np.abs(a - b).max() <= 1e-14 * max(np.abs(a).max(), 1e-300)


@pytest.mark.parametrize("group", ["beam", "cable", "plate", "leaf", "rigid_body"])
def test_add_builds_what_the_typed_method_builds(group):
    typed, generic = System(), System()
    for s in (typed, generic):
        s.material("steel", youngs_modulus=2.1e11, density=7850.0, poisson_ratio=0.3)
    if group == "beam":
        typed.beam("b", material="steel", start=(0, 0, 0), end=(2, 0, 0), nodes=4,
                   section=Rectangle(0.05, 0.1), formulation="nonlinear")
        generic.add("beam", name="b", material="steel", start=(0, 0, 0), end=(2, 0, 0),
                    nodes=4, section="rectangle", width=0.05, height=0.1,
                    formulation="nonlinear")
    elif group == "cable":
        typed.cable("b", material="steel", start=(0, 0, 0), end=(0, 0, -3), nodes=5)
        generic.add("cable", name="b", material="steel", start=(0, 0, 0), end=(0, 0, -3),
                    nodes=5)
    elif group == "plate":
        args = dict(material="steel", thickness=0.01, corner=(0, 0, 0), edge_x=(1, 0, 0),
                    edge_y=(0, 0.5, 0), nx=3, ny=2)
        typed.plate("b", **args)
        generic.add("plate", name="b", **args)
    elif group == "leaf":
        args = dict(material="steel", thickness=0.01, width=0.06, arc_length=1.0, radius=2.0,
                    centre=(0, 0, 0), nx=4, ny=1)
        typed.leaf("b", **args)
        generic.add("leaf", name="b", **args)
    else:
        args = dict(mass=3.0, inertia=(0.1, 0.2, 0.3, 0.0, 0.0, 0.0), position=(1, 2, 3))
        typed.rigid_body("b", **args)
        generic.add("rigid_body", name="b", **args)
    assert type(typed.bodies["b"]) is type(generic.bodies["b"])
    assert kind_of(generic.bodies["b"]).group == group
    (q_typed, m_typed), (q_generic, m_generic) = _mass_and_q(typed), _mass_and_q(generic)
    _close(q_typed, q_generic)
    _close(m_typed, m_generic)


def test_add_refuses_an_unknown_group_and_key():
    s = System()
    with pytest.raises(InputError, match="unknown group 'bean'.*beam, cable"):
        s.add("bean", name="x")
    s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    with pytest.raises(InputError, match="unknown key 'lenght'"):
        s.add("beam", name="b", material="steel", start=(0, 0, 0), end=(1, 0, 0), nodes=3,
              lenght=1.0)
    with pytest.raises(InputError, match="nodes is required"):
        s.add("cable", name="c", material="steel", start=(0, 0, 0), end=(1, 0, 0))
    # the namelist's check and message, through the Python door
    with pytest.raises(InputError, match=r"beam\[b\].*nodes.*must be at least 2"):
        s.add("beam", name="b", material="steel", start=(0, 0, 0), end=(1, 0, 0), nodes=1)


# -- the typed methods: thin wrappers over System.add whose keywords are the kind's keys --

@pytest.mark.parametrize("group", GROUPS)
def test_the_typed_method_lists_exactly_the_kinds_keys(group):
    found = kind(group)
    method = getattr(System, found.api)
    params = inspect.signature(method).parameters
    assert list(params)[0] == "self"
    assert not [p for p in params.values() if p.kind in (p.VAR_KEYWORD, p.VAR_POSITIONAL)]
    assert set(params) - {"self"} == set(found.keys) | set(found.api_keys)
    assert len(params) - 1 == len(found.keys) + len(found.api_keys)
    # a required keyword has no default, an optional one shows one (a positional parameter
    # keeps the API's: force_element's body2 follows body1 = 'ground'); help() names each key
    for k, key in found.keys.items():
        required = key.default is REQUIRED and k not in found.scene_defaults
        if params[k].kind is params[k].KEYWORD_ONLY:
            assert (params[k].default is inspect.Parameter.empty) == required, k
        assert f"``{k}``" in method.__doc__, k


def test_the_typed_methods_keep_their_positional_parameters():
    positional = {found.api: [n for n, p in inspect.signature(
        getattr(System, found.api)).parameters.items() if p.kind is p.POSITIONAL_OR_KEYWORD]
        for found in kinds()}
    assert positional == {"beam": ["self", "name"], "cable": ["self", "name"],
                          "plate": ["self", "name"], "leaf": ["self", "name"],
                          "rigid_body": ["self", "name"],
                          "force_element": ["self", "name", "type", "body1", "body2"]}


def test_a_key_added_to_a_kind_is_a_keyword_of_its_typed_method(monkeypatch):
    monkeypatch.setitem(kind("plate").keys, "colour", Key("str", "grey", doc="its colour"))

    def plate(self, name: str, **values):
        """A plate."""

    made = _typed("plate")(plate)
    colour = inspect.signature(made).parameters["colour"]
    assert colour.kind is colour.KEYWORD_ONLY and colour.default == "grey"
    assert "``colour`` (str; default 'grey'): its colour" in made.__doc__


def test_keys_absent_from_the_old_signatures_are_accepted():
    """The old System.beam took a section only as a Section object and System.leaf required
    ny: the kind's namelist form of the section and the default ny = 1 now pass."""
    by_keys, by_object = System(), System()
    for s in (by_keys, by_object):
        s.material("steel", youngs_modulus=2.1e11, density=7850.0, poisson_ratio=0.3)
    by_keys.beam("b", material="steel", start=(0, 0, 0), end=(2, 0, 0), nodes=4,
                 section="box", width=0.05, height=0.1, wall=0.005, formulation="nonlinear")
    by_object.beam("b", material="steel", start=(0, 0, 0), end=(2, 0, 0), nodes=4,
                   section=Box(0.05, 0.1, 0.005), formulation="nonlinear")
    assert by_keys.bodies["b"].section.area == pytest.approx(0.05 * 0.1 - 0.04 * 0.09,
                                                             rel=1e-12)
    leaf = dict(material="steel", thickness=0.01, width=0.06, arc_length=1.0, radius=2.0,
                centre=(0, 0, 0), nx=4)
    by_keys.leaf("l", **leaf)
    by_object.leaf("l", **leaf, ny=1)
    assert by_keys.bodies["l"].ny == 1
    (q_keys, m_keys), (q_object, m_object) = _mass_and_q(by_keys), _mass_and_q(by_object)
    _close(q_keys, q_object)
    _close(m_keys, m_object)


@pytest.mark.parametrize("api, args", [
    ("beam", dict(material="steel", start=(0, 0, 0), end=(1, 0, 0), nodes=3)),
    ("rigid_body", dict(mass=1.0, inertia=(1, 1, 1, 0, 0, 0), position=(0, 0, 0))),
])
def test_the_typed_method_refuses_an_unknown_keyword_naming_it(api, args):
    s = System()
    s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    with pytest.raises(InputError, match=rf"{api}\[b\].*unknown key 'lenght' \(the keys of "
                                         rf"&{api}: name, "):
        getattr(s, api)("b", **args, lenght=1.0)
    assert "b" not in s.bodies
    with pytest.raises(InputError, match=r"force_element\[f\].*unknown key 'stifness'"):
        s.force_element("f", "spring_damper", "ground", "ground", point1=(0, 0, 0),
                        point2=(1, 0, 0), stifness=1.0)


def test_the_typed_methods_key_lines_wrap_as_textwrap_does():
    """The typed methods' key lines (system._fill, a plain word wrap at 88 characters) break
    where textwrap.fill breaks them when it splits no word at a hyphen, and keep every
    word."""
    from ancfdrv.system.system import _fill
    lines = []
    for found in kinds():
        doc = getattr(System, found.api).__doc__.split("an unknown one is refused):")[1]
        lines += ["- " + part.replace("\n  ", " ").strip() for part in doc.split("\n- ")[1:]]
    assert len(lines) > 50
    for line in lines:
        ours = _fill(line)
        assert ours.replace("\n  ", " ") == line
        theirs = textwrap.fill(line, 88, subsequent_indent="  ", break_on_hyphens=False)
        assert ours == theirs, line

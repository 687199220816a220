"""The scene reference docs/scenes.md is generated from the schema (issue 22 item 4) and kept
in sync: regenerating it gives the committed file. Every type the namelist accepts is
documented with its parameters, and the namelist and the Python API take the same drive
parameters (the dataclass fields of each drive are namelist keys of its type)."""
from __future__ import annotations

import dataclasses
from pathlib import Path

from ancfdrv import scenedoc
from ancfdrv.builders.general import _DRIVE_KEYS
from ancfdrv.io.schema import GENERAL_SCHEMA, SCHEMA
from ancfdrv.system.drives import DRIVE_TYPES
from ancfdrv.system.joints import JOINT_TYPES
from ancfdrv.system.system import LOAD_PARAMETERS

DOC = Path(__file__).resolve().parents[1] / "docs" / "scenes.md"


def test_docs_scenes_md_is_the_generated_reference():
    assert DOC.read_text() == scenedoc.render(), (
        "docs/scenes.md is out of date: run python -m ancfdrv.scenedoc -o docs/scenes.md")


def test_every_group_key_and_type_is_in_the_reference():
    text = DOC.read_text()
    for schema in (SCHEMA, GENERAL_SCHEMA):
        for group, keys in schema.items():
            heading = f"### `&{group}`"
            if schema is SCHEMA and group in GENERAL_SCHEMA:
                heading += scenedoc.TEMPLATE_SUFFIX
            assert heading + "\n" in text, heading
            section = text.split(heading + "\n", 1)[1].split("### ", 1)[0]
            for key in keys:
                assert f"| `{key}` |" in section, (group, key)
    choices = {g: set(GENERAL_SCHEMA[g]["type"].check.choices) for g in ("drive", "joint",
                                                                         "load")}
    assert choices["drive"] == set(DRIVE_TYPES)
    assert choices["joint"] == set(JOINT_TYPES) == set(scenedoc.JOINT_PARAMETERS)
    assert choices["load"] == set(LOAD_PARAMETERS)
    for kind in DRIVE_TYPES:
        assert f"| `{kind}` |" in text


def test_namelist_drives_take_the_python_parameters():
    """Each drive class's parameters (its dataclass fields) are keys the namelist takes for
    that type, and the other way round (constant's value_ is the keyword 'value')."""
    for kind, cls in DRIVE_TYPES.items():
        fields = {f.name.rstrip("_") for f in dataclasses.fields(cls)} - {"name"}
        if kind == "luffing":
            namelist = {"omega", "t_start", "t_brake", "sweep", "start"}
        elif kind == "table":
            namelist = {"times", "values", "interpolation"}
        else:
            namelist = set(_DRIVE_KEYS[kind].values())
        assert fields == namelist, kind
        for key in namelist:
            assert key in GENERAL_SCHEMA["drive"], (kind, key)

"""Markdown reference tables of config sections, written from the fields' own descriptions and defaults, so
the documentation cannot drift from the code (a test compares the docs with this output).

``python3 -m react3d_core.config.reference perception.models`` prints the table of that section.
"""

from __future__ import annotations

import json
import sys
from typing import Any

from pydantic import BaseModel

from . import PipelineConfig


def section(path: str) -> type[BaseModel]:
    """The config model at a dotted path of :class:`PipelineConfig`, e.g. ``perception.models``."""
    model: type[BaseModel] = PipelineConfig
    for name in path.split("."):
        field = model.model_fields.get(name)
        sub = getattr(field, "annotation", None)
        if field is None or not (isinstance(sub, type) and issubclass(sub, BaseModel)):
            raise KeyError(f"{path}: no config section {name!r} in {model.__name__}")
        model = sub
    return model


def _cell(value: Any) -> str:
    """A default as JSON would write it (strings quoted, None as null), long ones cut short."""
    text = json.dumps(value, ensure_ascii=False)
    if len(text) > 60:
        text = text[:57] + "…"
    return "`" + text.replace("|", "\\|") + "`"


def markdown_table(model: type[BaseModel], prefix: str = "") -> str:
    """One row per field: name, default, what it does (nested sections are not expanded)."""
    rows = ["| field | default | what it does |", "|---|---|---|"]
    defaults = model().model_dump(mode="json")
    for name, info in model.model_fields.items():
        desc = (info.description or "").replace("|", "\\|")
        rows.append(f"| `{prefix}{name}` | {_cell(defaults[name])} | {desc} |")
    return "\n".join(rows) + "\n"


if __name__ == "__main__":
    path = sys.argv[1] if len(sys.argv) > 1 else "perception.models"
    sys.stdout.write(markdown_table(section(path)))

"""docs/15-python.md's API reference is the package's: every public function and
method with its signature and its docstring's first sentence, as this module makes
it. After changing the API, print the section anew and paste it in:
PYTHONPATH=<the package> python3 deploy/python/tests/test_docs.py"""
import inspect
import os
from pathlib import Path

import tactile

PUBLIC = ["Scenario.load", "Scenario.from_toml", "Scenario.paper", "Scenario.shipped",
          "Scenario.shipped_names", "Scenario.with_set", "Scenario.sets", "Scenario.check",
          "Scenario.to_toml", "run", "sweep", "read_sweep", "report", "export_lerobot", "Run", "Run.read",
          "Run.trace", "ScenarioError", "RunError", "CallbackError", "NoTraceWarning"]
START, END = "<!-- api reference: begin -->", "<!-- api reference: end -->"


def _annotation(a) -> str:
    return str(a).replace('"', "").replace("'", "")


def _signature(f) -> str:
    s = inspect.signature(f)
    parts = []
    for p in s.parameters.values():
        if p.name == "self":
            continue
        text = ("*" if p.kind is p.VAR_POSITIONAL else "") + p.name
        if p.annotation is not p.empty:
            text += f": {_annotation(p.annotation)}"
        if p.default is not p.empty:
            text += f" = {p.default!r}"
        parts.append(text)
    ret = "" if s.return_annotation is s.empty else f" -> {_annotation(s.return_annotation)}"
    return f"({', '.join(parts)}){ret}"


def _first_sentence(doc: str) -> str:
    text = " ".join(inspect.cleandoc(doc or "").split("\n\n")[0].split())
    return text.split(". ")[0].rstrip(".") + "."


def reference() -> str:
    lines = [START]
    for name in PUBLIC:
        obj = tactile
        for part in name.split("."):
            obj = (inspect.getattr_static(obj, part) if part in ("sets", "trace")
                   else getattr(obj, part))
        if isinstance(obj, property):
            head, doc = f"`tactile.{name}` (property)", obj.__doc__
        elif inspect.isclass(obj):
            base = obj.__mro__[1].__name__
            head = f"`tactile.{name}`" if base == "object" else f"`tactile.{name}({base})`"
            doc = obj.__doc__
        else:
            head, doc = f"`tactile.{name}{_signature(obj)}`", obj.__doc__
        lines.append(f"- {head}: {_first_sentence(doc)}")
    lines.append(END)
    return "\n".join(lines) + "\n"


def test_the_docs_api_reference_is_the_packages():
    docs = (Path(os.environ["TACTILE_ROOT"]) / "docs" / "15-python.md").read_text()
    start, end = docs.index(START), docs.index(END) + len(END) + 1
    assert docs[start:end] == reference(), "print it anew: python3 " + __file__


if __name__ == "__main__":
    print(reference(), end="")

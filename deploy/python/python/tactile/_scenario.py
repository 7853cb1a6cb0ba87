"""A scenario as a value: its TOML, where its relative paths are read, the `--set`s on
it; and the scenarios shipped inside the package."""
from __future__ import annotations

import math
import numbers
import os
from pathlib import Path
from typing import Any, List, Mapping, Optional, Sequence, Union

from . import _native
from ._native import ScenarioError

PathLike = Union[str, "os.PathLike[str]"]

# The shipped scenarios and the files they read, laid out as in the repository
# (deploy/scenarios, deploy/robots), so their relative paths hold.
SHIPPED = Path(__file__).resolve().parent / "scenarios"


def _toml_string(s: str) -> str:
    """A TOML basic string: quotes, backslashes and control characters escaped,
    everything else as it is (JSON's escapes would split a character outside the BMP
    into surrogates, which TOML refuses)."""
    out = []
    for ch in s:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _toml_value(key: str, v: Any) -> str:
    """A Python value (NumPy's scalars too) as the TOML literal `--set KEY=VALUE`
    takes."""
    if isinstance(v, bool) or getattr(getattr(v, "dtype", None), "kind", None) == "b":
        return "true" if v else "false"
    if isinstance(v, numbers.Integral):
        return str(int(v))
    if isinstance(v, numbers.Real):
        x = float(v)
        if not math.isfinite(x):
            raise ScenarioError(f"--set {key}: {x} is not a finite number")
        return repr(x)
    if isinstance(v, str):
        return _toml_string(v)
    if isinstance(v, (list, tuple)):
        return "[" + ",".join(_toml_value(key, x) for x in v) + "]"
    raise ScenarioError(f"--set {key}: a {type(v).__name__} is no TOML value "
                        "(give a number, a string, a bool or a list of them)")


def _text(text: Any, name: str) -> str:
    """A scenario's text, at most what the command reads from a file (the same limit
    and message): a larger one is refused before anything parses it."""
    if not isinstance(text, str):
        raise TypeError(f"{name}: a scenario's TOML is a str, not a {type(text).__name__}")
    limit = _native.MAX_SCENARIO_BYTES
    # Counted in characters first: a huge text is not encoded to be measured.
    size = len(text) if len(text) > limit else len(text.encode("utf-8", "surrogatepass"))
    if size > limit:
        raise ScenarioError(f"scenario {name} is {size} bytes, more than the {limit} a "
                            "scenario may have")
    return text


def _sets_fit(sets: Sequence[str], what: str) -> None:
    """`--set`s of at most what a scenario may hold (the command's are bounded by the
    system's argument list; a Python value is not): a larger value is refused before
    the compiled half copies it."""
    limit = _native.MAX_SCENARIO_BYTES
    size = sum(len(s.encode("utf-8", "surrogatepass")) for s in sets)
    if size > limit:
        raise ScenarioError(f"{what}: the values are {size} bytes of TOML, more than the "
                            f"{limit} a scenario may have")


class Scenario:
    """A scenario: its TOML, the folder its relative paths are read from, and the
    `--set`s to apply. Immutable: `with_set` returns a new one."""

    __slots__ = ("_text", "_base_dir", "_name", "_path", "_sets")

    def __init__(self, text: str, base_dir: PathLike = ".", name: str = "<scenario text>",
                 path: Optional[PathLike] = None, sets: Sequence[str] = ()):
        self._text = _text(text, name)
        self._base_dir = os.fspath(Path(base_dir).resolve())
        self._name = name
        self._path = None if path is None else os.fspath(Path(path).resolve())
        self._sets = tuple(sets)

    @classmethod
    def load(cls, path: PathLike) -> "Scenario":
        """The scenario in file `path`, read as the command reads it (UTF-8, at most
        1 MiB; the same errors); relative paths in it are read beside it."""
        text, base_dir, name = _native.read_scenario(os.fspath(path))
        return cls(text, base_dir, name, path)

    @classmethod
    def from_toml(cls, text: str, base_dir: PathLike = ".") -> "Scenario":
        """A scenario from its TOML text (at most 1 MiB, as a file); relative paths are
        read from `base_dir`."""
        return cls(text, base_dir)

    @classmethod
    def paper(cls) -> "Scenario":
        """The built-in paper scenario (what `tactile run` runs with no scenario)."""
        return cls(_native.PAPER_SCENARIO, ".", "deploy/scenarios/paper.toml (built in)")

    @classmethod
    def shipped(cls, name: str) -> "Scenario":
        """A scenario shipped inside the package, by name (`"wall-delay"`: the
        repository's `deploy/scenarios/wall-delay.toml`, with the files it reads); the
        names are `Scenario.shipped_names()`."""
        names = cls.shipped_names()
        if not isinstance(name, str) or name.removesuffix(".toml") not in names:
            raise ScenarioError(f"shipped scenario {name!r}: there is none of that name; "
                                f"the package ships {', '.join(names)}")
        return cls.load(SHIPPED / f"{name.removesuffix('.toml')}.toml")

    @staticmethod
    def shipped_names() -> List[str]:
        """The names of the scenarios shipped inside the package, sorted: what
        `Scenario.shipped` takes."""
        return sorted(p.stem for p in SHIPPED.glob("*.toml"))

    def with_set(self, values: Mapping[str, Any]) -> "Scenario":
        """A copy with `--set KEY=VALUE` for each entry: the same keys and checks as the
        command's (`network.forward.delay_ms`, `control.kind`, ...)."""
        if not isinstance(values, Mapping):
            raise TypeError(f"with_set: give a dict {{KEY: VALUE}}, not a "
                            f"{type(values).__name__}")
        for k in values:
            if not isinstance(k, str):
                raise TypeError(f"with_set: {k!r}: a key is a scenario key, a str "
                                "(network.forward.delay_ms, control.kind, ...)")
        sets = self._sets + tuple(f"{k}={_toml_value(k, v)}" for k, v in values.items())
        _sets_fit(sets, "with_set")
        # A key the scenario has not, or a value of the wrong type, raises here, where
        # it was typed; a value out of range (which may hang on keys still to be set)
        # waits for check() and the run.
        _native.check_sets(self._text, self._base_dir, self._name, self._path, list(sets))
        return Scenario(self._text, self._base_dir, self._name, self._path, sets)

    @property
    def sets(self) -> tuple:
        """The `--set`s applied, as the command takes them."""
        return self._sets

    def _source(self) -> tuple:
        return (self._text, self._base_dir, self._name, self._path, list(self._sets))

    def check(self) -> list:
        """Validates the scenario as `tactile check` does (inputs read, arm loaded);
        raises ScenarioError naming the field. Returns what check says (length,
        files, the delays in both units, warnings)."""
        return _native.check(*self._source())[1]

    def to_toml(self) -> str:
        """The scenario as it would run: every default filled in, the sets applied,
        paths resolved (`tactile check`'s output)."""
        return _native.check(*self._source())[0]

    def __repr__(self) -> str:
        sets = "".join(f" --set {s}" for s in self._sets)
        return f"<tactile.Scenario {self._name}{sets}>"


def scenario_of(scenario: Any, what: str) -> Scenario:
    """`scenario` if it is one, else TypeError saying how to make one."""
    if not isinstance(scenario, Scenario):
        raise TypeError(f"{what}: give a tactile.Scenario (tactile.Scenario.load('x.toml') "
                        f"reads a file, Scenario.shipped('wall-delay') a shipped one), not a "
                        f"{type(scenario).__name__}")
    return scenario


def out_folder(out: Any, what: str) -> Path:
    """An output folder as given: an empty path is refused (it would be the working
    folder, where a report's dozen files would land among the user's)."""
    path = os.fspath(out)
    if isinstance(path, bytes):
        path = os.fsdecode(path)
    if path == "":
        raise ScenarioError(f"{what}: out='' is no folder (it would be the working "
                            "folder); give a folder's name, or '.' to mean the working "
                            "folder")
    return Path(path)

"""The enhance options, read from the library's option table (include/vertexflow/enhance_options.h)
through the compiled module, and the functions built on them.

An option exists in Python exactly when it is in the table: the keywords, defaults, annotations
and docstrings of enhance, enhance_file, batch and enhance_options are made here at import time,
and the stub (python/generate_stub.py) is written from the same objects.
"""

import dataclasses
import inspect
import math
import textwrap
import typing
from collections.abc import Callable, Sequence

from . import _core

#: The names of the enhance modes (enhance.h), as reports and batch summaries give them.
ENHANCE_MODES: tuple[str, ...] = _core._enhance_mode_names()

#: Which options choose each mode, as the engine answers: [{name, reference, options}].
MODE_TABLE: tuple[dict, ...] = _core._enhance_mode_table()

#: The option that changes the faces: with it, enhance returns (V_out, F_out, report).
FACES_OPTION: str = _core._FACES_OPTION


@dataclasses.dataclass(frozen=True)
class EnhanceOption:
    """One option of the enhance engine: its keyword, the C++ member and CLI flag that hold it, its
    kind and default, its choices or range, its help, and the modes it applies to."""

    name: str
    cpp: str
    flag: str | None
    flag_negates: bool
    kind: str  # bool, int, float, choice, indices, optional_int
    default: typing.Any
    choices: tuple[str, ...]
    min: float
    max: float
    min_open: bool
    max_open: bool
    help: str
    modes: tuple[str, ...]

    @property
    def annotation(self) -> typing.Any:
        """The annotation help() shows."""
        if self.kind == "choice":
            return typing.Literal[self.choices]
        if self.kind == "indices":
            return typing.Optional[typing.Sequence[int]]
        if self.kind == "optional_int":
            return typing.Optional[int]
        return {"bool": bool, "int": int, "float": float}[self.kind]

    @property
    def stub_annotation(self) -> str:
        """The annotation the stub writes."""
        if self.kind == "choice":
            return "Literal[" + ", ".join(_stub_literal(c) for c in self.choices) + "]"
        if self.kind == "indices":
            return "npt.ArrayLike | None"
        if self.kind == "optional_int":
            return "int | None"
        return self.kind

    def range_text(self) -> str:
        """The allowed range, as interval or bound ("" when any finite number goes)."""
        if self.kind not in ("int", "float", "optional_int"):
            return ""
        # The table's unbounded sides are infinite or +-1e308.
        low = math.isfinite(self.min) and abs(self.min) < 1e308
        high = math.isfinite(self.max) and abs(self.max) < 1e308
        if low and high:
            return f"in {'(' if self.min_open else '['}{self.min:g}, {self.max:g}{')' if self.max_open else ']'}"
        if low:
            return f"{'>' if self.min_open else '>='} {self.min:g}"
        if high:
            return f"{'<' if self.max_open else '<='} {self.max:g}"
        return ""

    def parameter(self) -> inspect.Parameter:
        return inspect.Parameter(self.name, inspect.Parameter.KEYWORD_ONLY, default=self.default,
                                 annotation=self.annotation)

    def doc(self) -> str:
        """Two or more lines for a docstring: the keyword, its default, where it applies; its help."""
        notes = []
        if self.flag:
            notes.append(f"CLI {self.flag}" + (f" sets {not self.default}" if self.flag_negates else ""))
        notes.append("every mode" if set(self.modes) == set(ENHANCE_MODES) else "modes: " + ", ".join(self.modes))
        if self.range_text():
            notes.append(self.range_text())
        head = f"{self.name}: {inspect.formatannotation(self.annotation)} = {self.default!r}  ({'; '.join(notes)})"
        return head + "\n" + textwrap.fill(self.help, width=96, initial_indent="    ", subsequent_indent="    ")


def _stub_literal(value: typing.Any) -> str:
    """A default as the stub writes it: strings in double quotes (the stub's style), else repr."""
    return '"' + value + '"' if isinstance(value, str) else repr(value)


#: Every option of the table, by keyword, in the table's order.
ENHANCE_OPTIONS: dict[str, EnhanceOption] = {o["name"]: EnhanceOption(**o) for o in _core._enhance_option_table()}


def modes_doc() -> str:
    """How the options choose the mode, one line per mode, from the engine's answers."""
    width = max(len(m["name"]) for m in MODE_TABLE)
    lines = []
    for mode in MODE_TABLE:
        parts = ["a reference" if mode["reference"] else "no reference"]
        parts += [f"{name}={value!r}" for name, value in mode["options"].items()]
        if not mode["options"]:
            parts.append("the default options")
        lines.append(f"  {mode['name']:<{width}}  " + ", ".join(parts))
    return "\n".join(lines)


def options_doc() -> str:
    return "\n".join(option.doc() for option in ENHANCE_OPTIONS.values())


def stub_option_lines(faces: bool | None = None, indent: str = "    ") -> list[str]:
    """The options as stub parameters, one line each. faces=True or False types the option that
    changes the faces as Literal[True] (no default) or Literal[False], for the overloads of enhance."""
    lines = []
    for option in ENHANCE_OPTIONS.values():
        if option.name == FACES_OPTION and faces is not None:
            lines.append(f"{indent}{option.name}: Literal[True]," if faces else
                         f"{indent}{option.name}: Literal[False] = False,")
        else:
            lines.append(f"{indent}{option.name}: {option.stub_annotation} = {_stub_literal(option.default)},")
    return lines


def front_end(name: str, head: Sequence[inspect.Parameter], call: Callable[..., typing.Any], summary: str,
              returns: typing.Any = inspect.Signature.empty) -> Callable[..., typing.Any]:
    """A function `name` taking the parameters `head` and then every option of the table as a
    keyword-only parameter with its default. It calls call(options, **head_values), where options
    holds only the options the caller gave ({keyword: value}): the library starts from its own
    defaults and checks each value against the table."""
    signature = inspect.Signature([*head, *(o.parameter() for o in ENHANCE_OPTIONS.values())],
                                  return_annotation=returns)

    def function(*args, **kwargs):
        arguments = signature.bind(*args, **kwargs).arguments  # TypeError for a keyword it does not have
        options = {k: v for k, v in arguments.items() if k in ENHANCE_OPTIONS}
        return call(options, **{p.name: arguments.get(p.name, p.default) for p in head})

    function.__name__ = function.__qualname__ = name
    function.__module__ = "vertexflow"
    function.__signature__ = signature
    function.__doc__ = (f"{summary.strip()}\n\nModes (which options choose them):\n{modes_doc()}\n\n"
                        f"Options (the library's option table, enhance_options.h):\n{options_doc()}\n")
    return function

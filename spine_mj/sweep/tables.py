"""The sweep config's building blocks: its table base, value types, and one-line errors.

:class:`Table` (a frozen TOML table that refuses undeclared keys), the value types its
keys take (:data:`Finite`, :data:`Seed`, :func:`count_type`, :func:`value_list` and its
:class:`Span` of values), the size limits they are checked against, and
:func:`validate_table`, which turns pydantic's errors into one SpineInputError line
naming the key, what is expected and what arrived. :mod:`spine_mj.sweep.config` declares
the config's tables with them.
"""

from __future__ import annotations

from typing import Annotated, Any, ClassVar

import numpy as np
from pydantic import (
    AllowInfNan,
    BaseModel,
    ConfigDict,
    Field,
    PlainValidator,
    Strict,
    TypeAdapter,
    ValidationError,
    field_validator,
    model_validator,
)

from spine_mj.errors import SpineInputError

#: Most cases and runs one config may expand to (checked before anything is allocated).
MAX_CASES = 1_000_000
MAX_RUNS = 10_000_000

#: A finite number (an integer becomes a float; booleans and strings are refused).
Finite = Annotated[float, Strict(), AllowInfNan(False)]
#: A generator or master seed: an integer >= 0.
Seed = Annotated[int, Strict(), Field(ge=0)]


def count_type(maximum: int) -> Any:
    """The type of a count: an integer from 1 to ``maximum``."""
    return Annotated[int, Strict(), Field(ge=1, le=maximum)]


class Table(BaseModel):
    """A TOML table: frozen, and a key it does not declare is an error."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    #: What its keys are, in the message for an unknown one.
    noun: ClassVar[str] = "key"


class Span(Table):
    """``{linspace = [a, b], num = n}`` or ``{logspace = [a, b], num = n}``: ``n`` values from
    ``a`` to ``b``, evenly or geometrically spaced."""

    linspace: tuple[Finite, Finite] | None = None
    logspace: tuple[Finite, Finite] | None = None
    num: count_type(MAX_CASES)

    @field_validator("logspace")
    def _positive_ends(cls, ends):
        if min(ends) <= 0:
            raise ValueError(f"end values must be > 0 (they are values, not exponents), got {list(ends)}")
        return ends

    @model_validator(mode="after")
    def _one_spacing(self):
        if (self.linspace is None) == (self.logspace is None):
            both = "neither" if self.linspace is None else "both"
            raise ValueError(f"give exactly one of linspace = [a, b] or logspace = [a, b], got {both}")
        return self

    def values(self) -> list[float]:
        space = np.linspace if self.logspace is None else np.geomspace
        return [float(v) for v in space(*(self.linspace or self.logspace), self.num)]


def value_list(item: Any, expected: str, *, distinct: bool = False) -> Any:
    """The type of a key that takes a value, a non-empty list of them or a :class:`Span`:
    a tuple of values of the pydantic type ``item`` (``expected`` names it in the message);
    with ``distinct``, none repeated."""
    adapter = TypeAdapter(item)

    def validate(value) -> tuple:
        if isinstance(value, dict):
            value = Span.model_validate(value).values()
        value = value if isinstance(value, list) else [value]
        if not value:
            raise ValueError("must be a value or a non-empty list, got []")
        out = []
        for v in value:
            try:
                out.append(adapter.validate_python(v))
            except ValidationError:
                raise ValueError(f"must be {expected} (or a list of them), got {v!r}") from None
        if distinct and len(set(out)) != len(out):
            raise ValueError(f"repeated value in {out!r}")
        return tuple(out)

    return Annotated[tuple, PlainValidator(validate)]


#: pydantic's words for the errors whose usual "Input should be ..." would not read well.
MESSAGES = {
    "model_type": "must be a table",
    "dict_type": "must be a table",
    "list_type": "must be a list",
    "tuple_type": "must be a list",
    "bool_type": "must be true or false",
    "too_short": "must have at least {min_length} item(s)",
    "too_long": "must have at most {max_length} item(s)",
    "string_too_short": "must be a non-empty string",
}


def validate_table(model: type[BaseModel], data, context: dict | None = None):
    """``model`` validated from ``data``, or a SpineInputError of one line: the first problem
    (key path, what is expected, what arrived) and how many others there are."""
    try:
        return model.model_validate(data, context=context)
    except ValidationError as exc:
        errors = exc.errors()
        n = len(errors) - 1
        more = f" (and {n} other problem{'s' if n > 1 else ''})" if n else ""
        raise SpineInputError(_describe(model, errors[0]) + more) from None


def _describe(model: type[BaseModel], error: dict) -> str:
    """A pydantic error as ``config key grid.ie[2]: must be ..., got ...``."""
    loc, kind, ctx = error["loc"], error["type"], error.get("ctx", {})
    if kind == "value_error":  # raised by the validators here, whose messages say what arrived
        what = str(ctx["error"])
    elif kind == "missing":
        what = "required"
    elif kind == "extra_forbidden":
        table = _table_at(model, loc)
        what = f"unknown {table.noun}; allowed: "
        what += ", ".join(f.alias or n for n, f in table.model_fields.items()) or "none"
    else:
        what = (
            MESSAGES[kind].format(**ctx) if kind in MESSAGES else error["msg"].replace("Input should", "must")
        )
        what += f", got {error['input']!r}"
    path = "".join(f"[{k}]" if isinstance(k, int) else f".{k}" for k in loc).lstrip(".")
    return f"config key {path}: {what}" if path else f"config: {what}"


def _table_at(model: type[BaseModel], loc: tuple) -> type[BaseModel]:
    """The model of the table holding the key at ``loc`` (a table inside a value: a Span)."""
    for key in loc[:-1]:
        if isinstance(key, str):
            field = next((f for n, f in model.model_fields.items() if (f.alias or n) == key), None)
            model = next(_models_in(getattr(field, "annotation", None)), Span)
    return model


def _models_in(annotation):
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        yield annotation
    for arg in getattr(annotation, "__args__", ()):
        yield from _models_in(arg)

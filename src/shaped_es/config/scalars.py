"""The config schema's strict scalar types and base model (shared by ``config/__init__.py`` and ``config/shaping.py``)."""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import BaseModel, BeforeValidator, ConfigDict, Strict


class ConfigWarning(UserWarning):
    """A setting the run will not use (a ``shaping.*`` field with a method that is not shaped); one line."""


def _not_bool(v: Any) -> Any:
    if isinstance(v, bool):
        raise ValueError(f"Input should be a number, not a boolean ({str(v).lower()})")
    return v


# Strict scalar types: an integer field takes only integers (not true/false, not 2.5 or "3"), a number
# field any finite number (not true/false; YAML reads 1e-3 as a string, which still counts), a boolean
# field only true/false.
Int = Annotated[int, Strict()]
Float = Annotated[float, BeforeValidator(_not_bool)]
Bool = Annotated[bool, Strict()]
SEED_LIMIT = 2**32  # seeds are 32-bit: a larger root seed would alias a smaller one


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", validate_assignment=True, allow_inf_nan=False)

"""YAML for config files and ``--set`` values: ``yaml.SafeLoader`` (plain data only) that also refuses
recursive aliases and aliases that expand a document past a bound ("billion laughs"). ``config.parse_yaml``
turns its errors into one ``ConfigError`` line."""

from __future__ import annotations

import re
from typing import Any

import yaml

# Values the aliases of one YAML document may add to it, beyond the values written out: anchors that
# spare repeating a section stay well inside it; a "billion laughs" document (700 bytes, 10**8 values)
# does not, and would hang whatever walks it (validation, gym.make's error message, dump_config).
ALIAS_BUDGET = 10_000


class AliasError(ValueError):
    """A recursive alias, or aliases past :data:`ALIAS_BUDGET`."""


_BOOL = "tag:yaml.org,2002:bool"


class _Loader(yaml.SafeLoader):
    """``yaml.SafeLoader`` that refuses recursive aliases and aliases past :data:`ALIAS_BUDGET`, and reads
    only ``true``/``false`` as booleans (YAML 1.2's core schema): YAML 1.1's ``yes``/``no``/``on``/``off``
    stay words, so ``--set tensorboard=yes`` is refused by the config's boolean check, as the README says
    (booleans are true/false), instead of silently meaning true."""

    yaml_implicit_resolvers = {k: [r for r in v if r[0] != _BOOL]
                               for k, v in yaml.SafeLoader.yaml_implicit_resolvers.items()}

    def construct_document(self, node):
        _check_aliases(node)
        return super().construct_document(node)


_Loader.add_implicit_resolver(_BOOL, re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF"))


def _check_aliases(root: yaml.Node) -> None:
    """``AliasError`` if an alias refers to a node that contains it, or the aliases expand the document
    by more than :data:`ALIAS_BUDGET` values (sizes counted once per node, so a bomb costs no time)."""
    size: dict[int, int] = {}  # id(node) -> values under it, aliases expanded
    open_: set[int] = set()  # nodes whose children are being counted (the path from the root)
    stack: list[tuple[yaml.Node, bool]] = [(root, False)]
    while stack:
        node, closing = stack.pop()
        key = id(node)
        kids = [] if isinstance(node, yaml.ScalarNode) else (
            [x for pair in node.value for x in pair] if isinstance(node, yaml.MappingNode) else node.value)
        if closing:
            open_.discard(key)
            size[key] = 1 + sum(size[id(k)] for k in kids)
        elif key in open_:
            raise AliasError(f"a YAML alias (line {node.start_mark.line + 1}) refers to a value that "
                             f"contains it (a recursive alias)")
        elif key not in size:
            open_.add(key)
            stack.append((node, True))
            stack.extend((k, False) for k in kids)
    if size[id(root)] - len(size) > ALIAS_BUDGET:
        raise AliasError(f"its YAML aliases expand to {size[id(root)]:,} values, more than {ALIAS_BUDGET:,} "
                         f"beyond the {len(size):,} written (an alias bomb?); write the values out")


def load(text: str) -> Any:
    """``text`` as YAML data; ``yaml.YAMLError`` if it is not YAML, :class:`AliasError` for the aliases
    above (and what constructing a value raises: ``ValueError`` for an impossible date, ...)."""
    return yaml.load(text, Loader=_Loader)  # noqa: S506 - _Loader is a SafeLoader

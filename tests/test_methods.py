"""The method registry (``methods.py``): a method is one file plus one entry, so no module outside the
registry branches on a method's name; every hook names something that exists, at a layer its caller may
import."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import shaped_es
from shaped_es.methods import METHODS, Method, resolve

SRC = Path(shaped_es.__file__).parent


def _method_name_comparisons(tree: ast.AST) -> list[int]:
    """Lines comparing ``<x>.method`` or ``method`` with a method's name (``==``, ``!=``, ``in``)."""

    def is_method(node) -> bool:
        return (isinstance(node, ast.Attribute) and node.attr == "method") or \
            (isinstance(node, ast.Name) and node.id == "method")

    def names_a_method(node) -> bool:
        if isinstance(node, ast.Constant):
            return node.value in METHODS
        if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
            return any(names_a_method(e) for e in node.elts)
        return False

    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare):
            sides = [node.left, *node.comparators]
            if any(is_method(s) for s in sides) and any(names_a_method(s) for s in sides):
                found.append(node.lineno)
    return found


def test_no_module_outside_the_registry_branches_on_a_method_name():
    bad = [f"{p.relative_to(SRC)}:{line}" for p in sorted(SRC.rglob("*.py")) if p.name != "methods.py"
           for line in _method_name_comparisons(ast.parse(p.read_text(), str(p)))]
    assert not bad, f"per-method behaviour belongs in methods.Method hooks: {bad}"


def test_the_check_would_catch_a_branch():
    src = 'if cfg.method == "ppo":\n    pass\nif method in ("shaped", "x"):\n    pass\nif name == "ppo":\n    pass\n'
    assert _method_name_comparisons(ast.parse(src)) == [1, 3]


@pytest.mark.parametrize("name", sorted(METHODS))
def test_every_hook_resolves(name):
    m = METHODS[name]
    paths = [m.train, m.policy_fields, m.evaluate, *m.checks] + ([m.report_extra] if m.report_extra else [])
    paths += [m.strategy, m.guide] if m.strategy else []
    for path in paths:
        assert callable(resolve(path)), (name, path)
    assert m.about and m.knobs


def test_cmaes_state_counts_its_covariance_below_the_diagonal_size():
    from shaped_es.config import RunConfig

    cfg = RunConfig(method="cmaes")
    n = cfg.es.cmaes_diagonal_above
    assert METHODS["cmaes"].state_bytes(cfg, n) == 4 * n * 8 + 3 * n * n * 8
    assert METHODS["cmaes"].state_bytes(cfg, n + 1) == 4 * (n + 1) * 8
    assert Method().state_bytes(cfg, 10) == 320

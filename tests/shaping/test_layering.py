"""Layer rule of ``shaping/`` (DESIGN.md): the method's pure blocks import nothing from the layers above
them (trainer, config, executors, rollout, guides, store, cli) -- the glue that does lives in ``guides/``."""

from __future__ import annotations

import ast
from pathlib import Path

import shaped_es.shaping

ABOVE = ("trainer", "config", "executors", "rollout", "guides", "store", "cli", "benchmark", "benchmarks",
         "report", "baselines", "evaluate", "render", "load", "preflight")


def _imports(path: Path) -> set[str]:
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            out.add(node.module)
    return out


def test_shaping_imports_nothing_from_the_layers_above():
    root = Path(shaped_es.shaping.__file__).parent
    files = sorted(root.glob("*.py"))
    assert len(files) >= 6
    bad = {f.name: sorted(m for m in _imports(f) if m.startswith("shaped_es.")
                          and m.split(".")[1] in ABOVE) for f in files}
    assert not {k: v for k, v in bad.items() if v}, bad


def test_the_rule_would_catch_an_upward_import(tmp_path):
    f = tmp_path / "x.py"
    f.write_text("from shaped_es.trainer import Trainer\nimport shaped_es.executors.process\n")
    assert {"shaped_es.trainer", "shaped_es.executors.process"} <= _imports(f)

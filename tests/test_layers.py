"""Import layering of the whole package (DESIGN.md, "Layers"): no cycle, no upward import, no import
between the units of one layer.

Every ``import`` in every module under ``src/shaped_es`` counts, the ones inside functions too. A unit
is a top-level module or package of ``shaped_es`` (``strategies`` holds ``strategies/*``); it may import
itself and the units of the layers below its own, nothing else. The units of one layer know nothing of
each other (``policies`` knows nothing of ``envs``, ``strategies`` nothing of either).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import shaped_es
from shaped_es.methods import METHODS

# Lowest first. "shaped_es" is the package's own __init__ (registers the envs, version, lazy load_policy).
LAYERS: list[tuple[str, ...]] = [
    ("seeding", "data", "monitor", "safe_yaml"),  # leaves: seeds, the Transitions record, what a run
    # reports (progress, TensorBoard, W&B, warnings in error.log, callbacks), YAML with bounded aliases
    ("envs", "policies", "strategies", "actions"),  # the independent blocks (envs/carla, CarlaNav-v0, inside envs);
    # actions: a policy output as an action of a space and back
    ("shaped_es", "shaping", "methods", "executors"),  # package init; the method's pure blocks; registries
    ("env_probe",),  # an env before its first rollout
    ("config", "rollout"),  # config/: the schema, how a key is spelt, a config's text read as data
    ("rundir",),  # the run directory: atomic writes, one writer, metrics.csv, checkpoints, run meta
    ("run_loop",),  # the run loop every method shares (lock, restore, rows, checkpoints)
    ("baselines",),  # PPO: knows nothing of ES
    ("trained",),  # a saved policy: load_policy, evaluate, render (ES or PPO)
    ("guides",),  # per-method hooks of the generation loop (shaped: a reference run's policy via load)
    ("trainer",),
    ("preflight",),  # checks before a run writes anything
    ("report", "api"),  # api: shaped_es.train from Python
    ("benchmark", "speed"),
    ("cli",),  # the shaped-es command: its commands, how one ends, the commands that explain, check-env
    ("__main__",),
]
LAYER = {unit: i for i, units in enumerate(LAYERS) for unit in units}
# DESIGN.md's "knows nothing of" where the order above allows more.
KNOWS_NOTHING_OF = {
    "rollout": {"strategies"},
    "rundir": {"strategies", "shaping"},  # training logic
    "run_loop": {"strategies", "shaping", "rollout", "executors"},  # any one method's work
    "baselines": {"strategies", "shaping"},  # ES
    "report": {"strategies", "shaping", "rollout", "executors", "baselines", "guides", "trainer"},  # training
    "monitor": {"rundir", "config"},  # it writes what the run loop hands it
}
SRC = Path(shaped_es.__file__).parent


def _module_name(path: Path) -> str:
    parts = ("shaped_es",) + path.relative_to(SRC).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _modules() -> dict[str, Path]:
    return {_module_name(p): p for p in sorted(SRC.rglob("*.py"))}


def imports(path: Path, name: str, modules) -> set[str]:
    """The ``shaped_es`` modules the file imports anywhere (``from pkg import mod`` is ``pkg.mod``)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:  # relative
                up = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                base = ".".join(up + ([node.module] if node.module else []))
            for a in node.names:
                sub = f"{base}.{a.name}"
                out.add(sub if sub in modules else base)
    return {m for m in out if m == "shaped_es" or m.startswith("shaped_es.")}


def unit(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "shaped_es"


@pytest.fixture(scope="module")
def graph() -> dict[str, set[str]]:
    modules = _modules()
    return {name: imports(path, name, modules) - {name} for name, path in modules.items()}


def test_every_unit_has_a_layer(graph):
    assert not sorted({unit(m) for m in graph} - set(LAYER)), "add the new module to LAYERS"
    assert len(graph) > 60


def test_no_upward_import_and_none_within_a_layer(graph):
    bad = sorted(f"{m} -> {t}" for m, targets in graph.items() for t in targets
                 if unit(t) != unit(m) and LAYER[unit(t)] >= LAYER[unit(m)])
    assert not bad, bad


def test_what_a_layer_knows_nothing_of(graph):
    bad = sorted(f"{m} -> {t}" for m, targets in graph.items() for t in targets
                 if unit(t) in KNOWS_NOTHING_OF.get(unit(m), ()))
    assert not bad, bad


def _cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One import cycle of ``graph`` (module -> modules it imports) as a closed path, or None."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(m: str) -> list[str] | None:
        state[m] = 1
        path.append(m)
        for t in sorted(graph.get(m, ())):
            if state.get(t) == 1:
                return path[path.index(t):] + [t]
            if t not in state and (found := visit(t)):
                return found
        state[m] = 2
        path.pop()
        return None

    for m in sorted(graph):
        if m not in state and (found := visit(m)):
            return found
    return None


def test_no_import_cycle_between_modules(graph):
    cycle = _cycle(graph)
    assert cycle is None, " -> ".join(cycle)


def test_registry_parts_live_below_their_resolvers():
    """``methods.METHODS`` names its parts by path (resolved on use): the strategies and guides must lie
    below the trainer that builds them, the train entries no higher than the trainer (cli/benchmark run them)."""
    from shaped_es.methods import resolve

    for name, m in METHODS.items():
        parts = [m.train] + ([m.strategy, m.guide] if m.strategy else [])
        for path in parts:
            assert callable(resolve(path)), (name, path)
            assert LAYER[unit(path.partition(":")[0])] <= LAYER["trainer"], (name, path)
        if m.strategy:
            for path in (m.strategy, m.guide):
                assert LAYER[unit(path.partition(":")[0])] < LAYER["trainer"], (name, path)


def test_the_carla_client_is_imported_lazily_in_one_place():
    """``carla`` (an optional extra) is imported only inside a function of ``envs/carla/connection.py``,
    so importing shaped_es, or registering CarlaNav-v0, never needs it."""
    found = []
    for name, path in _modules().items():
        tree = ast.parse(path.read_text(), str(path))
        in_function = {id(n) for f in ast.walk(tree) if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef))
                       for n in ast.walk(f)}
        for node in ast.walk(tree):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module or ""] if isinstance(node, ast.ImportFrom) and not node.level else [])
            if any(n == "carla" or n.startswith("carla.") for n in names):
                found.append((name, id(node) in in_function))
    assert found == [("shaped_es.envs.carla.connection", True)]


def test_the_rules_would_catch_a_bad_import(tmp_path):
    f = tmp_path / "x.py"
    f.write_text("def f():\n    from shaped_es.trainer import Trainer\n    import shaped_es.executors.process\n"
                 "from shaped_es import seeding\nfrom . import y\n")
    found = imports(f, "shaped_es.strategies.x", {"shaped_es.seeding", "shaped_es.strategies.y"})
    assert found == {"shaped_es.trainer", "shaped_es.executors.process", "shaped_es.seeding",
                     "shaped_es.strategies.y"}
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b"}, "b": set()}) is None


def test_the_top_level_shows_its_parts():
    """A newcomer finds the run directory, the CLI and what a run reports by folder names: at most 14
    modules sit directly under ``src/shaped_es/`` (``__init__`` and ``__main__`` included)."""
    top = sorted(p.name for p in SRC.glob("*.py"))
    assert len(top) <= 14, top


def test_method_hooks_lie_below_their_callers():
    """``methods.Method``'s hooks are resolved by preflight (checks), trained/ (policy_fields, evaluate)
    and benchmark (report_extra): each must lie at or below its caller's layer."""
    callers = {"checks": "preflight", "policy_fields": "trained", "evaluate": "trained", "report_extra": "benchmark"}
    for name, m in METHODS.items():
        for hook, caller in callers.items():
            paths = getattr(m, hook)
            for path in ([paths] if isinstance(paths, str) else list(paths or ())):
                assert LAYER[unit(path.partition(":")[0])] <= LAYER[caller], (name, hook, path)

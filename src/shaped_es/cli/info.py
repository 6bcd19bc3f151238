"""How the command line explains itself: every ``--help`` with each option's default (:class:`HelpFormatter`),
a malformed command line as one error line (:class:`Parser`), and the commands that explain rather than
run: ``shaped-es config`` (every config field with its value, default, type and description, so ``--set``
keys can be found), ``shaped-es envs`` (the registered env ids, their presets and whether they meet the
waypoint contract) and ``shaped-es check-env ID`` (what an env needs to train here, one line per check;
``env_check.py``). Their parsers and handlers, for ``cli.py`` to wire in."""

from __future__ import annotations

import argparse
import copy
import difflib
import json
import sys
import textwrap
import typing
from typing import Any

import numpy as np

from pydantic import BaseModel

WRAP = 100  # config comments wrap at this width


# -- every command's --help and its errors ---------------------------------------------------------------------
class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Every option's default in its help; ``None`` defaults (taken from the config) are described in the
    option's own help instead of printing "(default: None)", and a help that names its default already
    gets no second one."""

    def _get_help_string(self, action):
        if action.default is None or "default" in (action.help or "").lower():  # already says it
            return action.help or ""
        return super()._get_help_string(action)

    def _format_action(self, action):
        if not action.help and action.option_strings and action.default not in (None, argparse.SUPPRESS):
            action = copy.copy(action)
            action.help = "(default: %(default)s)"  # an option without help still shows its default
        return super()._format_action(action)


class Parser(argparse.ArgumentParser):
    """A malformed command line is one error line too (argparse prints its usage first): ``shaped-es:
    error: ...`` naming the command's ``--help``, exit code 2. Sub-parsers are of this class."""

    def error(self, message: str):
        print(f"shaped-es: error: {' '.join(message.split())} (usage: {self.prog} --help)", file=sys.stderr)
        sys.exit(2)

    def parse_args(self, args=None, namespace=None):
        """As argparse's, but an unknown option is reported by the sub-command it was given to (naming
        that command's ``--help``), with the closest option it has (``--genrations``: did you mean
        ``--generations``?)."""
        ns, extra = self.parse_known_args(args, namespace)
        if extra:
            sub = self._chosen(ns)
            opts = [o for a in sub._actions for o in a.option_strings if o.startswith("--")]
            hints = [f"{x}: did you mean {m[0]}?" for x in extra if x.startswith("--")
                     for m in [difflib.get_close_matches(x.split("=")[0], opts, n=1)] if m]
            sub.error(f"unrecognized arguments: {' '.join(extra)}" + (f" ({'; '.join(hints)})" if hints else ""))
        return ns

    def _chosen(self, ns: argparse.Namespace) -> argparse.ArgumentParser:
        """The deepest sub-parser the parsed command line chose (this parser without sub-commands)."""
        for action in self._actions:
            if isinstance(action, argparse._SubParsersAction):
                sp = action.choices.get(getattr(ns, action.dest, None) or "")
                if sp is not None:
                    return sp._chosen(ns) if isinstance(sp, Parser) else sp
        return self


def use_formatter(parser: argparse.ArgumentParser) -> None:
    """``HelpFormatter`` for the parser and every sub-parser, however deep (added anywhere)."""
    parser.formatter_class = HelpFormatter
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sp in action.choices.values():
                use_formatter(sp)


# -- shaped-es config ----------------------------------------------------------------------------------------
def add_parsers(sub) -> None:
    from shaped_es.config import set_item

    c = sub.add_parser("config", help="every config field: value, default, type and description (--set keys)",
                       description="Print the complete run config as commented YAML (a valid --config file): "
                       "each field's value, type and description, and its default where the value differs.")
    c.add_argument("prefix", nargs="?", default="",
                   help="only the fields whose dotted key starts with this, e.g. es or shaping.cloning (default: all)")
    c.add_argument("--config", help="show this YAML config's values (default: the built-in defaults)")
    c.add_argument("--set", action="append", metavar="KEY=VALUE", type=set_item,
                   help="show the values with this override, as train would take it (repeatable; default: none)")
    c.add_argument("--json", action="store_true",
                   help="one JSON object per field (key, value, default, type, description), one per line")
    c.set_defaults(fn=cmd_config)

    e = sub.add_parser("envs", help="registered env ids: presets, spaces, time limit, waypoint contract",
                       description="List the Gymnasium ids this machine can make (each made and reset once), "
                       "with their presets, dims, time limit and whether they meet the waypoint contract that "
                       "--method shaped needs. An own env: --import mymodule (or --env mymodule:Id in train).")
    e.add_argument("--all", action="store_true",
                   help="also the ids that cannot be used here (not made, or spaces a policy cannot act in), with "
                        "the reason")
    e.add_argument("--import", dest="modules", action="append", metavar="MODULE",
                   help="import MODULE first, so the envs it registers are listed (repeatable; default: none)")
    e.add_argument("--json", action="store_true", help="one JSON object per env, one per line")
    e.set_defaults(fn=cmd_envs)

    k = sub.add_parser("check-env", help="run an env a few episodes and report what training needs of it",
                       description="Make the env, run seeded random-action episodes and print one line per "
                       "check (Gymnasium's API checker, spaces, time limit, finiteness, seeding, waypoint "
                       "contract) and the methods it trains with. Exit code 0, or 1 if a check FAILs.")
    k.add_argument("env_id", help="Gymnasium id, e.g. CarNav-v0 or mymodule:MyEnv-v0")
    k.add_argument("--set", action="append", metavar="KEY=VALUE", type=set_item,
                   help="an env keyword argument (as env_kwargs.KEY=VALUE in train), e.g. preset=paper "
                   "(repeatable; default: none)")
    k.add_argument("--episodes", type=int, default=2, help="random-action episodes, each run twice (seeding)")
    k.add_argument("--max-steps", type=int, default=200, help="cap on steps per episode")
    k.add_argument("--json", action="store_true", help="one JSON object: the checks and the methods (and "
                   "with --labels the probe's returns, choice and verdict under 'labels')")
    k.add_argument("--labels", action="store_true", help="also drive the env with M_phi's labels, as a shaped run "
                   "with shaping.inverse_dynamics.frame=auto does before its first generation: the label-driven "
                   "return per frame and query clip against zero action, and the choice a run makes")
    k.add_argument("--obs-norm", action="store_true", help="with --labels: probe as a run with --set "
                   "es.obs_norm=true does (its simulated candidates see the normalizer of the probe's data; a badly "
                   "scaled observation's labels can fail without it and pay with it)")
    k.set_defaults(fn=cmd_check_env)


def config_fields(model: type[BaseModel], values: dict, defaults: dict, prefix: str = ""):
    """``(dotted key, value, default, type, description, depth)`` of every field of ``model`` in order,
    sections first as ``(key, None, None, "section", description, depth)``."""
    for name, f in model.model_fields.items():
        key = f"{prefix}{name}"
        sub = _section(f)
        if sub is not None:
            yield key, None, None, "section", "", key.count(".")
            yield from config_fields(sub, values[name], defaults[name], f"{key}.")
        else:
            yield key, values[name], defaults[name], type_text(f), f.description or "", key.count(".")


def _section(field) -> type[BaseModel] | None:
    ann = field.annotation
    return ann if isinstance(ann, type) and issubclass(ann, BaseModel) else None


def type_text(field) -> str:
    """A field's type in words, with its bounds: 'int > 0', 'number in [0, 1]', 'one of a|b', ..."""
    ann = field.annotation
    args = [a for a in typing.get_args(ann) if a is not type(None)]
    optional = type(None) in typing.get_args(ann)
    base = args[0] if optional and len(args) == 1 else ann
    if typing.get_origin(base) is typing.Annotated:
        base = typing.get_args(base)[0]
    if typing.get_origin(base) is typing.Literal:
        text = "one of " + "|".join(str(a) for a in typing.get_args(base))
    elif typing.get_origin(base) in (tuple, list):
        item = next((a for a in typing.get_args(base) if a is not Ellipsis), None)
        if typing.get_origin(item) is typing.Annotated:
            item = typing.get_args(item)[0]
        text = {int: "list of ints", float: "list of numbers"}.get(item, "list")
    elif typing.get_origin(base) is dict:
        text = "mapping"
    else:
        text = {int: "int", float: "number", bool: "true/false", str: "text", dict: "mapping"}.get(base, str(base))
    bounds = []
    for m in field.metadata:
        for attr, sym in (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<=")):
            v = getattr(m, attr, None)
            if v is not None:
                bounds.append(f"{sym} {v:g}" if isinstance(v, float) else f"{sym} {v}")
    text += (" " + ", ".join(bounds)) if bounds else ""
    return text + (" or null" if optional else "")


def cmd_config(a: argparse.Namespace) -> int:
    from shaped_es.config import ConfigError, RunConfig, build_config, merge, parse_set, read_yaml

    data = read_yaml(a.config) if a.config else {}
    cfg = build_config(merge(data, parse_set(a.set)))
    values, defaults = cfg.model_dump(mode="json"), RunConfig().model_dump(mode="json")
    rows = [r for r in config_fields(RunConfig, values, defaults)
            if not a.prefix or r[0] == a.prefix or r[0].startswith(a.prefix + ".")]
    if not rows:
        raise ConfigError(f"no config field starts with {a.prefix!r} (shaped-es config lists them all)")
    if a.json:
        for key, value, default, kind, desc, _ in rows:
            if kind != "section":
                print(json.dumps({"key": key, "value": value, "default": default, "type": kind,
                                  "description": desc}))
        return 0
    print("# shaped-es run config: every field's value, type and meaning. Set one with --set KEY=VALUE (KEY as\n"
          "# dotted below, e.g. es.sigma=0.1) or save this as a --config file.")
    shown: set[str] = set()
    for key, value, default, kind, desc, depth in rows:
        for i, part in enumerate(key.split(".")[:-1]):  # parents of a filtered field
            parent = ".".join(key.split(".")[: i + 1])
            if parent not in shown:
                shown.add(parent)
                print(f"{'  ' * i}{part}:")
        if kind == "section":
            if key not in shown:
                shown.add(key)
                print(f"{'  ' * depth}{key.rsplit('.', 1)[-1]}:")
            continue
        print(_yaml_line(key.rsplit(".", 1)[-1], value, default, kind, desc, depth))
    return 0


def _yaml_line(name: str, value: Any, default: Any, kind: str, desc: str, depth: int) -> str:
    pad = "  " * depth
    head = f"{pad}{name}: {json.dumps(value)}"
    note = f"{kind}. {desc}" + ("" if value == default else f" (default: {json.dumps(default)})")
    return textwrap.fill(f"{head}  # {note}", WRAP, subsequent_indent=f"{pad}  # ", break_long_words=False,
                         break_on_hyphens=False)


# -- shaped-es envs ------------------------------------------------------------------------------------------
def cmd_envs(a: argparse.Namespace) -> int:
    import importlib

    import gymnasium as gym

    import shaped_es  # noqa: F401 - registers the built-in envs
    from shaped_es.config import ConfigError
    from shaped_es.cli.describe_env import describe_env

    for m in a.modules or []:
        try:
            importlib.import_module(m)
        except ImportError as exc:
            raise ConfigError(f"--import {m}: {exc}") from None
    found = [describe_env(env_id) for env_id in gym.registry]
    made = [d for d in found if d["error"] is None]
    broken = [d for d in found if d["error"] is not None]
    shown = made + (broken if a.all else [])
    if a.json:
        for d in shown:
            print(json.dumps(d))
        return 0
    head = ("id", "presets", "obs", "act", "time limit", "waypoint contract (--method shaped)")  # act: policy outputs
    table = [[d["id"], ", ".join(d["presets"]) or "-", _cell(d["obs"]), _cell(d["act"]), _cell(d["time_limit"]),
              (f"yes ({d['waypoints']}-d)" if d["waypoints"] else "no") if d["error"] is None
              else f"cannot be used here: {d['error']}"] for d in shown]
    widths = [max(len(str(r[i])) for r in [head, *table]) for i in range(len(head) - 1)]
    for r in [head, *table]:
        print("  ".join(str(c).ljust(w) for c, w in zip(r, widths)) + "  " + str(r[-1]))
    if any(d["act"] is not None for d in made):  # a MultiDiscrete([3, 5]) read "act 8" as wrong
        print("\n(act: the policy's outputs: the action size of a Box, the options of a Discrete, all sub-actions' "
              "options of a MultiDiscrete, the bits of a MultiBinary)")
    if broken and not a.all:
        print(f"\n{len(broken)} more registered ids cannot be used here (a missing package, or spaces an MLP "
              f"policy cannot take): shaped-es envs --all lists each with its reason; shaped-es check-env ID "
              f"checks one env in depth")
    return 0


def _cell(v) -> str:
    return "-" if v is None else str(v)


# -- shaped-es check-env -------------------------------------------------------------------------------------
def cmd_check_env(a: argparse.Namespace) -> int:
    from shaped_es.config import ConfigError, parse_set
    from shaped_es.cli.check_env import FAIL, as_dicts, check_env, trains_with

    if a.episodes <= 0 or a.max_steps <= 0:
        raise ConfigError("--episodes and --max-steps must be positive")
    checks = check_env(a.env_id, parse_set(a.set), episodes=a.episodes, max_steps=a.max_steps)
    methods = trains_with(checks)
    failed = any(c.status == FAIL for c in checks)
    from shaped_es.guides.label_check import check_labels
    from shaped_es.guides.probe_variants import clip_text

    if not a.json:  # the checks first: an env that fails in the label probe still shows what passed
        width = max(len(c.name) for c in checks)
        for c in checks:
            print(f"{c.status:<4}  {c.name:<{width}}  {c.detail}")
        stopped = checks[-1].name == "spaces" and checks[-1].status == FAIL  # check_env stops at bad spaces
        print(f"{a.env_id} trains with: {', '.join(methods)}" if methods else
              f"{a.env_id} cannot train here: fix the FAIL line(s) above"
              + (" (the time limit, episode, waypoint and reward checks run once the spaces pass)" if stopped else ""))
        sys.stdout.flush()
    labels = None
    if a.labels and "shaped" in methods:
        from shaped_es.shaping.kernel_notice import say_if_compiling

        say_if_compiling("check-env")  # the probe compiles the shaping kernels on a cold cache
        labels = check_labels(a.env_id, parse_set(a.set), obs_norm=a.obs_norm)
    elif a.labels and failed:  # the waypoint contract was not reached: nothing trains until the FAIL is fixed
        labels = {"env": a.env_id, "verdict": "not probed: the env cannot train here (the FAIL line above)"}
    elif a.labels:
        labels = {"env": a.env_id, "verdict": "no waypoint contract, so no labels to probe (only --method shaped "
                                              "needs them)"}
    if a.json:
        print(json.dumps({"env": a.env_id, "checks": as_dicts(checks), "trains_with": methods}
                         | ({"labels": labels} if labels is not None else {})))
    elif labels is not None:
        if labels.get("zero_is"):
            print(f"labels: {labels['zero_is']}")
        if "chosen" in labels:
            means = " | ".join(f"{k} {np.mean(v):.2f}" for k, v in labels["returns"].items())
            print(f"labels: label-driven return over {len(labels['zero_action'])} episodes: {means} | zero "
                  f"action {np.mean(labels['zero_action']):.2f}")
            if labels.get("clones"):
                means = " | ".join(f"{k} {np.mean(v):.2f}" for k, v in labels["clones"].items())
                print(f"labels: the simulated candidate's return (the initial mean cloned toward each "
                      f"variant's labels): {means}")
            c = labels["chosen"]
            chunk = f", targets=chunk ({c['chunk']} steps)" if c.get("chunk") else ""
            print(f"labels: with seed {labels['seed']} a shaped run picks frame={c['frame']}{chunk}, query_clip="
                  f"{clip_text(c['query_clip'])}: {c['reason']}; each run probes with its own seed")
        for line in labels.get("details", []):
            print(f"labels: {line}")
        print(f"labels: {labels['verdict']}")
    sys.stdout.flush()
    return 1 if failed else 0

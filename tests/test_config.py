import pytest

from shaped_es.config import ConfigError, build_config, dump_config, load_config, merge, parse_set, parse_yaml
from shaped_es.safe_yaml import ALIAS_BUDGET


def test_defaults_roundtrip(tmp_path):
    cfg = build_config({"env": "CartPole-v1", "es": {"pairs": 4}})
    p = tmp_path / "c.yaml"
    p.write_text(dump_config(cfg))
    assert load_config(p) == cfg


def test_merge_dotted():
    assert merge({"es": {"pairs": 2}}, {"es.sigma": 0.2}) == {"es": {"pairs": 2, "sigma": 0.2}}


@pytest.mark.parametrize(
    "data, needle",
    [
        ({"es": {"sigma": -1}}, "es.sigma"),
        ({"es": {"pairs": 0}}, "es.pairs"),
        ({"method": "sgd"}, "method"),
        ({"bogus": 1}, "bogus"),
        ({"rollout": {"episodes": "two"}}, "rollout.episodes"),
        ({"policy": {"hidden": [0]}}, "policy"),
        ({"es": {"alpha": 1.5}}, "es.alpha"),
        ({"shaping": {"inverse_dynamics": {"shoot_frame": "waypoint", "shoot_model": "rollout"}}},
         "shoot_frame waypoint needs shoot_model chunk"),
        ({"shaping": {"inverse_dynamics": {"step_change": True, "frame": "motion"}}},
         "step_change true needs frame world, both or auto"),
        ({"shaping": {"inverse_dynamics": {"step_change": "yes"}}}, "shaping.inverse_dynamics.step_change"),
    ],
)
def test_bad_fields_one_line(data, needle):
    with pytest.raises(ConfigError) as e:
        build_config(data)
    msg = str(e.value)
    assert needle in msg and "\n" not in msg


def test_bad_files(tmp_path):
    with pytest.raises(ConfigError, match="not found"):
        load_config(tmp_path / "nope.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("es: {sigma: [1, 2\n")
    with pytest.raises(ConfigError, match="not valid YAML"):
        load_config(bad)
    lst = tmp_path / "list.yaml"
    lst.write_text("- 1\n- 2\n")
    with pytest.raises(ConfigError, match="mapping"):
        load_config(lst)


def test_yaml_anchors_work_within_a_bound_and_bombs_or_recursion_are_one_line():
    assert parse_yaml("a: &a {x: 1, y: [1, 2]}\nb: *a\nc: {<<: *a, z: 3}\n", "here") == {
        "a": {"x": 1, "y": [1, 2]}, "b": {"x": 1, "y": [1, 2]}, "c": {"x": 1, "y": [1, 2], "z": 3}}
    wide = "a: &a [" + ", ".join(["1"] * 100) + "]\nb: [" + ", ".join(["*a"] * (ALIAS_BUDGET // 101)) + "]\n"
    assert len(parse_yaml(wide, "here")["b"]) == ALIAS_BUDGET // 101  # just within the bound
    rows = ["a0: &a0 [x, x, x, x, x, x, x, x, x, x]"] + [
        f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]" for i in range(1, 9)]
    with pytest.raises(ConfigError, match="config file c.yaml: its YAML aliases expand to 1,234,567,909 values"):
        parse_yaml("\n".join(rows), "config file c.yaml")
    with pytest.raises(ConfigError, match="refers to a value that contains it"):
        parse_yaml("a: &a [1, *a]\n", "here")
    with pytest.raises(ConfigError, match="nests too deeply"):
        parse_yaml("a: " + "[" * 5000 + "]" * 5000, "here")


@pytest.mark.parametrize("item, needle", [
    ("es.sigma=[", "--set es.sigma=[ is not valid YAML"),
    ("es.sigma=2001-02-30", "--set es.sigma=2001-02-30 holds a value YAML cannot read: day is out of range"),
    ("x=[&a [1, 1, 1, 1, 1, 1, 1, 1, 1, 1], &b [*a, *a, *a, *a, *a, *a, *a, *a, *a, *a], "
     "&c [*b, *b, *b, *b, *b, *b, *b, *b, *b, *b], &d [*c, *c, *c, *c, *c, *c, *c, *c, *c, *c]]", "alias bomb"),
])
def test_set_values_that_yaml_cannot_read_are_one_line(item, needle):
    with pytest.raises(ConfigError) as e:
        parse_set([item])
    assert needle in str(e.value) and "\n" not in str(e.value)


@pytest.mark.parametrize("key", ["es.sigma", "rollout.max_steps", "policy.hidden"])
def test_an_empty_set_value_is_refused_naming_the_key_and_got_empty(key):
    """``--set es.sigma=`` said "Input should be a valid number" without the value, and ``--set
    rollout.max_steps=`` (an empty shell variable) left the field null without a word: YAML reads '' as null."""
    for value in ("", " "):
        with pytest.raises(ConfigError) as e:
            parse_set([f"{key}={value}"])
        assert str(e.value) == (f"invalid config: {key}: an empty value; give one (null leaves an optional field "
                                f"unset) (got {value!r})")
    assert parse_set(["rollout.max_steps=null"]) == {"rollout.max_steps": None}  # null, said, still unsets
    assert build_config(merge({}, parse_set(["rollout.max_steps=null"]))).rollout.max_steps is None


def test_settings_dataclasses_share_their_config_sections_defaults():
    """One truth: the shaping dataclasses and PPOSettings have their config section's defaults (a section's
    ``frame: auto`` resolves to the dataclass's world/motion in guides/shaped.py, ``step_change: auto`` to its
    off or the label probe's choice), PPOSettings its fields."""
    from dataclasses import fields

    from shaped_es.baselines.ppo_settings import PPOSettings
    from shaped_es.config import CloningSettings, InverseDynamicsSettings, PPOConfig
    from shaped_es.shaping.settings import CloningConfig, InverseDynamicsConfig

    assert [f.name for f in fields(PPOSettings)] == list(PPOConfig.model_fields)
    for cls, section, resolved in ((InverseDynamicsConfig, InverseDynamicsSettings, {"frame", "step_change"}),
                                   (CloningConfig, CloningSettings, set()), (PPOSettings, PPOConfig, set())):
        shared = [f for f in fields(cls) if f.name in section.model_fields and f.name not in resolved]
        assert len(shared) >= 5, cls
        for f in shared:
            assert f.default == section.model_fields[f.name].default, (cls.__name__, f.name)


def test_a_misspelt_key_is_named_with_what_it_may_mean():
    with pytest.raises(ConfigError) as e:
        build_config({"shaping": {"inverse_dynamics": {"query_scal": "raw"}}})
    assert str(e.value) == ("invalid config: shaping.inverse_dynamics.query_scal: unknown field "
                            "(did you mean query_scale or query_clip?)")
    with pytest.raises(ConfigError, match=r"^invalid config: zzz: unknown field$"):
        build_config({"zzz": 1})


def test_every_error_is_named_on_the_one_line():
    """A config with several mistakes names them all, so a user fixes them in one go (one line still)."""
    with pytest.raises(ConfigError) as e:
        build_config({"es": {"sigma": -1, "lrr": 0.1}, "shaping": {"mean_clone": {"acept": "paired"}}})
    line = str(e.value)
    assert "\n" not in line and line.startswith("invalid config: es.sigma: ")
    assert line.endswith(" (+2 more: es.lrr, shaping.mean_clone.acept)"), line


@pytest.mark.parametrize("data", [
    {"shaping": {"mean_clone": {"acept": "paired"}}},  # a YAML file's sections
    {"shaping.mean_clone.acept": "paired"},  # a dotted key (--set, the API, a YAML file's top level)
    {"shaping": {"mean_clone.acept": "paired"}},  # a dotted key inside a section
    {"shaping.mean_clone": {"acept": "paired"}},
    {"shaping": {"mean_clone": {"acept": "paired"}}, "es.sigma": 0.1},
])
def test_a_misspelt_key_at_depth_3_is_named_however_it_is_written(data):
    with pytest.raises(ConfigError) as e:
        build_config(merge(data, {}))
    assert str(e.value) == "invalid config: shaping.mean_clone.acept: unknown field (did you mean accept or accept_flat?)"


@pytest.mark.parametrize("key, line", [
    ("shaping.mechansim", "shaping.mechansim: unknown field (did you mean mechanism?)"),
    ("shapng.eta", "shapng: unknown field (did you mean shaping?)"),
    ("shaping.mean_clon.accept", "shaping.mean_clon: unknown field (did you mean mean_clone?)"),
    ("es.sigma.x", "es.sigma: Input should be a valid number"),
    # a new user's --set sigma=0.1: a key at the wrong level names the sections that hold it
    ("sigma", "sigma: unknown field (did you mean es.sigma?)"),
    ("babble_sigma", "babble_sigma: unknown field (did you mean shaping.inverse_dynamics.babble_sigma?)"),
    ("zzz_no_field", "zzz_no_field: unknown field"),
])
def test_a_misspelt_dotted_key_names_its_first_bad_part(key, line):
    with pytest.raises(ConfigError) as e:
        build_config(merge({}, parse_set([f"{key}=1"])))
    assert str(e.value) == f"invalid config: {line}"


def test_a_config_files_dotted_keys_are_paths_and_its_sections_hold_beside_them(tmp_path):
    p = tmp_path / "c.yaml"
    p.write_text("shaping.mean_clone.accept: mean\nshaping:\n  eta: 0.02\n")  # the dotted key first
    cfg = load_config(p)
    assert cfg.shaping.mean_clone.accept == "mean" and cfg.shaping.eta == 0.02
    assert merge({"es.sigma": 0.2, "es": {"pairs": 2}}, {}) == {"es": {"pairs": 2, "sigma": 0.2}}
    with pytest.raises(ConfigError) as e:  # a dotted key inside a section stays a key: nest it
        build_config({"shaping": {"mean_clone.accept": "mean"}})
    assert str(e.value).endswith("shaping.mean_clone.accept: unknown field (a dotted key is not a path here: "
                                 "nest it, one key per level)")


def test_a_null_value_in_a_config_file_says_it_was_null():
    """A new user's YAML ``noise:`` with nothing after it said "Input should be a valid number" with no value named."""
    with pytest.raises(ConfigError) as e:
        build_config(merge({"shaping": {"mean_clone": {"noise": None}}}, {}))
    assert str(e.value) == ("invalid config: shaping.mean_clone.noise: Input should be a valid number "
                            "(got null: `key: null`, or `key:` with nothing after it)")

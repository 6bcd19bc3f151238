import pytest

from shaped_es.config import ConfigError, build_config, dump_config, load_config, merge


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

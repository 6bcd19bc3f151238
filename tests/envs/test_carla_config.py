"""CarlaNav-v0's settings: presets match CarNav-v0's task, the server address and the per-worker port."""

import pytest

from shaped_es.envs.carla.config import CarlaNavConfig, make_config, server_address
from shaped_es.envs.carnav.config import NavTaskConfig
from shaped_es.envs.carnav.config import make_config as carnav_config
from shaped_es.executors.base import WORKER_INDEX_ENV


def test_presets_share_carnavs_task():
    shared = [f for f in NavTaskConfig.__dataclass_fields__]
    for preset in ("default", "paper"):
        a, b = make_config(preset), carnav_config(preset)
        assert {f: getattr(a, f) for f in shared} == {f: getattr(b, f) for f in shared}
    assert make_config("paper").max_steps == 1000 and make_config("paper").route_length == (1200.0, 1800.0)
    assert make_config().town == "Town07" and make_config().no_rendering


def test_port_steps_by_three_per_worker():
    cfg = make_config()
    assert server_address(cfg, {}) == ("localhost", 2000)
    assert [server_address(cfg, {WORKER_INDEX_ENV: str(i)})[1] for i in range(4)] == [2000, 2003, 2006, 2009]
    env = {"SHAPED_ES_CARLA_HOST": "sim7", "SHAPED_ES_CARLA_PORT": "3000", WORKER_INDEX_ENV: "2"}
    assert server_address(cfg, env) == ("sim7", 3006)
    assert server_address(make_config(host="h", port=4000, worker_index=1), env) == ("h", 4003)  # kwargs win


def test_bad_settings_are_one_line():
    with pytest.raises(ValueError, match=r"^CarlaNav-v0: \$SHAPED_ES_CARLA_PORT must be an integer"):
        server_address(make_config(), {"SHAPED_ES_CARLA_PORT": "20x0"})
    with pytest.raises(ValueError, match="is not a TCP port"):
        server_address(make_config(port=65530), {WORKER_INDEX_ENV: "3"})
    with pytest.raises(ValueError, match="^CarlaNav-v0: unknown option"):
        make_config(grid_nodes=(3, 3))  # a CarNav-v0 town field
    with pytest.raises(ValueError, match="^CarlaNav-v0: timeout_s"):
        make_config(timeout_s=0)
    assert isinstance(make_config(route_length=[10, 20]), CarlaNavConfig)

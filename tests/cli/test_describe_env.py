"""``shaped-es envs``' listing of one registered id (cli/describe_env.py)."""

from shaped_es.cli.describe_env import describe_env


def test_describe_env():
    d = describe_env("CarNav-v0")
    assert d["presets"] == ["default", "paper"] and d["waypoints"] == 2 and d["time_limit"] == 250
    assert describe_env("CartPole-v1")["waypoints"] is None
    blackjack = describe_env("Blackjack-v1")  # a Tuple of Discretes: flattened to one one-hot vector
    assert blackjack["error"] is None and blackjack["obs"] == 32 + 11 + 2 and blackjack["act"] == 2

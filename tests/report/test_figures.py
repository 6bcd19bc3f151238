"""The across-seed figures: a mean is drawn only where every seed has data (a mean over the seeds that have
reported so far would jump as each seed enters, as it did on Fig. 4's wall-time panel)."""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from shaped_es.report.figures import _draw, plot_reward_bands  # noqa: E402


def _seed(x, y):
    x, y = np.asarray(x, float), np.asarray(y, float)
    return {"wall_time_s": x, "test_reward_mean": y, "generation": np.arange(len(x), dtype=float)}


def test_the_mean_starts_where_every_seed_has_begun():
    early = _seed([10, 20, 30], [100, 200, 300])  # one seed reports first ...
    late = _seed([25, 50], [0, 0])  # ... the other's first point comes at 25 s
    fig, ax = plt.subplots()
    assert _draw(ax, [early, late], "wall_time_s", "test_reward_mean", "k", "m", 0.95, hold_end=True)
    x, y = ax.lines[0].get_xdata(), ax.lines[0].get_ydata()
    ok = np.isfinite(y)
    assert x[ok].min() >= 25 and x[ok].max() == 50  # from the last seed's start to the longest end
    # at 25 s: (200 + 0) / 2; from 30 s on: (300, held to the end, + 0) / 2; never one seed alone
    np.testing.assert_allclose(np.unique(y[ok]), [100.0, 150.0])
    plt.close(fig)


def test_generation_axis_uses_every_seed(tmp_path):
    a, b = _seed([1, 2, 3], [1, 2, 3]), _seed([1, 2], [3, 4])
    fig, ax = plt.subplots()
    _draw(ax, [a, b], "generation", "test_reward_mean", "k", "m", 0.95)
    y = ax.lines[0].get_ydata()
    np.testing.assert_allclose(y[np.isfinite(y)], [2.0, 3.0])  # generations 1, 2 (both); 3 has one seed
    plt.close(fig)
    assert plot_reward_bands({"vanilla": [a, b]}, tmp_path / "f.png").stat().st_size > 10_000


def test_the_legend_names_the_policy_a_run_tested(tmp_path):
    from shaped_es.report.plots import tested_policy

    def run(name, text):
        (tmp_path / name).mkdir()
        (tmp_path / name / "config.yaml").write_text(text)
        return tmp_path / name

    assert tested_policy(run("mean", "method: vanilla\nrollout:\n  test_policy: mean\n")) == "mean"
    assert tested_policy(run("best", "method: shaped\nrollout:\n  test_policy: best\n")) == "best member"
    assert tested_policy(run("old", "method: vanilla\nrollout:\n  episodes: 2\n")) == "best member"  # before the setting
    assert tested_policy(run("ppo", "method: ppo\nrollout:\n  test_policy: mean\n")) == "policy"
    assert tested_policy(tmp_path / "missing") == "policy"


def test_a_figure_is_written_whole_or_not_at_all(tmp_path):
    """A figure goes through a temporary of its own and a rename (as every file of a run): a save that fails
    while drawing leaves the old figure as it was and no temporary; one that succeeds replaces it."""
    import matplotlib.pyplot as plt
    import pytest

    from shaped_es.report.figures import save_figure

    out = tmp_path / "figures" / "reward.png"
    out.parent.mkdir()
    out.write_bytes(b"old figure")
    fig = plt.figure()

    def killed_midway(fh, **kw):  # half a PNG drawn, then the draw fails
        fh.write(b"\x89PNG half")
        raise RuntimeError("killed while drawing")

    fig.savefig = killed_midway
    with pytest.raises(RuntimeError):
        save_figure(fig, out)
    assert out.read_bytes() == b"old figure"
    assert sorted(p.name for p in out.parent.iterdir()) == ["reward.png"]
    fig = plt.figure()
    fig.gca().plot([0, 1], [1, 0])
    assert save_figure(fig, out) == out
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in out.parent.iterdir()) == ["reward.png"]
    assert not plt.get_fignums()  # every figure closed, failed or not

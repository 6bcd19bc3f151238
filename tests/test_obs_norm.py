"""``es.obs_norm``: running observation normalization (ARS V2) for the ES methods.

The statistics (``policies.ObsStats``) merge like one pass over all the data; the rollouts' per-member
sums do not depend on how members are split into tasks (batched core, Gymnasium envs, serial envs);
a run's rows do not depend on the worker count; a crashed run resumes to the rows and checkpoint an
uninterrupted one gives; ``load_policy(...).predict`` (and ``to_torch``, ``evaluate``) act as the
rollouts did; the shaped method's ``candidate`` fits the mean's clone on normalized states (labels read
raw ones) with the normalizer the next generation's rollouts use, and resumes exactly; its other
mechanisms refuse the setting in one line, PPO ignores it with a warning.
"""

import warnings
from dataclasses import replace

import numpy as np
import pytest

from helpers import CARTPOLE_TINY, new_run, run_until_crash, strip_time, train
from shaped_es import evaluation_seeds, load_policy
from shaped_es.config import ConfigError, ConfigWarning, build_config
from shaped_es.executors.inline import InlineExecutor
from shaped_es.policies import OBS_CLIP, MLPSpec, ObsNorm, ObsStats
from shaped_es.rollout import policy_episode_tasks, population_tasks, run_task
from shaped_es.trained.evaluate import evaluate_run
from shaped_es.trainer import Trainer

TINY = {**CARTPOLE_TINY, "executor": "inline", "es": {**CARTPOLE_TINY["es"], "obs_norm": True}}


# --- the statistics ---------------------------------------------------------------------------------


def test_merged_statistics_equal_one_pass_over_all_data():
    rng = np.random.default_rng(0)
    parts = [rng.normal(3.0, 2.0, size=(n, 4)) * [1, 10, 0.1, 1] for n in (1, 7, 50, 3)]
    stats = ObsStats.empty(4)
    for x in parts:
        stats = stats.merge(ObsStats.from_sums(len(x), x.sum(0), (x * x).sum(0)))
    every = np.concatenate(parts)
    assert stats.count == len(every)
    np.testing.assert_allclose(stats.mean, every.mean(0), rtol=1e-12)
    np.testing.assert_allclose(stats.var, every.var(0), rtol=1e-9)
    assert stats.merge(ObsStats.empty(4)).count == stats.count  # an empty batch changes nothing


def test_normalizer_before_any_data_and_its_clip():
    norm = ObsStats.empty(3).norm()  # mean 0, variance 1: the identity, clipped
    np.testing.assert_array_equal(norm.mean, np.zeros(3, np.float32))
    np.testing.assert_array_equal(norm.std, np.ones(3, np.float32))
    out = norm.apply(np.array([[0.5, -7.0, 100.0]]))
    assert out.dtype == np.float32
    np.testing.assert_array_equal(out, [[0.5, -OBS_CLIP, OBS_CLIP]])
    const = ObsStats.from_sums(4, np.full(2, 8.0), np.full(2, 16.0)).norm()  # a constant observation
    np.testing.assert_array_equal(const.apply(np.full((1, 2), 2.0)), [[0.0, 0.0]])


# --- the rollouts' sums -----------------------------------------------------------------------------


def _population(env_id, obs_dim, act_dim, P=5, E=2):
    spec = MLPSpec(obs_dim, act_dim, (8,))
    rng = np.random.default_rng(1)
    params = rng.normal(0, 0.5, size=(P, spec.num_params)).astype(np.float32)
    seeds = np.arange(P * E).reshape(P, E) + 100
    return spec, params, seeds


def _sums(env_id, spec, params, seeds, workers, norm=None, record=False):
    tasks = population_tasks(env_id, {}, spec, params, seeds, workers, record=record, obs_norm=norm,
                             obs_stats=True)
    res = [run_task(t) for t in tasks]
    return res, [np.concatenate([r.obs_stats[k] for r in res]) for k in range(3)]


@pytest.mark.parametrize("env_id", ["CarNav-v0", "CartPole-v1"])
def test_member_sums_do_not_depend_on_the_task_split(env_id):
    """Per member: the count is its steps, the sum its observations' (as recorded), whatever the split."""
    from shaped_es.rollout import probe_env

    probe = probe_env(env_id, {})
    spec, params, seeds = _population(env_id, probe.obs_dim, probe.act_dim)
    norm = ObsNorm(np.full(spec.obs_dim, 0.1, np.float32), np.full(spec.obs_dim, 2.0, np.float32))
    res1, one = _sums(env_id, spec, params, seeds, 1, norm, record=True)
    _, three = _sums(env_id, spec, params, seeds, 3, norm)
    for a, b in zip(one, three):
        np.testing.assert_array_equal(a, b)
    count, total, squares = one
    lengths = np.concatenate([r.lengths for r in res1]).sum(1)  # (P,)
    np.testing.assert_array_equal(count, lengths)
    states = [t.state.astype(np.float64) for r in res1 for t in r.transitions]  # raw observations
    np.testing.assert_allclose(total, [s.sum(0) for s in states], rtol=1e-10, atol=1e-9)
    np.testing.assert_allclose(squares, [(s * s).sum(0) for s in states], rtol=1e-10, atol=1e-9)
    # the policies saw the normalized observations: their recorded actions are forward(norm(state))
    from shaped_es.policies import forward

    tr = res1[0].transitions[0]
    np.testing.assert_allclose(tr.action, forward(spec, params[:1], norm.apply(tr.state)[None])[0],
                               rtol=1e-5, atol=1e-6)


def test_serial_envs_give_the_lock_step_sums(monkeypatch):
    spec, params, seeds = _population("CartPole-v1", 4, 2, P=3, E=3)
    _, lock_step = _sums("CartPole-v1", spec, params, seeds, 1)
    monkeypatch.setattr("shaped_es.rollout.runs_serially", lambda env: True)
    _, serial = _sums("CartPole-v1", spec, params, seeds, 1)
    for a, b in zip(lock_step, serial):
        np.testing.assert_array_equal(a, b)


# --- runs -------------------------------------------------------------------------------------------


def _inline(workers: int) -> InlineExecutor:
    ex = InlineExecutor()
    ex.workers = workers  # the population split into this many tasks, run in this process
    return ex


def test_run_does_not_depend_on_the_executor_or_worker_count_and_differs_from_no_norm(tmp_path):
    one = train(tmp_path / "one", TINY, executor=_inline(1))
    three = train(tmp_path / "three", TINY, executor=_inline(3))
    procs = train(tmp_path / "procs", {**TINY, "executor": "process", "workers": 2})  # tasks pickled
    a, _ = one.require_checkpoint()
    for other in (three, procs):
        assert strip_time(one.read_metrics()) == strip_time(other.read_metrics())
        b, _ = other.require_checkpoint()
        for k in ("policy/obs_count", "policy/obs_mean", "policy/obs_m2", "policy/best_obs_mean", "policy/mean"):
            np.testing.assert_array_equal(a[k], b[k])
    rows = one.read_metrics()
    assert float(a["policy/obs_count"]) == float(rows[-1]["env_steps"])  # every training step counted once
    plain = train(tmp_path / "plain", {**TINY, "es": CARTPOLE_TINY["es"]})
    arrays, _ = plain.require_checkpoint()
    assert not any("obs" in k for k in arrays)  # off: nothing saved, nothing applied
    assert load_policy(tmp_path / "plain").obs_norm is None
    assert strip_time(plain.read_metrics()) != strip_time(rows)


@pytest.mark.parametrize("crash_at,every", [(4, 2), (5, 3)])
def test_crash_and_resume_equals_an_uninterrupted_run(tmp_path, monkeypatch, crash_at, every):
    cfg_d = {**TINY, "generations": 8, "checkpoint_every": every}
    full = train(tmp_path / "full", cfg_d)
    cfg, store = new_run(tmp_path / "crashed", cfg_d)
    run_until_crash(monkeypatch, cfg, store, crash_at)
    Trainer(cfg, store, progress=False).run()
    assert strip_time(store.read_metrics()) == strip_time(full.read_metrics())
    a, _ = full.require_checkpoint()
    b, _ = store.require_checkpoint()
    assert sorted(a) == sorted(b)
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)


def test_load_policy_predict_acts_as_the_rollouts(tmp_path):
    """The saved best policy with the normalizer it was tested with: predict on a rollout's raw
    observations gives the rollout's actions bit for bit; evaluate's returns equal a plain gymnasium
    loop's; to_torch agrees; "mean" takes the latest statistics."""
    import torch

    store = train(tmp_path / "run", {**TINY, "env": "CarNav-v0", "es": {**TINY["es"], "pairs": 3},
                                     "rollout": {"episodes": 1, "test_episodes": 2}, "generations": 3})
    arrays, _ = store.require_checkpoint()
    for which in ("best", "mean"):
        policy = load_policy(tmp_path / "run", which)
        assert policy.obs_norm is not None
        if which == "best":
            np.testing.assert_array_equal(policy.obs_norm.std, arrays["policy/best_obs_std"])
        else:
            latest = ObsStats(float(arrays["policy/obs_count"]), arrays["policy/obs_mean"], arrays["policy/obs_m2"])
            np.testing.assert_array_equal(policy.obs_norm.mean, latest.norm().mean)
        seeds = evaluation_seeds(3, 12345)
        (task,) = policy_episode_tasks(policy.env_id, policy.env_kwargs, policy.spec, policy.theta,
                                       np.array(seeds), workers=1, max_steps=policy.max_steps, rowwise=True,
                                       obs_norm=policy.obs_norm)
        tr = run_task(replace(task, record=True)).transitions[0]
        np.testing.assert_array_equal(policy.predict(tr.state), tr.action)  # CarNav's Box is [-1, 1]
        with torch.no_grad():
            out = policy.to_torch()(torch.from_numpy(tr.state)).numpy()
        np.testing.assert_allclose(out, tr.action, rtol=1e-5, atol=1e-6)
        env = policy.make_env()
        ours = []
        for s in seeds:
            obs, _ = env.reset(seed=s)
            total, done = 0.0, False
            while not done:
                obs, r, term, trunc, _ = env.step(policy.predict(obs))
                total, done = total + float(r), term or trunc
            ours.append(total)
        env.close()
        ev = evaluate_run(tmp_path / "run", episodes=3, which=which, seed=12345, executor="inline")
        np.testing.assert_array_equal(ev["episode_returns"], ours)


def test_best_policy_keeps_the_normalizer_it_was_tested_with(tmp_path, monkeypatch):
    """The best row's test reward is reproduced by evaluating its policy on the run's own test seeds."""
    from shaped_es import seeding

    store = train(tmp_path / "run", {**TINY, "generations": 5})
    rows = store.read_metrics()
    arrays, meta = store.require_checkpoint()
    best_g = meta["best_generation"] - 1  # the row whose test episodes made it the best
    policy = load_policy(tmp_path / "run")
    seeds = seeding.episode_seeds(3, seeding.TEST, best_g, np.zeros(1), 3)[0]  # TINY's seed, 3 episodes
    tasks = policy_episode_tasks(policy.env_id, policy.env_kwargs, policy.spec, policy.theta, seeds,
                                 workers=1, generation=best_g, obs_norm=policy.obs_norm)
    ret = np.concatenate([run_task(t).returns[0] for t in tasks])
    assert float(ret.mean()) == float(rows[best_g]["test_reward_mean"]) == meta["best_test_reward"]


# --- config -----------------------------------------------------------------------------------------


@pytest.mark.parametrize("mechanism", ["paper", "pair"])
def test_shaped_refuses_obs_norm_but_with_candidate_in_one_line(tmp_path, mechanism):
    from shaped_es.preflight import check_run

    cfg = build_config({"env": "CarNav-v0", "method": "shaped", "es": {"obs_norm": True},
                        "shaping": {"mechanism": mechanism}})
    with pytest.raises(ConfigError, match=f"es.obs_norm is not supported with shaping.mechanism={mechanism}") as exc:
        check_run(cfg, warn=False)
    assert "\n" not in str(exc.value)
    with pytest.raises(ConfigError, match="es.obs_norm"):
        Trainer(cfg, new_run(tmp_path / "r", cfg)[1], progress=False)
    for method in ("shaped", "shaped_cmaes"):  # the default mechanism passes, without a warning
        ok = build_config({"env": "CarNav-v0", "method": method, "es": {"obs_norm": True}})
        with warnings.catch_warnings():
            warnings.simplefilter("error", ConfigWarning)
            check_run(ok, warn=True)


@pytest.mark.parametrize("mechanism,setting", [("paper", {"mean_clone": {"revert_margin": 1.0}}),
                                               ("pair", {"mean_clone": {"accept_margin": 2.0}}),
                                               ("paper", {"backoff_after": 3})])
def test_candidate_only_settings_with_another_mechanism_are_one_error_line(mechanism, setting):
    from shaped_es.preflight import check_run

    key = next(iter(setting))
    name = f"shaping.{key}" + (f".{next(iter(setting[key]))}" if isinstance(setting[key], dict) else "")
    cfg = build_config({"env": "CarNav-v0", "method": "shaped", "shaping": {"mechanism": mechanism, **setting}})
    with pytest.raises(ConfigError, match=f"{name} only applies with shaping.mechanism=candidate") as exc:
        check_run(cfg, warn=False)
    assert "\n" not in str(exc.value) and repr(mechanism) in str(exc.value)
    check_run(build_config({"env": "CarNav-v0", "method": "shaped", "shaping": setting}), warn=False)  # candidate
    check_run(build_config({"env": "CarNav-v0", "method": "shaped",  # the clone's own settings: pair reads them
                            "shaping": {"mechanism": mechanism, "mean_clone": {"steps": 50}}}), warn=False)


# --- the shaped method (mechanism candidate) --------------------------------------------------------

SHAPED_TINY = {"env": "UR5Reach-v0", "executor": "inline", "method": "shaped", "generations": 4, "seed": 1,
               "es": {"pairs": 6, "obs_norm": True}, "policy": {"hidden": [8]},
               "rollout": {"episodes": 1, "test_episodes": 2, "max_steps": 40}, "tensorboard": False,
               "shaping": {"labels": "controller", "history": 2,
                           "mean_clone": {"steps": 10, "batch_size": 32, "record_every": 3}}}


@pytest.mark.parametrize("method,labels", [("shaped", "controller"), ("shaped", "mphi"),
                                           ("shaped_cmaes", "controller")])
def test_shaped_candidate_clones_through_the_next_generations_normalizer(tmp_path, monkeypatch, method, labels):
    """Each generation's mean clone gets the normalizer generation g+1's rollouts (and so its candidates)
    use, and the run resumes exactly after a crash."""
    from shaped_es import trainer as trainer_mod
    from shaped_es.guides.mechanisms import mean_clone

    sh = {**SHAPED_TINY["shaping"], "labels": labels}
    if labels == "mphi":  # M_phi reads raw states (its own normalization), whatever the policies see
        sh["inverse_dynamics"] = {"steps_per_generation": 30, "filter": "none"}
    cfg = {**SHAPED_TINY, "method": method, "shaping": sh}
    clone_norms, roll_norms = {}, {}
    clone, tasks = mean_clone.clone_sampled, trainer_mod.population_tasks

    def spy_clone(*a, **kw):
        clone_norms[len(clone_norms)] = kw["obs_norm"]
        return clone(*a, **kw)

    def spy_tasks(*a, **kw):
        roll_norms.setdefault(a[6], kw["obs_norm"])  # generation -> its members' normalizer
        return tasks(*a, **kw)

    monkeypatch.setattr(mean_clone, "clone_sampled", spy_clone)
    monkeypatch.setattr(trainer_mod, "population_tasks", spy_tasks)
    full = train(tmp_path / "full", cfg).read_metrics()
    assert full[-1]["shaping_active"] == "1" and any(r["candidate_return"] != "" for r in full)
    cloned = [g for g in range(4) if full[g]["clone_samples"] != ""]  # generations whose mean was cloned
    per = 4 if labels == "mphi" else 1  # M_phi's labels: the rivals' clones too (guides/rival.py: frame, servo,
    # shooting)
    assert per * len(cloned) == len(clone_norms) >= 2
    for i, g in enumerate(np.repeat(cloned, per)):
        if g + 1 in roll_norms:
            assert clone_norms[i] is not None
            np.testing.assert_array_equal(clone_norms[i].mean, roll_norms[g + 1].mean)
            np.testing.assert_array_equal(clone_norms[i].std, roll_norms[g + 1].std)
    assert not np.array_equal(clone_norms[0].mean, np.zeros_like(clone_norms[0].mean))  # not the identity
    monkeypatch.undo()
    c, store = new_run(tmp_path / "crashed", cfg)
    run_until_crash(monkeypatch, c, store, 3)
    Trainer(c, store, progress=False).run()
    assert strip_time(store.read_metrics()) == strip_time(full)


def test_clone_is_fitted_on_normalized_states_and_labels_read_raw_ones():
    """clone_sampled with obs_norm: the label source and the reference read the raw states; the fit sees
    them normalized, and fits a policy of normalized inputs far better than it fits the raw ones."""
    from shaped_es.policies import forward
    from shaped_es.shaping.cloning import clone_sampled
    from shaped_es.shaping.member_rows import MemberRows
    from shaped_es.shaping.settings import CloningConfig

    rng = np.random.default_rng(0)
    spec = MLPSpec(3, 2, (16,))
    scale, shift = np.array([50.0, 0.01, 3.0]), np.array([200.0, -0.5, 10.0])
    states = (rng.normal(size=(600, 3)) * scale + shift).astype(np.float32)  # badly scaled raw states
    x = states.astype(np.float64)
    stats = ObsStats.from_sums(len(x), x.sum(0), (x * x).sum(0))
    norm = stats.norm()
    teacher = rng.normal(0, 1.0, size=spec.num_params).astype(np.float32)
    seen = []

    def labels(s, q):  # the teacher acts on normalized states; the label source gets raw ones
        seen.append(np.array(s))
        return forward(spec, teacher[None], norm.apply(s).reshape(1, -1, 3))[0].reshape(*s.shape[:-1], 2)

    refs = []
    rows = MemberRows.from_lists([states], [np.zeros((600, 1), np.float32)])
    cfg = CloningConfig(steps=300, lr=0.01, batch_size=64, optimizer="adam")
    theta = spec.init(3)[None]  # (1, n)
    res = clone_sampled(spec, theta, rows, labels, cfg, np.array([7]), obs_norm=norm,
                        reference_fn=lambda s: refs.append(np.array(s)) or np.zeros((*s.shape[:-1], 2), np.float32))
    raw = clone_sampled(spec, theta, rows, labels, cfg, np.array([7]))  # the same fit on raw inputs
    assert np.abs(seen[0]).max() > 100 and np.abs(refs[0]).max() > 100  # raw states, not normalized ones
    assert res.loss_after[0] < 0.2 * raw.loss_after[0]
    pred = forward(spec, res.theta_star, norm.apply(states)[None])[0]  # the clone acts on norm(s)
    err_norm = float(np.mean((pred - labels(states, None)) ** 2))
    pred_raw = forward(spec, res.theta_star, states[None])[0]
    assert err_norm < 0.2 * float(np.mean((pred_raw - labels(states, None)) ** 2))


def test_ppo_ignores_obs_norm_with_a_warning():
    from shaped_es.preflight import warn_ignored

    with pytest.warns(ConfigWarning, match="es.obs_norm"):
        warn_ignored(build_config({"method": "ppo", "es": {"obs_norm": True}}))


def test_a_shaped_run_starts_from_its_label_probes_statistics_and_restarts_to_the_same(tmp_path, monkeypatch):
    """With ``es.obs_norm`` the label probe's simulated candidates are fitted and driven under the normalizer of
    the probe's own data, and generation 0 starts from those statistics: from an empty normalizer, generation 1's
    rescaled every input and a new user's probe candidate, taken at generation 0 (-9.26), tested at -54.91 a
    generation later. A run restarted in generation 0 (the probe on file) starts from the same statistics."""
    import json

    from shaped_es import trainer as trainer_mod
    from shaped_es.guides import clone_probe

    cfg = {**SHAPED_TINY, "shaping": {**SHAPED_TINY["shaping"], "labels": "mphi",
                                      "inverse_dynamics": {"steps_per_generation": 30, "filter": "none"}}}
    roll_norms, sim_norms = {}, []
    tasks, rounds = trainer_mod.population_tasks, clone_probe.roll_out

    def spy_tasks(*a, **kw):
        roll_norms.setdefault(a[6], kw["obs_norm"])  # generation -> its members' normalizer
        return tasks(*a, **kw)

    def spy_roll(cfg_, spec, params, seeds, generation, executor=None, norm=None):
        if generation >= 10_000:  # the simulated candidates' rounds (the data's rollouts: generation 0, 1)
            sim_norms.append(norm)
        return rounds(cfg_, spec, params, seeds, generation, executor, norm)

    monkeypatch.setattr(trainer_mod, "population_tasks", spy_tasks)
    monkeypatch.setattr(clone_probe, "roll_out", spy_roll)
    store = train(tmp_path / "full", {**cfg, "generations": 2})
    count, mean, m2 = json.loads((store.root / "label_probe.json").read_text())["obs_stats"]
    start = ObsStats(count, np.array(mean), np.array(m2)).norm()
    assert count > 0 and not np.allclose(start.mean, 0) and sim_norms
    for norm in (roll_norms[0], *sim_norms):  # generation 0 and every simulated candidate: the probe's data's
        np.testing.assert_array_equal(norm.mean, start.mean)
        np.testing.assert_array_equal(norm.std, start.std)
    monkeypatch.undo()
    c, again = new_run(tmp_path / "restarted", {**cfg, "generations": 2})
    run_until_crash(monkeypatch, c, again, 1)  # the probe is on file, no checkpoint yet: generation 0 again
    Trainer(c, again, progress=False).run()
    assert strip_time(again.read_metrics()) == strip_time(store.read_metrics())


def test_check_env_labels_probes_as_an_obs_norm_run_does_and_the_runs_line_says_how():
    """A new user's badly scaled base: ``check-env --labels`` probed with raw inputs (its candidate below zero
    action) where the obs_norm run's probe found one at 2.20, and the run's line pointed at the raw check."""
    from shaped_es.guides.label_check import check_labels, probe_line
    from shaped_es.guides.label_probe import ProbeResult

    raw, normed = check_labels("PointVel-v0"), check_labels("PointVel-v0", obs_norm=True)
    assert raw["clones"] != normed["clones"]  # its simulated candidates were fitted and driven under the normalizer
    res = ProbeResult("both", None, {"both": [1.0]}, 10, 0.1, "r", [0.0], obs_stats=[3.0, [0.0], [1.0]])
    assert probe_line(res, "X-v0").endswith("shaped-es check-env X-v0 --labels --obs-norm")
    assert probe_line(ProbeResult("both", None, {"both": [1.0]}, 10, 0.1, "r", [0.0]), "X-v0").endswith("--labels")

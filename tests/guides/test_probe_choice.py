"""The label probe's choice rules (guides/probe_choice.py): the frame's test on simulated candidates and labels,
the signed-rank test, and the rule for the extensions the probe offers (chunk targets, a longer clip)."""

import subprocess
import sys

import numpy as np
from scipy.stats import wilcoxon

from shaped_es.guides.probe_choice import choose, choose_targets, clone_beats, signed_rank_greater


def test_signed_rank_is_scipys_wilcoxon_on_the_probes_sizes():
    # ties and zeros up to 13 episodes (SciPy's exhaustive permutation test), none up to 40 (its exact law)
    rng = np.random.default_rng(0)
    for i in range(600):
        if i % 2:
            d = rng.integers(-4, 5, size=int(rng.integers(2, 14))) * 0.5
        else:
            d = rng.standard_t(2, size=int(rng.integers(2, 41))) + rng.normal()
        if np.any(d != 0):
            want = float(wilcoxon(d, alternative="greater").pvalue)
            assert np.isclose(signed_rank_greater(d), want, rtol=1e-9, atol=1e-12), d
    assert signed_rank_greater(np.arange(1.0, 11.0)) == 1 / 2**10  # every sign positive: the one extreme
    assert signed_rank_greater(np.array([0.0, -1.0])) == 1.0


def test_a_shaped_guide_does_not_import_scipy_stats():
    # scipy.stats costs every shaped run ~1 s at its start (the probe's test is written by hand for that)
    code = "import sys, shaped_es.guides.shaped; print('scipy.stats' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"


def test_choose_replaces_the_default_only_where_zero_action_beats_its_labels():
    zero = np.array([0.0, 0.0, 0.0, 0.0])
    good = np.array([1.0, 2.0, 3.0, 4.0])  # the default's labels drive the body: kept, whatever else wins
    better = good + 5.0
    assert choose({"both": good, "world": better}, "both", zero)[0] == "both"
    bad = np.array([-5.0, -6.0, -5.5, -6.5])  # worse than zero action on every episode
    noisy = bad + np.array([4.0, -3.0, 5.0, -4.0])  # not beyond 2 SE of the default
    clear = bad + np.array([4.0, 4.2, 3.9, 4.1])
    name, reason = choose({"both": bad, "world": noisy, "world+clip2": clear}, "both", zero)
    assert name == "world+clip2" and reason.startswith("zero action beats the default")
    name, reason = choose({"both": bad, "world": noisy}, "both", zero)
    assert name == "both" and "no variant beats" in reason


def test_choose_takes_the_variant_whose_simulated_candidate_is_clearly_better():
    zero = np.zeros(10)
    labels = {"both": np.full(10, 9.0), "both+clip2": np.full(10, 9.0), "world": np.full(10, 8.0)}
    # heavy-tailed clone returns: the default's clone crashes on 2 of 10 episodes (a 2-SE test misses it)
    base = np.array([5.5, 4.4, -7.1, 7.3, 2.9, -26.8, -51.1, 0.2, 6.9, 5.5])
    clipped = np.array([7.3, 6.5, 6.6, 8.5, 5.2, 5.4, 8.0, 5.9, 3.8, 7.9])
    name, reason = choose(labels, "both", zero, {"both": base, "both+clip2": clipped, "world": base})
    assert name == "both+clip2" and reason.startswith("its simulated candidate")
    # a consistent but tiny gain (0.25 where the probe's returns span ~60) does not switch
    flat = np.full(10, -25.0)
    tiny = {"both": flat, "both+clip2": flat + 0.25, "world": flat}
    assert choose({**labels, "both": np.full(10, 35.0)}, "both", zero, tiny)[0] == "both"
    # clones that do not differ: the label rule decides (here: keep the default)
    assert choose(labels, "both", zero, {"both": clipped, "both+clip2": clipped[::-1], "world": clipped})[0] == "both"


def test_clone_beats_needs_a_signed_rank_win_and_a_share_of_the_spread():
    a = np.arange(10.0) + 1.0
    assert clone_beats(a + 1.0, a, scale=10.0) == (True, 1.0)
    assert not clone_beats(a + 1.0, a, scale=100.0)[0]  # 1 < 5% of 100
    assert not clone_beats(a, a, scale=1.0)[0]  # no difference at all
    mixed = a + np.array([3.0, -3.0] * 5)  # as many losses as wins
    assert not clone_beats(mixed, a, scale=1.0)[0]


def test_chunk_targets_stand_only_where_their_candidate_is_the_best_of_all():
    """A chunk variant that beats both's clearly is taken where its simulated candidate is also the best of every
    variant's and shooting horizon's; where a shooting candidate drove better (the kart), the one-step variants
    are chosen among as if no chunk variant had been probed."""
    def eps(m):
        return np.array([m + 0.01 * k for k in range(10)])
    returns = {k: eps(1.0) for k in ("both", "world", "both+chunk4")}
    clones = {"both": eps(0.0), "world": eps(2.0), "both+chunk4": eps(4.0)}
    zero = eps(0.5)
    assert choose_targets(returns, "both", zero, clones, ["both+chunk4"])[0] == "both+chunk4"
    assert choose_targets(returns, "both", zero, clones, ["shoot:8"])[0] == "world"  # as without chunk variants
    one = {k: v for k, v in clones.items() if "chunk" not in k}
    name, why = choose_targets(returns, "both", zero, clones, ["shoot:8"])
    alone = choose({k: v for k, v in returns.items() if "chunk" not in k}, "both", zero, one)
    assert name == alone[0] and why.startswith(alone[1])
    assert "both+chunk4's simulated candidate did beat the default's clearly" in why  # says why it was passed over
    assert "the shooting labels' (8 steps)" in why
    assert "here world's" in choose_targets(returns, "both", zero, clones, ["world"])[1]
    # UR5Reach-v0's seeds 0 and 1: the chunk candidate is the best of all, but the one-step labels drive the arm
    # clearly better than the chunk labels: the one-step displacement shows the action, so one-step targets stay
    drive = {**returns, "world": eps(3.0)}
    name, why = choose_targets(drive, "both", zero, clones, ["both+chunk4"])
    assert name == "world" and "do not drive the body better (here frame=world, query_clip=none's, by 2.00)" in why
    near = {**returns, "world": eps(1.2) + 0.5 * (-1.0) ** np.arange(10)}  # better on average, not by 2 SE
    assert choose_targets(near, "both", zero, clones, ["both+chunk4"])[0] == "both+chunk4"


def test_a_longer_clip_stands_only_where_the_labels_chosen_without_it_do_not_drive_better():
    """A clip-4 variant that won the frame test stands where the labels chosen without it do not drive the body
    clearly better and its own labels drive it better than zero action (the unicycle's clip-4 seeds); a variant
    with both extensions must pass both rules."""
    def eps(m):
        return np.array([m + 0.01 * k for k in range(10)])
    returns = {"both": eps(1.0), "world": eps(1.0), "both+clip4": eps(1.001), "both+chunk4+clip4": eps(1.0)}
    clones = {"both": eps(0.0), "world": eps(0.0), "both+clip4": eps(4.0), "both+chunk4+clip4": eps(2.0)}
    zero = eps(0.5)
    assert choose_targets(returns, "both", zero, clones, ["both+clip4"], "+clip4")[0] == "both+clip4"
    name, why = choose_targets({**returns, "both": eps(3.0)}, "both", zero, clones, ["both+clip4"], "+clip4")
    assert name == "both" and "but a query clip of 4 stands only where the labels chosen without it" in why
    assert choose_targets(returns, "both", zero, clones, ["both+clip4"], None)[0] == "both+clip4"  # off: a plain name
    both = {**clones, "both+clip4": eps(0.0), "both+chunk4+clip4": eps(4.0)}  # the doubly extended one wins the test
    assert choose_targets(returns, "both", zero, both, ["both+chunk4+clip4"], "+clip4")[0] == "both+chunk4+clip4"
    assert choose_targets(returns, "both", zero, both, ["shoot:8"], "+clip4")[0] == "both"  # chunk: not the best of all
    # the Reacher's seeds 0, 2 and 3: every variant's labels drive the arm worse than zero action; a clip of 4 is a
    # larger move asked of labels that do not move the body: passed over, and the line says why
    name, why = choose_targets(returns, "both", eps(1.5), clones, ["both+clip4"], "+clip4")
    assert name == "both" and "a query clip of 4 stands only where its labels drive the body better than zero" in why
    near = eps(0.9) + 0.3 * (-1.0) ** np.arange(10)  # zero action a little worse on average, not by 2 SE
    assert choose_targets(returns, "both", near, clones, ["both+clip4"], "+clip4")[0] == "both"


def test_chunk_targets_are_judged_against_the_labels_chosen_without_either_extension():
    """UR5Reach-v0's seed 1: without chunk variants the choice was a clip-4 variant whose labels drove the arm about
    as badly as the chunk variant's, so the chunk variant stood, though both's labels beat its own by 18 (the run
    ended 19 return lower). Chunk targets are judged against the labels chosen without chunk and longer-clip
    variants both; the choice then made without chunk variants stands."""
    def eps(m):
        return np.array([m + 0.01 * k for k in range(10)])
    alt = 3.0 * (-1.0) ** np.arange(10)
    returns = {"both": eps(6.0), "both+clip4": eps(5.0) + alt, "both+chunk4": eps(4.0)}
    clones = {"both": eps(0.0), "both+clip4": eps(2.0), "both+chunk4": eps(3.0)}
    zero = eps(-1.0)
    name, why = choose_targets(returns, "both", zero, clones, ["both+chunk4", "both+clip4"], "+clip4")
    assert name == "both+clip4" and "chunk targets stand only where the labels chosen without it" in why
    assert "(here frame=both, query_clip=none's, by 2.00)" in why
    # without the longer clip offered, the same chunk rule as before
    two = {k: v for k, v in returns.items() if "clip4" not in k}
    assert choose_targets(two, "both", zero, {k: v for k, v in clones.items() if "clip4" not in k},
                          ["both+chunk4"])[0] == "both"


def test_a_longer_clip_that_never_binds_does_not_stand():
    """UR5Reach-v0's seed 17: both+chunk4+clip4's labels were both+chunk4's to the last digit (the clip never
    bound), so its simulated candidate was the same labels' clone on another seed stream; its win (44.7 against
    34.6) was the clone's noise, and the run that took it was slower (30 generations against 13)."""
    def eps(m):
        return np.array([m + 0.01 * k for k in range(10)])
    returns = {"both": eps(1.0), "world": eps(1.0), "both+clip4": eps(1.0)}  # both+clip4's labels are both's
    clones = {"both": eps(0.0), "world": eps(0.0), "both+clip4": eps(4.0)}
    name, why = choose_targets(returns, "both", eps(0.5), clones, ["both+clip4"], "+clip4")
    assert name == "both" and "a query clip of 4 stands only where the clip changes the labels (here both's" in why
    bound = {**returns, "both+clip4": eps(1.0) + 0.001}  # the clip changed them: it stands
    assert choose_targets(bound, "both", eps(0.5), clones, ["both+clip4"], "+clip4")[0] == "both+clip4"


def test_the_shooting_rival_stays_where_it_beats_zero_action_or_every_candidate():
    """A new user's drone: zero action hovers (return 0) and every simulated candidate loses to it, the shooting
    labels' least (-2.6 against -3.3); runs that dropped that rival solved no seed in 30 generations, runs that
    kept it solved in 7-29. The Reacher's: the shooting candidate below zero action and below the best variant's
    (dropped, as before: an extra row that never wins cost it 2 of 8 solved seeds)."""
    from shaped_es.guides.probe_choice import keep_shoot

    def eps(m):
        return np.array([m + 0.1 * (-1) ** k for k in range(10)])
    drone = {"both": eps(-3.3), "world+clip2": eps(-4.2)}
    assert keep_shoot(eps(-2.6), eps(0.0), drone)  # the best candidate of all
    assert not keep_shoot(eps(-2.6), eps(0.0), drone, keep_best=False)  # the gate alone
    assert not keep_shoot(eps(-18.3), eps(-12.6), {"world+clip2": eps(-16.9)})  # the Reacher's seed 0
    assert keep_shoot(eps(3.0), eps(0.0), {"both": eps(9.0)})  # above zero action: kept, as always
    assert not keep_shoot(eps(-1.0), eps(0.0), {})  # nothing to compare with: the gate alone


def test_the_default_choice_names_the_closest_candidate_and_what_kept_it_out():
    """A new user's hovercraft: both+clip2's simulated candidate 4.18 against the chosen both's -0.89, and the
    line said only that none beats it clearly; it now names the closest and the test it failed."""
    rng = np.random.default_rng(0)
    returns = {"both": np.full(10, 1.0), "both+clip2": np.full(10, 1.0)}
    zero = np.full(10, 0.0) + 0.01 * rng.standard_normal(10)
    noisy = np.array([30.0, -20, 25, -15, 20, -10, 15, -5, 12, 3])  # mean 5.5, half the episodes worse
    clones = {"both": np.zeros(10), "both+clip2": noisy}
    name, why = choose(returns, "both", zero, clones)
    assert name == "both" and "(closest: frame=both, query_clip=2's 5.50 against 0.00, signed-rank p " in why
    assert "needs < 0.05)" in why
    small = {"both": np.zeros(10), "both+clip2": np.full(10, 0.01) + 0.001 * np.arange(10)}  # consistent, tiny
    assert "a gain below 5% of the probe's return spread" in choose(returns, "both", zero, small)[1]
    assert "closest" not in choose(returns, "both", zero, {"both": np.ones(10), "both+clip2": np.zeros(10)})[1]


def test_where_no_candidate_beats_zero_action_the_probe_cannot_judge_and_the_shooting_rival_stays():
    """The drone's seeds where a variant's candidate came first among losers: every simulated candidate below zero
    action (unjudged), and ``keep_unjudged`` keeps the shooting rival; one candidate above zero action by 2
    paired standard errors and the probe judges as before."""
    from shaped_es.guides.probe_choice import keep_shoot, unjudged

    def eps(m):
        return np.array([m + 0.1 * (-1) ** k for k in range(10)])
    clones, tried = {"both": eps(-1.5), "world": eps(-4.0)}, {"4": eps(-3.0), "8": eps(-4.4)}
    assert unjudged(eps(0.0), {**clones, **tried})
    assert not keep_shoot(eps(-3.0), eps(0.0), clones, keep_best=True)  # a variant's came first: dropped
    assert keep_shoot(eps(-3.0), eps(0.0), clones, True, keep_unjudged=True, tried=tried)
    judged = {**clones, "both": eps(1.0)}  # a variant's candidate above zero action: the probe judges
    assert not unjudged(eps(0.0), judged) and not keep_shoot(eps(-3.0), eps(0.0), judged, True, True, tried)
    assert not keep_shoot(eps(-3.0), eps(0.0), clones, True, True, {**tried, "16": eps(2.0)})  # a horizon's above
    assert not unjudged(eps(0.0), {})  # nothing simulated: nothing to say


def test_the_second_horizon_is_the_probed_one_nearest_the_choice():
    from shaped_es.guides.probe_choice import nearest_horizon

    assert nearest_horizon(4, [4, 8, 16]) == 8
    assert nearest_horizon(8, [4, 8, 16]) == 4  # 4 steps away, 16 is 8
    assert nearest_horizon(16, [4, 8, 16]) == 8
    assert nearest_horizon(6, [4, 8]) == 4  # a tie: the shorter
    assert nearest_horizon(4, [4]) is None

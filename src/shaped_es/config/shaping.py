"""The ``shaping`` section of the run configuration (the shaped method's settings), part of ``config/__init__.py``'s
schema: M_phi (``inverse_dynamics``), the members' clones (``cloning``) and the mean's (``mean_clone``)."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator

from shaped_es.config.scalars import Bool, Float, Int, _Strict
from shaped_es.methods import MECHANISMS
from shaped_es.shaping.settings import (ACCEPT_RULES, LABEL_SOURCES, SHOOT_COSTS, SHOOT_FRAMES, SHOOT_MODELS, CloningConfig, InverseDynamicsConfig,
                                        MeanCloneConfig)

# The shaping sections take their defaults from the shaping layer's dataclasses (one truth); guides/shaped.py
# builds those from these sections. tests/test_config.py fails if a shared field's default differs.
_MPHI, _CLONE, _MEAN = InverseDynamicsConfig(), CloningConfig(), MeanCloneConfig()


class InverseDynamicsSettings(_Strict):
    hidden: tuple[Int, ...] = Field(_MPHI.hidden, description="ReLU widths; paper (20, 20) nav, 3 layers arm")
    lr: Float = Field(_MPHI.lr, gt=0, description="Adam learning rate (paper)")
    step_change: Literal["auto"] | Bool = Field(
        "auto", description="M_phi also sees how far each displacement departs from the last step's "
        "(p_{t+1} - p_t - (p_t - p_{t-1}); queries: w_t - p_t - (p_t - p_{t-1})), world and both frames: on a "
        "second-order body a step is mostly the velocity it already had, and the torque's share is learned "
        "slowly from the displacement alone (shaping/mphi_inputs.change_block); auto: the label probe's choice, "
        "on where M_phi without it explains little of held-out actions and with it far more "
        "(guides/probe_step_change.py; without a probe: false); docs/benchmarks/step_change_v33")
    batch_size: Int = Field(_MPHI.batch_size, gt=0, description="minibatch size (paper)")
    steps_per_generation: Int = Field(_MPHI.steps_per_generation, ge=0,
                                      description="training iterations per generation")
    min_return: Float = Field(_MPHI.min_return,
                              description="with filter total or positive (not the default none, which keeps "
                              "every transition): episodes with a lower return are left out (paper: 5)")
    max_dataset: Int = Field(_MPHI.max_dataset, gt=0, description="cap on aggregated transitions (FIFO)")
    frame: Literal["auto", "world", "motion", "waypoint", "both"] = Field(
        "auto", description="M_phi's displacement frame: world (paper), the agent's motion frame, the "
        "waypoint's direction (x toward w_t - p_t; defined at rest), both (world and motion frames "
        "concatenated: the model uses whichever explains the action), or auto: world for 1-D waypoint "
        "spaces; for 2-D and more, both unless the label probe before generation 0 finds another frame and "
        "query_clip (none or 2; 1, the default there, or none where M_phi sees each step's change) whose "
        "simulated candidate (the initial mean cloned toward its labels) clearly drives the body better, or "
        "zero action driving it better than both's labels (RUN/label_probe.json; shaped-es check-env ID --labels)")
    rival_frame: Literal["none", "world", "motion", "waypoint", "both"] = Field(
        "waypoint", description="mechanism candidate, labels mphi: a second M_phi in this frame trains on the same "
        "steps, and the mean's clone toward its labels is a second candidate each generation, judged like the "
        "first (selection picks whichever frame pays on this body; guides/rival.py); none: off; skipped where "
        "it is the run's frame or the waypoint space is 1-D")
    rival_servo: bool = Field(
        True, description="mechanism candidate, labels mphi: a forward model f(s, a) -> p_{t+1} - p_t trains on "
        "the same steps, and the mean's clone toward its damped servo labels (a_hat = k G^T ((w - p) - c f(s, 0)) "
        "/ q, G = df/da; shaping/forward_servo.py) is one more candidate each generation, judged like the others "
        "(the labels of torque-driven arms, which no inverse of the dynamics gives)")
    rival_shoot: bool = Field(
        True, description="mechanism candidate, labels mphi: a forward model of the next shoot_horizon steps "
        "with an action held, f(s, a) -> (p_{t+j} - p_t)_j, trains on the same steps, and the mean's clone toward "
        "its shooting labels (the held candidate action whose predicted path passes nearest the waypoint; "
        "shaping/forward_shoot.py) is one more candidate each generation, judged like the others (the labels "
        "of bodies whose action shows in the position only after a few steps: inertia, a steered wheel); with "
        "frame auto the label probe keeps it only where its simulated candidate beats zero action")
    shoot_horizon: Int = Field(4, ge=1, le=64, description="the shooting labels' horizon: steps an action is held")
    shoot_ahead: Float = Field(1.0, ge=0, le=4, description="the shooting labels aim this many of the waypoint "
                               "path's last steps past the waypoint (w + k (w - the waypoint before it)), as pure "
                               "pursuit looks past its waypoint (a car circles a waypoint inside its turning "
                               "circle); 0: at the waypoint (docs/benchmarks/shoot_ahead_v10)")
    shoot_hold: Bool = Field(False, description="the shooting labels treat a goal the body reached and that stayed "
                             "(its episode's last waypoint, the body within half the waypoint path's last step of it) "
                             "as a point to hold: aimed at, not past (shoot_ahead), and paths scored by their mean "
                             "distance to it whatever shoot_cost. A new user's crane: late reward 82.1 against 60.8; "
                             "but a quadrotor 8/10 against 10/10 at its threshold and the shooting candidates then also "
                             "win where M_phi's carry a body (10 seeds each; docs/benchmarks/held_goal_v35), so off "
                             "by default: try it on a body whose goal must be held and whose shooting labels carry it")
    rival_hold: Bool = Field(False, description="with rival_shoot on and shoot_hold off: the shooting labels' held-goal "
                             "version (shoot_hold's aim and path score, the same forward model) is one more candidate "
                             "each generation wherever the rows hold a goal the body reached and that stayed (none: "
                             "no candidate, no cost), judged like the others, so the run, not the user, decides "
                             "whether a goal to hold pays on this body; its episodes are not recorded (every model's "
                             "data as without it). A new user's crane: late reward +14.6 [-7.6, +38.2]; a quadrotor "
                             "10/10 in 0.92x (shoot_hold: 8/10); ReacherWay-v0 the default's runs; an attitude body "
                             "1.11x [1.00, 1.28]; a joint arm's late reward -3.4 [-6.6, -0.5] (10 seeds each; "
                             "docs/benchmarks/held_rival_v36), so off by default")
    shoot_keep_best: Bool = Field(True, description="with frame auto, the label probe also keeps the shooting "
                                  "rival where its simulated candidate, though not above zero action, has the best "
                                  "mean return of every simulated candidate (a body whose zero action is a safe "
                                  "policy, a hovering drone, drops every learned variant against it; "
                                  "docs/benchmarks/shoot_keep_best_v17)")
    shoot_unjudged: Bool = Field(True, description="with frame auto, where no simulated candidate of the label "
                                 "probe beats zero action (it cannot judge: a body whose zero action is a safe policy), "
                                 "the shooting rival runs anyway, its paths scored by their mean distance to the aim, "
                                 "at the probe's horizon and at the probed horizon nearest it (two rivals): the run's "
                                 "selection judges them (docs/benchmarks/shoot_unjudged_v18)")
    shoot_unjudged_all: Bool = Field(True, description="with shoot_unjudged, where the probe cannot judge, the "
                                     "shooting rival runs at three probed horizons (the chosen one, the one nearest "
                                     "it and the shortest other: 4, 8 and 16 of 4-32), not only the chosen one and the "
                                     "one nearest it (a new user's quadrotor needs 16 "
                                     "steps where the probe chose 4 or 8: 5/5 seeds solved against 0/5; "
                                     "docs/benchmarks/shoot_unjudged_all_v19); false: those two")
    shoot_cost: Literal[SHOOT_COSTS] = Field("min", description="the shooting labels score a held action's "
                                               "predicted path by its nearest pass to the aim (min) or its mean "
                                               "distance to it (mean: a new user's drone 6/10 solved against 3/10, "
                                               "the kart 1.42x and UR5Reach-v0 1.20x the generations; "
                                               "docs/benchmarks/shoot_keep_best_v17)")
    shoot_model: Literal[SHOOT_MODELS] = Field("chunk", description="the shooting labels' forward model: chunk (the "
                                               "h-step displacement from the state and the mean recorded action) or "
                                               "rollout (one step of the whole observation and the position, rolled "
                                               "out h steps with the action held: a body that is far from linear "
                                               "over h steps, a quadrotor tilting to move; shaping/forward_rollout.py)")
    shoot_frame: Literal[SHOOT_FRAMES] = Field(
        "auto", description="the frame the shooting labels' chunk model predicts paths in: world, or waypoint (x "
        "toward the waypoint; a body that observes itself only relative to itself, with no world heading in its "
        "state: a car's heading error and lidar, a trailer's goal in its own frame); auto: the label probe picks it by "
        "how well each frame's model predicts its held-out steps (the waypoint frame where the world frame's model "
        "explains nothing and the waypoint frame's does clearly better; world without a probe or with one "
        "coordinate; guides/probe_shoot_frame.py)")
    shoot_probe_horizons: tuple[Annotated[Int, Field(ge=1, le=64)], ...] = Field(
        (8, 16, 32), description="with frame auto, the label probe also simulates the shooting labels' candidate at "
        "these horizons and the run takes the one whose candidate beats shoot_horizon's clearly (signed-rank, as "
        "the frame's choice): a body whose action shows in its position only after many steps (a drone's tilt "
        "rate) needs a longer look, a sliding hovercraft 32 steps (10 seeds: 24.1 generations against 29.9 with "
        "(8, 16); docs/benchmarks/probe_horizon32_v20); (): shoot_horizon only")
    probe_chunk: Int = Field(
        4, ge=0, le=64, description="with frame auto and targets one_step, the label probe also trains M_phi on "
        "chunk targets of this many steps (p_{t+k} - p_t labelled with the mean action over them) and simulates "
        "each frame's and query_clip's candidate with them; the run takes them where such a candidate clearly "
        "beats the default's (signed-rank, as the frame's choice), is the best the probe simulated, and the "
        "one-step labels do not drive the body better than its labels: a body whose action shows in its position "
        "only a step later (a differential drive's turn rate) has no one-step label for it "
        "(docs/benchmarks/probe_chunk_v15); 0: one-step targets only")
    probe_keep: Int = Field(
        0, ge=0, le=64, description="with frame auto, the label probe's simulated candidates go on past their first "
        "DAgger round only for this many variants with the best mean return, and the default variant (successive "
        "halving; a variant cut there keeps its first round's returns); 0: every variant runs every round. Measured "
        "at 6: 0.72-0.75x the probe's env steps, but its choices changed on 35 of 100 probes (UR5Reach-v0 10 of 10: "
        "a horizon whose clone returned -45 after one round returned 10 after three); docs/benchmarks/"
        "probe_horizon32_v20")
    probe_clip_long: Float | None = Field(
        4.0, gt=0, description="with frame auto and no query_clip set, the label probe also tries every variant "
        "with the query clipped to this many times the mean training step (a third clip beside none and "
        "2, or 1 where M_phi sees each step's change; its simulated candidates have seed streams of their own); "
        "the run takes such a variant where it wins the frame's choice, the labels chosen without it do not drive "
        "the body better, and its own labels drive the body better than zero action (a torque arm's labels do not: "
        "a longer query there only asks them for a larger wrong move). docs/benchmarks/probe_clip_long_v16; null: "
        "clips none and 2 (or 1) only")
    shoot_long_nearest: Bool = Field(
        True, description="where the label probe can judge and chose the longest probed horizon (32), the probed "
        "horizon nearest it (16) runs beside it as a second shooting rival (variant 4): a long hold's early jump can "
        "land where shorter labels win. The 21 runs it alters: 267 generations to the threshold against 279 (faster "
        "on 9, slower on 3; a lander seed ending at 6.8 against -1.6; UR5Reach-v0's seed 6 16 against 12); "
        "docs/benchmarks/probe_horizon32_v20")
    shoot_keep_base: bool = Field(
        False, description="where the label probe chose a longer shooting horizon and shoot_horizon's simulated "
        "candidate also beat zero action, the shooting labels at shoot_horizon run beside it as one more rival "
        "(the run's selection judges both). Off: measured on the 15 seeds where it runs, no faster, one more "
        "clone a generation (docs/benchmarks/shoot_horizon_v8)")
    servo_gain: Float = Field(1.0, gt=0, description="the servo's gain k (its error in units of the median "
                              "query distance q, its action direction of unit norm)")
    servo_damping: Float = Field(3.0, ge=0, description="the servo's damping c: the predicted no-action step "
                                 "f(s, 0) (the body's velocity) taken from the waypoint error")
    query_clip: Float | None = Field(None, gt=0, description="clip |waypoint - position| to this many "
                                     "times the mean training step (the mean length of the displacements M_phi "
                                     "has trained on, a running mean over the run; None: raw, as the paper; "
                                     "with frame auto the label probe chooses; where M_phi sees each step's "
                                     "change it clips to 1 unless the query as asked clearly pays)")
    targets: Literal["one_step", "hindsight", "matched", "chunk"] = Field(
        _MPHI.targets, description="training displacements: p_{t+1} - p_t (paper), p_{t+h} - p_t with h ~ "
        "U{1..horizon} (hindsight relabelling), or the smallest h <= horizon reaching the state's query "
        "distance |w_t - p_t| (matched), or p_{t+horizon} - p_t labelled with the mean action over those steps "
        "(chunk: for torque-driven bodies)")
    horizon: Int = Field(_MPHI.horizon, ge=1, le=1000,
                         description="hindsight/matched: at most this many steps ahead; chunk: its length")
    query_scale: Literal["raw", "own_step"] = Field(
        _MPHI.query_scale, description="label queries: w_t - p_t (paper), or its direction at the length of "
        "the step the agent took from s_t (own_step: inside M_phi's one-step data; the label corrects the "
        "heading)")
    query_mix: Float = Field(_MPHI.query_mix, gt=0, le=1, description="label queries: (1 - mix) x the last step "
                             "p_t - p_{t-1} + mix x (w_t - p_t), the current motion turned toward the waypoint "
                             "(1: w_t - p_t, the paper)")
    babble: Int = Field(16, ge=0, le=10_000, description="motor babbling (labels=mphi only: M_phi's data): this many random "
                        "policies (weights ~ N(0, babble_sigma^2)) roll out beside the population in the "
                        "first babble_generations generations, until the label budget first sleeps "
                        "(shaping.backoff_after); their steps are M_phi's data (and the "
                        "clone's states), their returns steer no ES step and they are never tested)")
    babble_generations: Int = Field(20, ge=0, description="generations with babbling policies")
    babble_sigma: Float = Field(1.0, gt=0, description="standard deviation of the babbling policies' weights")
    filter: Literal["total", "positive", "none"] = Field(
        _MPHI.filter, description="which episodes' steps M_phi trains on: all (none: any step is dynamics "
        "data; an env whose rewards are never positive trains too), those whose positive (waypoint) part of "
        "the return reaches min_return (positive, the paper's words: 'a cumulative positive reward of 5'; "
        "what made the paper's mechanism work, docs/paper-construction.md), or the whole return (total)")

    @model_validator(mode="after")
    def _shoot_frame(self):
        if self.shoot_frame == "waypoint" and self.shoot_model == "rollout":
            raise ValueError("shoot_frame waypoint needs shoot_model chunk (the rollout model predicts in the world "
                             "frame only)")
        if self.step_change is True and self.frame in ("motion", "waypoint"):
            raise ValueError(f"step_change true needs frame world, both or auto (its change block is the world "
                             f"displacement's; frame {self.frame} has none)")
        return self


class CloningSettings(_Strict):
    steps: Int = Field(_CLONE.steps, ge=0,
                       description="behaviour-cloning gradient steps per member per generation")
    lr: Float = Field(_CLONE.lr, gt=0, description="cloning step size")
    batch_size: Int = Field(_CLONE.batch_size, description="samples per member per step (<= 0: all)")
    optimizer: Literal["adam", "sgd"] = Field(_CLONE.optimizer, description="cloning optimizer")
    max_samples: Int = Field(_CLONE.max_samples, description="newest samples of D_i used (<= 0: all)")


class MeanCloneSettings(_Strict):
    steps: Int = Field(_MEAN.steps, ge=0, description="Adam steps of the mean's clone per generation")
    lr: Float = Field(_MEAN.lr, gt=0, description="its step size")
    batch_size: Int = Field(_MEAN.batch_size, gt=0, description="rows per step, from the recent recorded steps")
    max_samples: Int = Field(_MEAN.max_samples, description="newest rows of the last `history` generations "
                             "used (<= 0: all)")
    record_every: Int = Field(_MEAN.record_every, ge=1, description="the rollouts keep the steps of every k-th "
                              "member (and of every candidate): the clone's states and M_phi's data")
    noise: Float = Field(_MEAN.noise, ge=0, le=100, description="> 0: the clone is fitted under the search's own "
                         "parameter noise from generation noise_from on: each Adam step's gradient is taken at theta + "
                         "noise * es.sigma * z, z near N(0, I), so it fits where the population will be sampled, not only "
                         "at its centre (a plain clone can sit where the return is sharp: UR5Reach-v0's late population "
                         "scored 0.4 against its mean's 43). 1 from generation 15: UR5Reach-v0's late reward +6.5 over "
                         "20 seeds (seeds 0-9 and 200-209), the same generations to the threshold on 7 of 9 suite tasks "
                         "on seeds 0-9 (the Reacher and the kart 1.05x) and 8 of 9 on 200-209 (the Reacher 1.06x); 0: a "
                         "plain fit. With shaped_cmaes the unit is CMA-ES's adapted step (the root mean square of its "
                         "per-coordinate standard deviations after each tell), not es.sigma, its initial one "
                         "(docs/benchmarks/noise_from_v29)")
    noise_from: Int = Field(_MEAN.noise_from, ge=0, description="the noise applies to the clones made from this "
                            "generation on (0-based, as metrics.csv counts); before it the fit is plain: the early "
                            "jumps, whose size gives the speed (noise from generation 0 took 1.3-1.9x the generations "
                            "on CarNav-v0 and UR5Reach-v0)")
    noise_ramp: Int = Field(_MEAN.noise_ramp, ge=0, description="> 0: the noise grows linearly from noise_from "
                            "over this many generations (the k-th noisy clone gets min(1, k / noise_ramp) of it); 0: "
                            "all of it from noise_from on (10 stretched UR5Reach-v0's dip after the switch and ended "
                            "lower: docs/benchmarks/noise_shape_v30)")
    scales: tuple[Float, ...] = Field(_MEAN.scales, min_length=1, description="candidate: mu + s (theta* - mu) "
                                      "is evaluated for each scale s, a positive number (e.g. [0.5, 1.0])")
    accept: Literal[tuple(ACCEPT_RULES)] = Field(
        _MEAN.accept, description="candidate: it becomes the mean if its return beats every member's (best), "
        "the mean's own on the same episodes (mean), the mean's by more than one standard error of the "
        "paired differences over the common and extra episodes (paired), or best and paired together")
    accept_margin: Float = Field(_MEAN.accept_margin, ge=0, le=100, description="candidate, accept paired or "
                                 "best_paired: the candidate's mean paired difference to the mean must exceed this "
                                 "many standard errors of it")
    accept_fresh: Bool = Field(_MEAN.accept_fresh, description="candidate, accept paired: the paired test runs on "
                               "the extra episodes only (the best candidate was picked on the common ones)")
    pick_all: Bool = Field(_MEAN.pick_all, description="candidate: the candidate the acceptance test judges is the "
                           "one with the best mean return over every episode the candidates ran (the common and "
                           "extra ones), not over the common ones alone (two episodes: a lucky candidate there can "
                           "be tested in place of one that would pass). Measured on the suite and five held-out bodies "
                           "(10 seeds each): no clear change either way (ReacherWay-v0 10/10 against 9/10, a new "
                           "user's plate 2/10 against 3/10; docs/benchmarks/held_rival_v36), so off")
    accept_flat: Bool = Field(_MEAN.accept_flat, description="candidate: where every member of the population "
                              "returned the same (the ES step has no signal: a plateau, a sparse reward nobody met "
                              "yet), a candidate whose mean gain over the mean on the paired episodes is positive wins")
    warm_start: Bool = Field(_MEAN.warm_start, description="the clone starts from the previous generation's "
                             "clone (a DAgger learner kept across generations) instead of the mean")
    extra_episodes: Int = Field(_MEAN.extra_episodes, ge=0, le=1000, description="candidate: the candidates "
                                "and the mean also run this many more episodes (none of the population's), on "
                                "which a winner must beat the mean too")
    keep_step: Bool = Field(_MEAN.keep_step, description="candidate: an accepted candidate also takes the ES "
                            "update it replaces (the new mean is c_g + (mu_{g+1} - mu_g)): a candidate judged "
                            "against the old mean does not undo the ES step")
    reset_momentum: Bool = Field(_MEAN.reset_momentum, description="candidate: an accepted jump also resets "
                                 "the ES optimizer's momentum (Adam's first moment), which holds gradients "
                                 "estimated around the old mean")
    keep_step_repeat: Bool = Field(_MEAN.keep_step_repeat, description="candidate: keep_step also on a jump "
                                   "right after a jump (false: the second jump in a row lands on the candidate "
                                   "itself, so the search restarts around it instead of cycling)")
    revert_margin: Float = Field(_MEAN.revert_margin, ge=0, le=100, description="candidate: > 0: an accepted "
                                 "jump is undone (the mean goes back to where the ES step alone took it) when the "
                                 "next population, sampled around the jump, has a mean return below the one "
                                 "before the jump by more than this many standard errors of the difference; the "
                                 "undone jump counts as a lost judgement for the back-off (0: never undone)")
    revert_paired: Float = Field(_MEAN.revert_paired, ge=0, le=100, description="candidate: > 0: after an "
                                 "accepted jump, the mean the ES step alone gave (what the jump replaced) runs "
                                 "beside the next generation on its episodes, and the jump is undone (the mean goes "
                                 "back to it) if it beats the jumped mean by more than this many standard errors of "
                                 "the paired differences: a candidate is judged against the old mean but replaces "
                                 "the new one; the undone jump counts as a lost judgement (0: no such row)")
    check_episodes: Int = Field(_MEAN.check_episodes, ge=0, le=1000, description="candidate: a winner and the "
                                "mean run this many more episodes at once (on winning generations only) and the "
                                "jump needs the paired test again on every episode the winner was not picked on "
                                "(the extra ones and these): the best of several candidates on two episodes is a "
                                "winner's curse (0: no check; a plateau's accept_flat win is not checked)")
    confirm: Bool = Field(_MEAN.confirm, description="candidate: a winner is evaluated again beside the next "
                          "generation, on new episodes, and becomes the mean only if it beats the mean's "
                          "return there")
    probe_candidate: Bool = Field(_MEAN.probe_candidate, description="candidate: the label probe's best simulated "
                                  "candidate (the initial mean cloned toward a variant's labels) is judged beside "
                                  "generation 0 by the same rule, and is the mean from then on if it wins; a loss "
                                  "there does not count against the labels (frame: auto only)")

    @model_validator(mode="after")
    def _positive(self):
        if any(not s > 0 for s in self.scales):
            raise ValueError("scales must be positive")
        return self


class ShapingConfig(_Strict):
    labels: Literal[LABEL_SOURCES] = Field(
        "mphi", description="where action labels come from: M_phi, the learned inverse-dynamics model (the "
        "paper); reference, a finished run's policy (shaping.reference_run); controller, the env's scripted "
        "waypoint controller (the oracle: what perfect labels give through the same candidate, without the probe's "
        "candidate or the rivals)")
    mechanism: Literal[tuple(MECHANISMS)] = Field(
        "candidate", description="how labels become search: paper (every member cloned, Delta = (theta* - "
        "mu)/eta spans Guided ES's subspace), candidate (the mean's clone is evaluated beside the "
        "population and becomes the mean when it beats every member), pair (the mean's clone as the "
        "direction of one antithetic pair); guides/mechanisms/")
    eta: Float = Field(0.01, ge=1e-12, description="surrogate normalization eta (paper 0.01)")
    surrogate: Literal["paper", "clone_orth"] = Field(
        "paper", description="mechanism paper: Delta = (theta* - mu_{g+1})/eta (paper), or each clone step "
        "theta* - theta minus its part in the span of the generation's perturbations (what the labels add)")
    history: Int = Field(5, gt=0, description="generations of a slot's data aggregated into D_i")
    early_mphi: Bool = Field(False, description="M_phi and the rival models train on generation 0's steps before "
                             "its clone, so generation 1 judges a candidate (otherwise the run's own first is "
                             "generation 2's: M_phi trains beside a generation's rollouts on the previous one's "
                             "steps); generation 1 then trains none (docs/benchmarks/early_mphi_v24)")
    placement: Literal["auto", "master", "workers"] = Field(
        "auto", description="where labels and cloning run: the master, in one batched computation on "
        "the data the rollouts send back (one machine), or the workers, on data read from the trajectory "
        "store (cluster); auto = master for inline/process executors and P x n <= 20M")
    trajectory_root: str | None = Field(
        None, description="where workers write trajectory shards: a path every node sees, or a URI "
        "pyarrow understands (s3://...); None: RUN_DIR/trajectories")
    reference_run: str | None = Field(
        None, description="a finished run of the same env whose best policy stands for the paper's "
        "'fully trained policy': logs the Fig. 5 test loss (labels vs its actions) and related label "
        "metrics each generation (master placement); the label source with labels=reference")
    diagnose_returns: Bool = Field(
        False, description="also roll out every theta* on the generation's episode seeds and log the "
        "return change cloning made (costs one more population rollout; diagnostics only)")
    backoff_after: Int = Field(
        8, ge=0, le=100_000, description="candidate: after this many judged generations in a row without an "
        "accepted candidate, shaping sleeps (no recording, M_phi, clone or candidate: a Vanilla-ES "
        "generation), first for 4 generations, then twice as long each time its labels lose again, waking "
        "to try; an acceptance resets it (guides/label_budget.py); 0: never back off. 8 against 5 on the "
        "suite: the Reacher 8/10 solved against 7/10, the unicycle and UR5Reach-v0 faster, 3 more awake "
        "generations where labels never pay (docs/benchmarks/backoff_patience_v9)")
    backoff_max: Int = Field(32, ge=0, le=100_000, description="the longest sleep, in generations")
    backoff_keep_rate: Float = Field(
        0.0, ge=0, le=1, description="candidate: while at least this share of the run's judged generations "
        "(and 2) accepted a candidate, a losing wake-up trial sleeps as long as the last sleep instead of twice "
        "as long (guides/label_budget.py); 0: always double. 0.2 was measured on the suite and 4 held-out "
        "bodies: about the same generations to the threshold, 5-43% more awake ones (docs/benchmarks/"
        "backoff_keep_v9)")
    backoff_heavy: Float = Field(
        1.0, ge=0, le=1e6, description="candidate: a run whose labels have never won sleeps before "
        "backoff_after once at least 3 judged generations in a row lost by a median of more than this many times "
        "the population's spread of returns (best member's minus worst's): candidates typically worse than "
        "everything the search sampled (guides/label_budget.py), for twice the first sleep; 0: off. A replay of the "
        "committed suite and held-out runs finds it changes only the swimmer's never-paying runs "
        "(docs/benchmarks/backoff_heavy_v13)")
    backoff_judges_jumps: Bool = Field(False, description="candidate: an accepted candidate after which the "
                                       "next population's mean return falls below the one before the jump counts "
                                       "as a lost judgement for the back-off (guides/label_budget.py)")
    inverse_dynamics: InverseDynamicsSettings = Field(default_factory=InverseDynamicsSettings)
    cloning: CloningSettings = Field(default_factory=CloningSettings)
    mean_clone: MeanCloneSettings = Field(default_factory=MeanCloneSettings)

"""Rival label variants: models trained on the same recorded steps as the run's ``M_phi``, whose labels
make more candidates each generation; selection keeps whichever pays on this body.

- ``shaping.inverse_dynamics.rival_frame`` (variant 1): a second ``M_phi`` in another frame;
- ``shaping.inverse_dynamics.rival_servo`` (variant 2): a learned forward model's damped servo
  (``shaping/forward_servo.py``), the labels a torque-driven arm's inverse dynamics cannot give;
- ``shaping.inverse_dynamics.rival_shoot`` (variant 3): a learned model of a few steps with an action held,
  and the held action whose path passes nearest the waypoint (``shaping/forward_shoot.py``), the labels of
  bodies whose action shows in the position only after a few steps (a car steered by its wheel's rate);
- ``shaping.inverse_dynamics.shoot_keep_base`` (variant 4, off by default): where the label probe chose a
  longer horizon than ``shoot_horizon`` and the ``shoot_horizon`` one's candidate also beat zero action, the
  shooting labels at ``shoot_horizon`` too, so the run's selection judges both (the probe judges the first
  generations' data only). Measured on the 15 seeds where it would run: no faster, at one more clone a
  generation (``docs/benchmarks/shoot_horizon_v8``);
- ``shaping.inverse_dynamics.rival_hold`` (variant 8): the shooting labels' held-goal version (``shoot_hold``'s
  aim and path score) on the shooting rival's own model (no model of its own: :attr:`Rival.shares`), a candidate
  only in generations whose rows hold a goal the body reached and that stayed (:meth:`Rival.idle`): the run
  judges whether aiming at a goal to hold pays, where ``shoot_hold`` decides it for the whole run. Its episodes
  are not recorded (:attr:`Rival.records`): recorded, they trained every model and moved seeds either way where it
  never won (ReacherWay-v0 8/10 against 9/10; unrecorded, the default's runs: ``docs/benchmarks/held_rival_v36``).

Which displacement frame makes M_phi's labels pay depends on the body, and the label probe before
generation 0 (``label_probe.py``) cannot always tell: forced by hand, the waypoint frame solves
Unicycle-v0 in 6.8 generations where the default (``both``) takes 14.9, yet it is never accepted on the
points or the car (``docs/benchmarks/frames_waypoint``), and the probe's simulated candidate chose it on
1 of 10 unicycle seeds. So instead of choosing before the run, the run keeps both: the mechanism
``candidate`` (``mechanisms/candidate.py``) clones the mean toward each model's labels and evaluates both
clones beside the population; selection (the same acceptance rule) takes whichever wins, generation by
generation. Cost: a second M_phi's training steps (in the shaping thread, beside the rollouts), a second
clone of the mean, and one more candidate's episodes.

The rival frame's model has no query clip (the probe's clip is the primary's). Each rival has its own
data parts (``RUN/mphi_data_rival``, ``RUN/mphi_data_servo``, ``RUN/mphi_data_shoot``) and checkpoint keys, so a resumed run
rebuilds it exactly as the primary's. The servo costs like the frame rival (a model's training steps in
the shaping thread, a clone, a candidate's episodes); it is on wherever M_phi's labels and the candidate
mechanism are, in any waypoint dimension.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from shaped_es import seeding
from shaped_es.guides.mphi_track import MphiTrack
from shaped_es.shaping.forward_servo import ServoLabels, servo_model
from shaped_es.shaping.forward_shoot import ShootLabels, shoot_model
from shaped_es.shaping.inverse_dynamics import InverseDynamics
from shaped_es.shaping.labels import MphiLabels

RIVAL_KEY = 1_000_021  # seed key of the rival frame's model (its init and minibatches)
SERVO_KEY = 1_000_022  # seed key of the servo's forward model
SHOOT_KEY = 1_000_024  # seed key of the shooting labels' forward model
SHOOT_BASE_KEY = 1_000_026  # seed key of the shooting labels' model at shoot_horizon beside a longer one
SHOOT_THIRD_KEY = 1_000_027  # seed key of the shooting labels' model at the third probed horizon (unjudged, all)
DIR = "mphi_data_rival"
SERVO_DIR = "mphi_data_servo"
SHOOT_DIR = "mphi_data_shoot"
SHOOT_BASE_DIR = "mphi_data_shoot_base"
SHOOT_THIRD_DIR = "mphi_data_shoot_third"
FRAME, SERVO, SHOOT, SHOOT_BASE = 1, 2, 3, 4  # variant ids: the candidate_rival column's values (0: own labels;
#                                              5: generation 0's probe candidate, mechanisms/candidate.PROBE)
SHOOT_THIRD = 6  # the shooting labels at the third probed horizon (shoot_unjudged_all)
SHOOT_HOLD = 8  # the shooting labels' held-goal version on the shooting rival's model (rival_hold; 7 was a fourth
#                 horizon's in the runs of commit 2dd35906, measured and removed)


@dataclass
class Rival:
    """One rival label variant: its id, name, model track and checkpoint keys."""

    variant: int  # FRAME, SERVO, SHOOT, SHOOT_BASE, SHOOT_THIRD or SHOOT_HOLD
    name: str  # for the run's lines: "waypoint frame", "servo", "shooting"
    track: MphiTrack
    prefix: str  # checkpoint keys of its model
    parts_key: str  # checkpoint key of its data parts
    own_labels: object = None  # labels of its own on another rival's track (SHOOT_HOLD); None: the track's
    # its candidate's episodes are recorded as every candidate's are (data for M_phi and every rival); False: not
    # (SHOOT_HOLD: an option's candidate leaves every model's data as without it, docs/benchmarks/held_rival_v36)
    records: bool = True

    @property
    def ready(self) -> bool:
        return self.track.ready

    @property
    def shares(self) -> bool:
        """The track is another rival's (it has labels of its own on it): that one adds its data, trains and
        checkpoints it."""
        return self.own_labels is not None

    @property
    def labels(self):
        return self.track.labels if self.own_labels is None else self.own_labels

    def idle(self, rows) -> bool:
        """Whether its labels on ``rows`` (``MemberRows``) would be another rival's: the held-goal version where no
        row holds a goal (its flag column all 0), whose clone would be the shooting rival's over again."""
        return self.variant == SHOOT_HOLD and not any(len(q) and bool((q[:, -1] > 0.5).any()) for q in rows.queries)


def rival_frame(cfg, frame: str, pos_dim: int) -> str | None:
    """The rival's frame for this run, or None: only with M_phi's labels and the candidate mechanism, a
    waypoint space of at least 2 dimensions, and a frame other than the run's own."""
    sh = cfg.shaping
    want = sh.inverse_dynamics.rival_frame
    if want == "none" or want == frame or pos_dim < 2 or sh.labels != "mphi" or sh.mechanism != "candidate":
        return None
    return want


def rival_track(obs_dim: int, pos_dim: int, act_dim: int, mphi_cfg, frame: str, root: Path,
                seed: int) -> MphiTrack:
    """The rival model in ``frame`` (M_phi's other settings as the run's, its own seed), its labels (no
    query clip) and its data parts under ``root / DIR``."""
    cfg = dataclasses.replace(mphi_cfg, frame=frame, seed=seeding.derive_seed(seed, seeding.SHAPING, RIVAL_KEY))
    mphi = InverseDynamics(obs_dim, pos_dim, act_dim, cfg)
    return MphiTrack(mphi, MphiLabels(mphi, frame, cfg.query_scale, cfg.query_mix), Path(root) / DIR)


def servo_on(cfg) -> bool:
    """Whether this run keeps the servo rival: M_phi's labels with the candidate mechanism."""
    sh = cfg.shaping
    return bool(sh.inverse_dynamics.rival_servo) and sh.labels == "mphi" and sh.mechanism == "candidate"


def servo_track(obs_dim: int, pos_dim: int, act_dim: int, mphi_cfg, root: Path, seed: int) -> MphiTrack:
    """The servo's forward model (M_phi's training settings, its own seed), labels and data parts."""
    model = servo_model(obs_dim, pos_dim, act_dim, mphi_cfg, seeding.derive_seed(seed, seeding.SHAPING, SERVO_KEY))
    return MphiTrack(model, ServoLabels(model), Path(root) / SERVO_DIR)


def shoot_on(cfg) -> bool:
    """Whether this run keeps the shooting rival: M_phi's labels with the candidate mechanism."""
    sh = cfg.shaping
    return bool(sh.inverse_dynamics.rival_shoot) and sh.labels == "mphi" and sh.mechanism == "candidate"


def shoot_track(obs_dim: int, pos_dim: int, act_dim: int, mphi_cfg, horizon: int, root: Path,
                seed: int, key: int = SHOOT_KEY, folder: str = SHOOT_DIR, ahead: float = 0.0,
                cost: str = "min", kind: str = "chunk", frame: str = "world", hold: bool = False) -> MphiTrack:
    """The shooting labels' forward model (M_phi's training settings, its own seed; ``kind``, ``frame``:
    ``shoot_model``'s), labels and data parts."""
    model = shoot_model(obs_dim, pos_dim, act_dim, mphi_cfg, horizon,
                        seed=seeding.derive_seed(seed, seeding.SHAPING, key), kind=kind, frame=frame)
    return MphiTrack(model, ShootLabels(model, ahead, cost, hold), Path(root) / folder)


def probe_shooting(res, mp) -> dict:
    """The shooting rivals the label probe's result ``res`` (``label_probe.ProbeResult``) gives a run whose
    ``shaping.inverse_dynamics`` settings are ``mp``: :func:`rivals`' keyword arguments (``check-env --labels``
    names the horizons from them too)."""
    return {"shoot": res.shoot_on, "shoot_horizon": res.shoot_horizon, "shoot_base": res.keeps_base(),
            "unjudged": res.unjudged_shooting() if mp.shoot_unjudged else None,  # the probe could not judge
            "third": res.third_horizon() if mp.shoot_unjudged and mp.shoot_unjudged_all else None,
            "beside": res.long_nearest() if mp.shoot_long_nearest else None,
            "shoot_frame": res.shoot_frame}


def rivals(cfg, frame: str, obs_dim: int, pos_dim: int, act_dim: int, mphi_cfg, root: Path,
           shoot: bool | None = None, shoot_horizon: int | None = None, shoot_base: bool = False,
           unjudged: tuple[int | None, str] | None = None, third: int | None = None,
           beside: int | None = None, shoot_frame: str | None = None) -> list[Rival]:
    """This run's rival label variants, in the order their candidates' rows take; ``shoot``: the label
    probe's verdict on the shooting rival (False: dropped; None: not probed, the config decides),
    ``shoot_horizon`` the horizon it chose (None: the config's), and ``shoot_base`` whether the config's
    horizon also runs beside a longer chosen one (its candidate beat zero action too); ``unjudged``: where
    the probe could not judge (``ProbeResult.unjudged_shooting``), the second horizon that runs beside the
    chosen one (variant 4; None: none) and the path score of both; ``third``: there, with ``shoot_unjudged_all``,
    the probed horizon neither of them holds (variant 6; ``ProbeResult.third_horizon``; None: none); ``beside``: where
    the probe could judge, a horizon that runs beside the chosen one (variant 4; ``ProbeResult.long_nearest``);
    ``shoot_frame``: the frame the probe chose for the shooting labels (None: not probed, the config's, auto being
    the world frame)."""
    out = []
    rf = rival_frame(cfg, frame, pos_dim)
    if rf is not None:
        out.append(Rival(FRAME, f"{rf} frame", rival_track(obs_dim, pos_dim, act_dim, mphi_cfg, rf, root, cfg.seed),
                         "rival/", "rival/parts"))
    if servo_on(cfg):
        mp = cfg.shaping.inverse_dynamics
        track = servo_track(obs_dim, pos_dim, act_dim, mphi_cfg, root, cfg.seed)
        track.labels.gain, track.labels.damping = float(mp.servo_gain), float(mp.servo_damping)
        out.append(Rival(SERVO, "servo", track, "servo/", "servo/parts"))
    if shoot_on(cfg) and shoot is not False:
        base = cfg.shaping.inverse_dynamics.shoot_horizon
        h = shoot_horizon or base
        both = shoot_base and h != base and cfg.shaping.inverse_dynamics.shoot_keep_base
        ahead = cfg.shaping.inverse_dynamics.shoot_ahead
        cost = cfg.shaping.inverse_dynamics.shoot_cost
        if unjudged is not None:  # the probe could not judge: a second horizon beside its choice, paths by their mean
            second, cost = unjudged
            both, base = second is not None, second
        elif beside is not None and beside != h and not both:  # shoot_long_nearest: the nearest beside a long one
            both, base = True, beside
        kind = cfg.shaping.inverse_dynamics.shoot_model
        configured = cfg.shaping.inverse_dynamics.shoot_frame
        sf = configured if configured != "auto" else (shoot_frame or "world")

        def track(horizon: int, key: int, folder: str) -> MphiTrack:
            return shoot_track(obs_dim, pos_dim, act_dim, mphi_cfg, horizon, root, cfg.seed, key, folder, ahead, cost,
                               kind, sf, cfg.shaping.inverse_dynamics.shoot_hold)
        out.append(Rival(SHOOT, shoot_name(h, cost, sf) if both else "shooting", track(h, SHOOT_KEY, SHOOT_DIR), "shoot/",
                         "shoot/parts"))
        if both:
            out.append(Rival(SHOOT_BASE, shoot_name(base, cost, sf), track(base, SHOOT_BASE_KEY, SHOOT_BASE_DIR),
                             "shoot_base/", "shoot_base/parts"))
        if unjudged is not None and third is not None:
            out.append(Rival(SHOOT_THIRD, shoot_name(third, cost, sf), track(third, SHOOT_THIRD_KEY, SHOOT_THIRD_DIR),
                             "shoot_third/", "shoot_third/parts"))
        if cfg.shaping.inverse_dynamics.rival_hold and not cfg.shaping.inverse_dynamics.shoot_hold:
            main = next(r for r in out if r.variant == SHOOT)
            held = ShootLabels(main.track.mphi, ahead, cost, hold=True)  # the same model, a goal to hold held
            out.append(Rival(SHOOT_HOLD, HOLD_NAME, main.track, "", "", own_labels=held, records=False))
    return out


def shoot_name(horizon: int, cost: str = "min", frame: str = "world") -> str:
    """A shooting rival's name with its horizon (and its path score where it is not the nearest pass, its frame
    where it is not the world's): ``shooting (8 steps)``, ``shooting (8 steps, mean distance, waypoint frame)``."""
    return (f"shooting ({horizon} steps{', mean distance' if cost == 'mean' else ''}"
            f"{', waypoint frame' if frame == 'waypoint' else ''})")


HOLD_NAME = "held-goal shooting"  # the held-goal rival's name in the run's lines


def names(rivals: list[Rival]) -> list[str]:
    """The rivals' names for the probe's line, the shooting labels' with their horizon: ``shooting (8 steps)``."""
    return [shoot_name(r.track.mphi.horizon, r.track.labels.cost, r.track.mphi.frame)
            if r.name == "shooting" else r.name for r in rivals]


def owned(rivals: list[Rival]) -> list[Rival]:
    """The rivals that own their track (add its data, train and checkpoint it): not :data:`SHOOT_HOLD`'s view."""
    return [r for r in rivals if not r.shares]

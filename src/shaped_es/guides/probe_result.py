"""What the label probe (``label_probe.py``) measured and chose, as a run keeps it (:class:`ProbeResult`; on disk:
``probe_file.py``): each variant's label-driven and simulated-candidate returns, zero action's, the shooting
labels', and the choices made from them, with what the run reads off them (which shooting horizons run beside the
chosen one, whether the probe could judge); and :func:`not_passed`, the names left once the passed-over
extensions are set aside."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from shaped_es.guides.probe_choice import beats, nearest_horizon, unjudged


@dataclass
class ProbeResult:
    """What the probe measured and chose; ``returns``: variant name -> per-episode returns."""

    frame: str
    query_clip: float | None
    returns: dict[str, list[float]]
    env_steps: int
    seconds: float
    reason: str
    zero_action: list[float] = field(default_factory=list)  # the middle action's returns, same episodes
    # variant name -> the simulated candidate's per-episode returns (guides/clone_probe.py), same episodes
    clones: dict[str, list[float]] = field(default_factory=dict)
    # the shooting labels' simulated candidate (shaping/forward_shoot.py), same episodes ([]: not probed),
    # and whether the run keeps the shooting rival (None: not probed, the config decides)
    shoot: list[float] = field(default_factory=list)
    shoot_on: bool | None = None
    # the horizon the shooting rival holds its actions for (None: not probed, the config's shoot_horizon), and
    # each horizon's simulated candidate where the probe tried several (shoot_probe_horizons)
    shoot_horizon: int | None = None
    shoot_tried: dict[str, list[float]] = field(default_factory=dict)
    # the simulated candidate with the best mean return, judged at generation 0 (guides/probe_candidate.py): a
    # variant's name, or "shoot:H" for the shooting labels holding actions H steps (None: a probe from before)
    candidate: str | None = None
    # its parameters (n,), kept in RUN/probe_candidate.FILE, not in the JSON (None: not at hand)
    candidate_params: np.ndarray | None = field(default=None, compare=False, repr=False)
    # M_phi's chunk length where the chosen variant trains on chunk targets (targets=chunk, horizon=chunk);
    # None: the configured targets (one-step; a probe from before probe_chunk)
    chunk: int | None = None
    # the probe's extensions passed over (the chosen variant lacks them: "+chunk", "+clip4"): their simulated
    # candidates neither keep nor drop the shooting rival nor count in :meth:`unjudged` ([]: a probe from before)
    passed: list[str] = field(default_factory=list)
    # es.obs_norm: the observation statistics of the probe's data, [count, mean (obs,), m2 (obs,)], which the run's
    # running statistics start from and its simulated candidates were fitted under (clone_probe.probe_stats;
    # None: off, or a probe from before)
    obs_stats: list | None = None
    # the shooting labels' frame (shaping.inverse_dynamics.shoot_frame auto: guides/probe_shoot_frame.py; None: a
    # probe from before, the world frame) and each frame's held-out error it was chosen by ({}: not compared)
    shoot_frame: str | None = None
    shoot_frame_errors: dict[str, float] = field(default_factory=dict)
    # M_phi's step_change (shaping.inverse_dynamics.step_change auto: guides/probe_step_change.py; None: a probe
    # from before, off) and the held-out action errors it was chosen by ({}: not compared)
    step_change: bool | None = None
    step_change_errors: dict[str, float] = field(default_factory=dict)

    def standing(self) -> dict[str, list[float]]:
        """The simulated candidates of the variants not passed over (``clones`` without :attr:`passed`'s)."""
        return not_passed(self.clones, self.passed)

    def keeps_base(self) -> bool:
        """Whether the shooting labels at the first probed horizon (``shoot_horizon``) also run, beside the
        longer one chosen: its simulated candidate beat zero action too (``guides/rival.py``, variant 4)."""
        base = next(iter(self.shoot_tried), None)
        return bool(self.shoot_on and base is not None and str(self.shoot_horizon) != base
                    and beats(np.array(self.shoot_tried[base]), np.array(self.zero_action))[0])

    def long_nearest(self) -> int | None:
        """Where the probe could judge and the shooting rival holds the longest probed horizon: the probed horizon
        nearest it (``shoot_long_nearest`` runs it beside); None otherwise."""
        tried = [int(h) for h in self.shoot_tried]
        if not (self.shoot_on and len(tried) > 1 and self.shoot_horizon == max(tried)) or self.unjudged():
            return None
        return nearest_horizon(self.shoot_horizon, tried)

    def unjudged(self) -> bool:
        """Whether no simulated candidate of a variant not passed over, nor of any shooting horizon, beat zero action
        (``probe_choice.unjudged``): the probe could not judge."""
        sims = {**self.standing(), **self.shoot_tried, **({"shoot": self.shoot} if self.shoot else {})}
        return bool(self.zero_action) and unjudged(np.array(self.zero_action), {k: np.array(v) for k, v in sims.items()})

    def unjudged_shooting(self) -> tuple[int | None, str] | None:
        """Where the shooting rival runs and the probe could not judge (:meth:`unjudged`): ``(second horizon, path
        score)``, the probed horizon nearest the chosen one (None: one probed) and the mean distance; else None."""
        if not (self.shoot_on and self.unjudged()):
            return None
        return nearest_horizon(self.shoot_horizon, [int(h) for h in self.shoot_tried]), "mean"

    def third_horizon(self) -> int | None:
        """Where the probe could not judge: the shortest probed horizon neither the chosen one nor the second holds
        (None: fewer than three probed, or the probe could judge). The shortest: a probe that cannot judge has no
        evidence for a long hold, and a 32-step rival's early jumps took a quadrotor and UR5Reach-v0 into poor
        neighbourhoods (``docs/benchmarks/probe_horizon32_v20``)."""
        two = self.unjudged_shooting()
        if two is None:
            return None
        return min((int(h) for h in self.shoot_tried if int(h) not in (self.shoot_horizon, two[0])), default=None)


def not_passed(named: dict, passed: list[str]) -> dict:
    """``named`` (variant or candidate name -> anything) without the names carrying a passed-over extension
    (``passed``: ``+chunk``, ``+clip4``)."""
    return {k: v for k, v in named.items() if not any(t in k for t in passed)}

"""Where the shaped method's action labels come from (``shaping.labels``): one choice, independent of how
labels become search (``shaping.mechanism``, ``guides/mechanisms/``).

========================  ===================================================================  ==========
source                    label of a state ``s_t`` visited by a rollout                        input kept
========================  ===================================================================  ==========
``mphi`` (the paper)      ``a_hat = M_phi(s_t, w_t - p_t)``: the learned inverse-dynamics       ``(T, d)``
                          model asked for the displacement to the next local waypoint           queries
``reference``             the action of a finished run's policy (the paper's "fully trained     ``(T, 0)``
                          policy", ``shaping.reference_run``)
``controller``            the env's scripted waypoint controller's action, asked during the     ``(T, act)``
                          rollout (``envs/core.py``'s optional ``waypoint_controller`` hook)
========================  ===================================================================  ==========

``reference`` and ``controller`` are oracles: they measure what a label-using mechanism can gain at most,
so every mechanism is judged with them first, then with ``mphi``'s learned labels. Each source says what
it keeps per row besides the state (:meth:`LabelSource.inputs`, stored with a generation's states) and
labels ``(states, inputs) -> actions`` in the policy's ``[-1, 1]`` scale.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from shaped_es.data import Transitions
from shaped_es.shaping.inverse_dynamics import InverseDynamics
from shaped_es.shaping.mphi_inputs import query_inputs

LABEL_SOURCES = ("mphi", "reference", "controller")


class LabelSource:
    """``inputs(transitions) -> (T, k)`` kept per row; ``self(states, inputs) -> (..., act)`` labels."""

    name = ""
    records_expert = False  # the rollouts must record the env controller's action (Transitions.expert)

    @property
    def ready(self) -> bool:
        """Whether labels can be taken now (M_phi: once it has trained)."""
        return True

    def inputs(self, tr: Transitions) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def __call__(self, states: np.ndarray, inputs: np.ndarray) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError


class MphiLabels(LabelSource):
    """The paper's labels: ``M_phi(s_t, q_t)`` with ``q_t`` the query displacement
    (``query_displacement``: ``w_t - p_t`` in M_phi's frame, or at the agent's own pace), each clipped to
    ``max_displacement`` (``shaping.inverse_dynamics.query_clip``; None: as asked)."""

    name = "mphi"

    def __init__(self, mphi: InverseDynamics, frame: str, query_scale: str = "raw", query_mix: float = 1.0):
        self.mphi, self.frame, self.query_scale, self.query_mix = mphi, frame, query_scale, query_mix
        self.max_displacement: float | None = None  # set by the guide from the training displacements

    @property
    def ready(self) -> bool:
        return self.mphi.iterations > 0

    @property
    def last_width(self) -> int:
        """Columns of the last step kept after the query (M_phi's ``step_change``; 0: none)."""
        return self.mphi.pos_dim if self.mphi.step_change else 0

    def inputs(self, tr: Transitions) -> np.ndarray:
        return query_inputs(tr, self.frame, self.query_scale, self.query_mix, self.mphi.step_change)  # (T, d [+ d])

    def __call__(self, states: np.ndarray, inputs: np.ndarray) -> np.ndarray:
        return self.mphi.ask(states, inputs, self.max_displacement)


class ReferenceLabels(LabelSource):
    """A finished run's policy: ``policy(states (..., obs)) -> (..., act)`` in ``[-1, 1]``."""

    name = "reference"

    def __init__(self, policy: Callable[[np.ndarray], np.ndarray]):
        self.policy = policy

    def inputs(self, tr: Transitions) -> np.ndarray:
        return np.zeros((len(tr), 0), np.float32)  # (T, 0): the state is all it reads

    def __call__(self, states: np.ndarray, inputs: np.ndarray) -> np.ndarray:
        return np.asarray(self.policy(states), np.float32)


class ControllerLabels(LabelSource):
    """The env's scripted waypoint controller: its actions, recorded by the rollouts on the visited
    states (``Transitions.expert``), are the labels."""

    name = "controller"
    records_expert = True

    def inputs(self, tr: Transitions) -> np.ndarray:
        if tr.expert is None:
            raise ValueError("transitions carry no controller actions (the rollouts did not record them)")
        return np.asarray(tr.expert, np.float32)  # (T, act)

    def __call__(self, states: np.ndarray, inputs: np.ndarray) -> np.ndarray:
        return np.asarray(inputs, np.float32)

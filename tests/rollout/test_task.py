"""rollout/task.py: where a rollout's error lines say it was."""

import numpy as np

from shaped_es.policies import MLPSpec
from shaped_es.rollout import RolloutTask, policy_episode_tasks


def _task(**kw) -> RolloutTask:
    return RolloutTask("Point-v0", {}, MLPSpec(2, 2, (4,)), np.zeros((1, 34), np.float32), np.zeros(1, int),
                       np.zeros((1, 2), np.int64), **kw)


def test_error_lines_count_generations_from_1_as_the_progress_line():
    """A new user's error said "generation 1" where the progress line had said "gen 2": metrics.csv's row
    generation 1 is generation 2 on every line a user reads."""
    assert _task(generation=0).where() == "generation 1"
    assert _task(generation=1).where() == "generation 2"
    assert _task(generation=1, during="the label probe, before generation 1").where() == \
        "the label probe, before generation 1"


def test_policy_episode_tasks_carry_what_they_are_part_of():
    tasks = policy_episode_tasks("Point-v0", {}, MLPSpec(2, 2, (4,)), np.zeros(34, np.float32), np.arange(4), 2,
                                 during="evaluate, the best policy")
    assert len(tasks) == 2 and all(t.where() == "evaluate, the best policy" for t in tasks)

# Exploration script (issue #27, session of 2026-12-03); run from the repo root: PYTHONPATH=src:docs/benchmarks/labels_offline python docs/benchmarks/labels_offline/<script>.py ENV ...
import sys
from probe import *
env_id = sys.argv[1]
env = gym.make(env_id)
spec = MLPSpec(env.observation_space.shape[0], env.action_space.shape[0])
for steps in (200,):
    print(env_id, "controller", steps, dagger(env_id, spec, None, "world", steps=steps, label=lambda s, q: q, expert=True), flush=True)

# Exploration script (issue #27, session of 2026-12-03); run from the repo root: PYTHONPATH=src:docs/benchmarks/labels_offline python docs/benchmarks/labels_offline/<script>.py ENV ...
import sys
from probe import *
env_id = sys.argv[1]; fr = sys.argv[2]
env = gym.make(env_id)
spec = MLPSpec(env.observation_space.shape[0], env.action_space.shape[0])
data = collect(env_id, spec)
m = train_mphi(spec, data, data[0][0].position.shape[1], frame=fr)
for mix in [float(x) for x in sys.argv[3].split(",")]:
    print(env_id, fr, mix, dagger(env_id, spec, m, fr, mix=mix, iters=10), flush=True)

# Exploration script (issue #27, session of 2026-12-03); run from the repo root: PYTHONPATH=src:docs/benchmarks/labels_offline python docs/benchmarks/labels_offline/<script>.py ENV ...
import sys
from probe import *
env_id = sys.argv[1]; G=int(sys.argv[2])
env = gym.make(env_id)
spec = MLPSpec(env.observation_space.shape[0], env.action_space.shape[0])
data = collect(env_id, spec, gens=G, pop=16)
pos_dim = data[0][0].position.shape[1]
res=[]
for fr in sys.argv[3].split(","):
    m = train_mphi(spec, data, pos_dim, frame=fr)
    x = m.newest(m.dataset_size)[0][:, spec.obs_dim:]; ms = float(np.linalg.norm(x, axis=1).mean())
    if fr == "both": ms /= np.sqrt(2)
    for qc in (None, 2.0):
        for k in (1.0, 0.5, 0.25):
            def lab(st, o, i, p, w, pr, c, k=k, qc=qc):
                u = w - p
                if qc is not None:
                    n = np.linalg.norm(u, axis=1, keepdims=True); u = u * np.minimum(1, qc * ms / np.maximum(n, 1e-12))
                u = (1 - k) * (p - pr) + k * u
                return m.label(o, make_query(fr, "raw")(o, p, p + u, pr))
            r = closed_loop(env_id, lab, episodes=20)
            res.append((fr, qc, k, round(r[0], 2)))
print(env_id, G, res)

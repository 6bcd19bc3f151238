import sys; sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1] / "labels_offline"))
import numpy as np, gymnasium as gym, time
from probe import collect, closed_loop
from shaped_es.policies import MLPSpec
from shaped_es.shaping.settings import InverseDynamicsConfig
from shaped_es.shaping.forward_servo import servo_model, ServoLabels
env_id = sys.argv[1]; gens = int(sys.argv[2])
env = gym.make(env_id); spec = MLPSpec(env.observation_space.shape[0], env.action_space.shape[0])
data = collect(env_id, spec, gens=gens)
pos = data[0][0].position.shape[1]
m = servo_model(spec.obs_dim, pos, spec.act_dim, InverseDynamicsConfig(), 0)
t0 = time.time()
for trs in data:
    m.add(trs); m.train(int(sys.argv[3]) if len(sys.argv) > 3 else None)
print(env_id, "train %.1fs" % (time.time() - t0), "scales", m.step_scale, m.query_scale, "iters", m.iterations)
for gain in (0.5, 1.0, 2.0):
    lab = ServoLabels(m, gain, 3.0)
    r = closed_loop(env_id, lambda st, o, i, p, w, pr, c: lab(o, (w - p)))
    print(" gain", gain, "ret %.2f" % r[0], flush=True)

import sys, json, numpy as np
from shaped_es import train
from shaped_es.monitor.callbacks import Callback
method, seed, gens, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
extra = dict(a.split("=",1) for a in sys.argv[5:])
log=[]
class C(Callback):
    def on_generation(self, row):
        mu = np.asarray(self.run.strategy.mean, np.float64)
        log.append(dict(g=row["generation"], norm=float(np.linalg.norm(mu)), maxabs=float(np.abs(mu).max()),
                        test=row["test_reward_mean"], pop=row["train_reward_mean"], acc=row.get("candidate_accepted"),
                        awake=row.get("shaping_awake")))
        json.dump(log, open(out + ".diag.json", "w"))
cfg = {"env": "UR5Reach-v0", "method": method, "generations": gens, "seed": seed, "executor": "inline"}
for k, v in extra.items():
    try: v = json.loads(v)
    except Exception: pass
    cfg[k] = v
if __name__ == "__main__":
    train(cfg, out, callback=C())

"""Kart-v0 whose 'controller' is greedy shooting with the true simulator (held action, 4 steps, the path
passing nearest the waypoint): the best a model-based 'reach the waypoint' label could be."""
import dataclasses
import numpy as np
from shaped_es.envs.planar.kart import KartCore, KartEnv, make_config
from shaped_es.envs.planar.env import entry_points
import gymnasium as gym

G = np.linspace(-1, 1, 5)
A = np.array([[x, y] for x in G for y in G], np.float32)
H = 4

class ShootCore(KartCore):
    def waypoint_controller(self, state, obs, info):
        B, K = state.batch_size, len(A)
        s = type(state)(**{f.name: np.repeat(getattr(state, f.name), K, axis=0) for f in dataclasses.fields(state)})
        s = dataclasses.replace(s, done=np.zeros(B * K, bool), steps=np.zeros(B * K, np.int64))
        w = np.repeat(np.asarray(info["waypoint"]).reshape(B, 2), K, 0)
        a = np.tile(A, (B, 1)); best = np.full(B * K, np.inf)
        for _ in range(H):
            s = KartCore.step(self, s, a)[0]
            best = np.minimum(best, np.linalg.norm(s.pos - w, axis=1))
        return A[best.reshape(B, K).argmin(1)]

class ShootEnv(KartEnv):
    env_id = "KartShoot-v0"
    core_cls = ShootCore

make_limited, ShootVectorEnv = entry_points(ShootEnv)
if "KartShoot-v0" not in gym.registry:
    gym.register(id="KartShoot-v0", entry_point="kartshoot:make_limited", reward_threshold=8.0,
                 vector_entry_point="kartshoot:ShootVectorEnv")

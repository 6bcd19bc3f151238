"""Prototype: ReacherWay-v0 whose 'controller' is a learned damped transpose servo from an offline forward model."""
import os
import numpy as np
import gymnasium as gym
from shaped_es.envs import reacher as R
from shaped_es.envs.core import limited_entry_point
from shaped_es.envs.vector import vector_entry_point

K_GAIN = float(os.environ.get("SERVO_K", 3.0)); DAMP = float(os.environ.get("SERVO_DAMP", 3.0))
W = dict(np.load(os.environ.get("SERVO_NPZ", str(__import__("pathlib").Path(__file__).with_name("fwd_ReacherWay-v0.npz"))), allow_pickle=False))


def servo(obs, p, w):
    x = (np.asarray(obs, np.float64) - W["mu_s"]) / W["sd_s"]
    h = np.tanh(x @ W["p0"].T + W["p1"]); h = np.tanh(h @ W["p2"].T + W["p3"]); o = h @ W["p4"].T + W["p5"]
    d = p.shape[1]; na = (o.shape[1] - d) // d
    g, G = o[:, :d], o[:, d:].reshape(-1, d, na)  # (B, d), (B, d, act)
    G = G / np.linalg.norm(G, axis=(1, 2), keepdims=True)
    e = (w - p) - DAMP * float(W["ms"]) * g  # (B, d)
    return np.clip(K_GAIN * (np.swapaxes(G, 1, 2) @ e[..., None])[..., 0], -1, 1).astype(np.float32)


class ServoCore(R.ReacherWayCore):
    def waypoint_controller(self, state, obs, info):
        return servo(obs, np.asarray(info["position"], np.float64), np.asarray(info["waypoint"], np.float64))


class ServoEnv(R.ReacherWayEnv):
    core_cls = ServoCore
    env_id = "ReacherServo-v0"


make_limited = limited_entry_point(ServoEnv)
ServoVec = vector_entry_point(ServoEnv)
if "ReacherServo-v0" not in gym.registry:
    gym.register(id="ReacherServo-v0", entry_point="servoenv:make_limited", reward_threshold=-6.5,
                 vector_entry_point="servoenv:ServoVec")

"""Edge cases of the waypoint contract, one configurable 2-D point env registered under several ids."""
import gymnasium as gym
import numpy as np


class Edge(gym.Env):
    def __init__(self, mode="plain", T=50):
        self.mode, self.T = mode, T
        self.observation_space = gym.spaces.Box(-5.0, 5.0, (4,), np.float32)
        if mode == "multidisc":
            self.action_space = gym.spaces.MultiDiscrete([3, 3])
        elif mode == "boxnd":
            self.action_space = gym.spaces.Box(-1.0, 1.0, (2, 1), np.float32)
        elif mode == "underact":
            self.action_space = gym.spaces.Box(-1.0, 1.0, (1,), np.float32)
        else:
            self.action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)

    def _obs_info(self):
        d = self.goal - self.pos
        if self.mode == "nanwp":  # naive unit vector: NaN once the point sits on the goal
            wp = self.pos + 0.1 * d / np.linalg.norm(d) if np.linalg.norm(d) > 0.1 else self.goal.copy()
            if self.reached:
                wp = self.pos + d / np.linalg.norm(d)  # 0/0 -> NaN
        else:
            step = min(1.0, 0.1 / max(float(np.linalg.norm(d)), 1e-9))
            wp = self.pos + step * d
        info = {"position": self.pos.copy(), "waypoint": wp}
        if self.mode == "scalar1d":
            info = {"position": float(self.pos[0]), "waypoint": float(wp[0])}
        if self.mode == "mismatch":
            info["waypoint"] = np.concatenate([wp, [0.0]])
        if self.mode == "list":
            info = {"position": list(self.pos), "waypoint": list(wp)}
        if self.mode == "hidim":
            info = {"position": np.concatenate([self.pos, np.zeros(8)]), "waypoint": np.concatenate([wp, np.zeros(8)])}
        if self.mode == "wpnone" and self.reached:
            info["waypoint"] = None  # route finished: no next waypoint
        if self.mode == "stepsonly" and self.t == 0:
            info = {}
        if self.mode == "reachend" and self.reached:
            info["waypoint"] = self.goal.copy()
        if self.mode == "colvec":
            info = {"position": info["position"].reshape(2, 1), "waypoint": info["waypoint"].reshape(2, 1)}
        if self.mode == "off1k":
            info = {"position": info["position"] + 1000.0, "waypoint": info["waypoint"] + 1000.0}
        if self.mode == "utm":  # the same body in UTM-like world coordinates (metres, large offsets)
            off = np.array([500000.0, 4000000.0])
            info = {"position": info["position"] + off, "waypoint": info["waypoint"] + off}
        if self.mode == "frozen":  # position reported as a constant (a fixed base), waypoint ahead of it
            info = {"position": np.zeros(2), "waypoint": np.array([0.1, 0.0])}
        if self.mode == "quantized":  # grid cells of 0.5: most steps do not change the position
            info = {"position": np.round(self.pos * 2) / 2, "waypoint": np.round(wp * 2) / 2}
        return np.concatenate([self.pos, self.goal]).astype(np.float32), info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.pos = np.zeros(2)
        self.reached = False
        self.t = 0
        self.insta = self.mode == "insta" and self.np_random.uniform() < 0.3
        self.goal = self.np_random.uniform(-2.0, 2.0, 2)
        if self.mode == "nanwp":
            self.goal = np.round(self.goal, 1)  # reachable exactly on the 0.1 grid... not guaranteed
        return self._obs_info()

    def step(self, action):
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        if self.mode == "multidisc":
            a = a - 1.0
        if self.mode == "underact":
            a = np.array([a[0], 0.3])
        self.pos = np.clip(self.pos + 0.1 * np.clip(a, -1.0, 1.0), -5.0, 5.0)
        if np.linalg.norm(self.goal - self.pos) < (0.15 if self.mode == "wpnone" else 0.05):
            if self.mode == "nanwp":
                self.pos = self.goal.copy()
            self.reached = True
        self.t += 1
        obs, info = self._obs_info()
        term = bool(self.insta) or (self.mode in ("wpnone", "reachend") and self.reached and self.np_random.uniform() < 0.0)
        return obs, -float(np.linalg.norm(self.goal - self.pos)), term, False, info


for m in ["multidisc", "boxnd", "underact", "nanwp", "scalar1d", "mismatch", "list", "hidim", "utm", "frozen", "quantized", "wpnone", "stepsonly", "insta", "colvec", "off1k"]:
    gym.register(f"Edge-{m}-v0", entry_point=Edge, kwargs={"mode": m}, max_episode_steps=50)
gym.register("Edge-short-v0", entry_point=Edge, kwargs={"mode": "plain"}, max_episode_steps=3)

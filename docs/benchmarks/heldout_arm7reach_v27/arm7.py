"""Arm7Reach-v0: the 7-DoF torque-driven arm of Gymnasium's MuJoCo Pusher-v5 model, as a reaching task.

The fingertip (body ``tips_arm``) must reach a random 3-D goal point (a forward-kinematics point of a
random joint configuration, so it is reachable), through spatial waypoints every ~0.05 m on the straight
line from the start fingertip to the goal. A waypoint is consumed when the fingertip comes within 0.03 m of
it, or once the fingertip's projection on the start-goal line has passed it (the README's checklist); the
last waypoint (the goal) only when reached within 0.03 m, which ends the episode (+2 bonus).

Reward per step: 10 * (progress along the waypoint path) / (initial path length)  - 1e-3 * |a|^2
  where progress is the decrease of phi = |p - w_k| + (remaining waypoints after k) * spacing.
So a full reach scores ~10 + 2 bonus minus a small action cost; doing nothing scores ~0.
The puck is parked far away (x, y + 5 m) and never touched. 100-step episodes (dt = 0.05 s).
"""

from __future__ import annotations

import os

import gymnasium as gym
import mujoco
import numpy as np
from gymnasium.envs.mujoco.mujoco_env import MujocoEnv

SPACING = 0.05
REACH = 0.03
_XML = os.path.join(os.path.dirname(gym.__file__), "envs", "mujoco", "assets", "pusher.xml")


class Arm7Reach(MujocoEnv):
    metadata = {"render_modes": ["human", "rgb_array", "depth_array"], "render_fps": 20}
    position_period = None  # Cartesian positions: nothing wraps

    def __init__(self, render_mode=None, **kwargs):
        obs_space = gym.spaces.Box(-np.inf, np.inf, (23,), np.float64)
        MujocoEnv.__init__(self, _XML, 5, observation_space=obs_space, render_mode=render_mode,
                           width=320, height=240, **kwargs)
        self.metadata["render_fps"] = int(np.round(1.0 / self.dt))
        self._tip_id = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, "tips_arm")
        self._lo = self.model.jnt_range[:7, 0].copy()
        self._hi = self.model.jnt_range[:7, 1].copy()
        self.goal = np.zeros(3)
        self.start = np.zeros(3)
        self.wps = np.zeros((1, 3))
        self.k = 0

    # -- geometry -----------------------------------------------------------------------------
    def tip(self):
        return self.data.xpos[self._tip_id].copy()

    def _phi(self, p):
        # remaining path length: to the current waypoint, then the rest of the line
        n = len(self.wps)
        return float(np.linalg.norm(p - self.wps[self.k]) + (n - 1 - self.k) * self.spacing)

    def _advance(self, p):
        n = len(self.wps)
        u = (self.goal - self.start) / self.L0
        s = float(np.dot(p - self.start, u))  # projection on the start-goal line
        while self.k < n - 1:
            w = self.wps[self.k]
            if np.linalg.norm(p - w) < REACH or s >= (self.k + 1) * self.spacing:
                self.k += 1
            else:
                break
        return self.k == n - 1 and np.linalg.norm(p - self.wps[-1]) < REACH

    # -- gym API --------------------------------------------------------------------------------
    def reset_model(self):
        rng = self.np_random
        qpos = self.init_qpos.copy()
        qpos[:7] = np.clip(rng.uniform(-0.05, 0.05, 7), self._lo, self._hi)
        qpos[7:9] = [5.0, 5.0]  # puck out of the way
        qpos[9:11] = 0.0
        # goal: forward kinematics of a random configuration, 0.15-0.45 m from the start tip
        self.set_state(qpos, np.zeros_like(self.init_qvel))
        start = self.tip()
        for _ in range(1000):
            q = qpos.copy()
            q[:7] = rng.uniform(self._lo * 0.7, self._hi * 0.7)
            self.data.qpos[:] = q
            mujoco.mj_kinematics(self.model, self.data)
            g = self.tip()
            d = np.linalg.norm(g - start)
            if 0.15 <= d <= 0.45 and g[2] > -0.25:
                break
        self.goal = g
        qpos[9:11] = [g[0] - 0.45, g[1] + 0.05]  # the red goal marker under the goal (render only)
        qvel = self.init_qvel.copy() * 0
        qvel[:7] = rng.uniform(-0.005, 0.005, 7)
        self.set_state(qpos, qvel)
        self.start = self.tip()
        self.L0 = float(np.linalg.norm(self.goal - self.start))
        n = max(1, int(np.ceil(self.L0 / SPACING)))
        self.spacing = self.L0 / n
        self.wps = self.start + np.outer(np.arange(1, n + 1) / n, self.goal - self.start)
        self.k = 0
        self.t = 0
        return self._get_obs()

    def _get_obs(self):
        p = self.tip()
        return np.concatenate([
            self.data.qpos[:7], 0.1 * self.data.qvel[:7], p, self.goal, (self.goal - p) * 3.0,
        ])

    def _get_info(self):
        return {"position": self.tip(), "waypoint": self.wps[self.k].copy(),
                "dist": float(np.linalg.norm(self.goal - self.tip()))}

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64), -2.0, 2.0)
        phi0 = self._phi(self.tip())
        self.do_simulation(a, self.frame_skip)
        p = self.tip()
        # progress toward the current waypoint (measured before it may be consumed)
        progress = phi0 - self._phi(p)
        done = self._advance(p)
        reward = 10.0 * progress / self.L0 - 1e-3 * float(np.dot(a, a)) + (2.0 if done else 0.0)
        if self.render_mode == "human":
            self.render()
        return self._get_obs(), reward, bool(done), False, self._get_info()

    def reset(self, *, seed=None, options=None):
        obs, info = super().reset(seed=seed, options=options)
        return obs, self._get_info()

    # -- oracle --------------------------------------------------------------------------------
    def waypoint_controller(self, obs, info, kp=8.0, vmax=0.6, kv=4.0, lam=0.05):
        """Damped-least-squares velocity servo toward info["waypoint"], as joint torques.

        Desired tip velocity v = kp * (w - p), clipped to vmax m/s; qdot* = J^T (J J^T + lam^2 I)^-1 v;
        torque = kv * (qdot* - qdot), clipped to the actuators' +-2.
        """
        p = self.tip()
        w = np.asarray(info["waypoint"], dtype=np.float64)
        # aim one waypoint further ahead so the tip does not stop at each one
        if self.k < len(self.wps) - 1:
            w = self.wps[self.k + 1]
        e = w - p
        v = kp * e
        sp = np.linalg.norm(v)
        if sp > vmax:
            v *= vmax / sp
        jacp = np.zeros((3, self.model.nv))
        mujoco.mj_jacBody(self.model, self.data, jacp, None, self._tip_id)
        J = jacp[:, :7]
        qd_star = J.T @ np.linalg.solve(J @ J.T + lam ** 2 * np.eye(3), v)
        tau = kv * (qd_star - self.data.qvel[:7])
        return np.clip(tau, -2.0, 2.0).astype(np.float32)


gym.register("Arm7Reach-v0", entry_point=Arm7Reach, max_episode_steps=100, reward_threshold=7.8)

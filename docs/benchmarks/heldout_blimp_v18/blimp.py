"""A hovering blimp in the vertical x-z plane (a new user's env, written from the shaped-es README).

Buoyancy cancels gravity, so zero action is a safe policy: the blimp drifts to a stop (linear and
angular drag). One thruster along the body axis (heading theta, in the x-z plane) and a slow yaw
torque: the position only moves toward a waypoint once the heading has turned toward it.

state: x, z, theta, vx, vz, omega;  action: [thrust, torque] in [-1, 1]^2;  dt = 0.1, 150 steps
    omega += dt * (K_TAU * torque - C_W * omega);  theta += dt * omega
    v     += dt * (K_T * thrust * [cos th, sin th] - C_V * v);  p += dt * v   (semi-implicit Euler)
obs (9): x, z, cos th, sin th, vx, vz, omega, goal_x - x, goal_z - z
reward: 10 * (|p_t - g| - |p_{t+1} - g|) / d0  - 0.01 * |a|^2   (whole way pays 10)
waypoints: every 0.1 on the start-goal line; consumed when the projection passes them or within 0.05.
"""
import gymnasium as gym
import numpy as np

DT, K_T, C_V, K_TAU, C_W = 0.1, 0.6, 1.0, 1.5, 1.5
SPACING, REACH = 0.1, 0.05
ARENA = 2.0


class Blimp(gym.Env):
    observation_space = gym.spaces.Box(-10.0, 10.0, (9,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        rng = self.np_random
        while True:
            self.start = rng.uniform(-ARENA, ARENA, 2)
            self.goal = rng.uniform(-ARENA, ARENA, 2)
            self.d0 = float(np.linalg.norm(self.goal - self.start))
            if self.d0 >= 1.0:
                break
        self.pos = self.start.copy()
        self.vel = np.zeros(2)
        self.theta = float(rng.uniform(-np.pi, np.pi))
        self.omega = 0.0
        n = int(np.ceil(self.d0 / SPACING))
        s = np.minimum(np.arange(1, n + 1) * SPACING, self.d0)
        self.u = (self.goal - self.start) / self.d0
        self.wps = self.start + s[:, None] * self.u
        self.wp_s = s
        self.k = 0
        self._advance()
        return self._obs_info()

    def _advance(self):
        proj = float((self.pos - self.start) @ self.u)
        n = len(self.wps)
        while self.k < n - 1 and (self.wp_s[self.k] <= proj
                                  or np.linalg.norm(self.wps[self.k] - self.pos) < REACH):
            self.k += 1

    def _obs_info(self):
        g = self.goal - self.pos
        obs = np.array([*self.pos, np.cos(self.theta), np.sin(self.theta), *self.vel, self.omega, *g])
        info = {"position": self.pos.copy(), "waypoint": self.wps[self.k].copy()}
        return np.clip(obs, -10, 10).astype(np.float32), info

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        d_before = float(np.linalg.norm(self.goal - self.pos))
        self.omega += DT * (K_TAU * a[1] - C_W * self.omega)
        self.theta = float((self.theta + DT * self.omega + np.pi) % (2 * np.pi) - np.pi)
        head = np.array([np.cos(self.theta), np.sin(self.theta)])
        self.vel = self.vel + DT * (K_T * a[0] * head - C_V * self.vel)
        self.pos = np.clip(self.pos + DT * self.vel, -3.0, 3.0)
        self._advance()
        d_after = float(np.linalg.norm(self.goal - self.pos))
        reward = 10.0 * (d_before - d_after) / self.d0 - 0.01 * float(a @ a)
        obs, info = self._obs_info()
        return obs, reward, False, False, info

    def waypoint_controller(self, obs, info):
        """Turn toward the waypoint (PD on the heading error), thrust by how well aligned; brake at the goal."""
        d = info["waypoint"] - info["position"]
        if self.k == len(self.wps) - 1:
            d = self.goal - self.pos
        err = float((np.arctan2(d[1], d[0]) - self.theta + np.pi) % (2 * np.pi) - np.pi)
        torque = np.clip(3.0 * err - 1.5 * self.omega, -1, 1)
        dist_goal = float(np.linalg.norm(self.goal - self.pos))
        speed_along = float(self.vel @ np.array([np.cos(self.theta), np.sin(self.theta)]))
        want = min(0.6, 1.2 * dist_goal)
        thrust = np.clip(np.cos(err) * (3.0 * (want - speed_along)), -1, 1) if abs(err) < 1.2 else 0.0
        return np.array([thrust, torque], dtype=np.float32)


gym.register("Blimp-v0", entry_point=Blimp, max_episode_steps=150, reward_threshold=6.7)  # 0.9 x controller 7.48

"""Small envs for fault injection: ``fault_envs:Reach-v0`` (the waypoint contract, for ``shaped``) and
``fault_envs:Faulty-v0``, a point pushed to the origin that misbehaves on request (``env_kwargs``):

``fault``: none | raise_step | raise_reset | raise_init | nan_reward | nan_obs | shape | hang | exit |
slow (every step sleeps 5 ms: a run that lasts) | huge_reward (1e308 a step from ``at_step`` on: finite
rewards whose sum overflows) | sys_exit0 / sys_exit_msg (``sys.exit(0)`` / ``sys.exit('message')`` in
step) | string_reward ('1e6') | array_reward (an array of 3) | old_step (the old Gym API's 4-tuple from
every step) | old_reset (reset returns the observation only) | dict_obs (a dict observation) |
close_raises (``close()`` raises)
``at_step``: the step of an episode at which it misbehaves (default 3)
``seeds``: only episodes reset with one of these seeds misbehave (default: every episode)
``marker``: only the first caller that creates this file misbehaves (it writes its pid there); later
calls, retries included, behave

Also ``Unbounded-v0`` (a ``Box(-inf, inf)`` action space), ``Endless-v0`` (never terminates, registered
without a time limit), ``Kwargs-v0`` (takes any keyword arguments) and ``Noisy-v0`` (float64
observations, which Gymnasium's env checker warns about).

Importable by worker processes (``PYTHONPATH`` holds this directory).
"""

from __future__ import annotations

import os
import sys
import time

import gymnasium as gym
import numpy as np


def claim(marker: str) -> bool:
    try:
        fd = os.open(marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
    except FileExistsError:
        return False
    os.write(fd, str(os.getpid()).encode())
    os.close(fd)
    return True


class Faulty(gym.Env):
    observation_space = gym.spaces.Box(-10, 10, (3,), np.float32)
    action_space = gym.spaces.Box(-1, 1, (2,), np.float32)

    def __init__(self, fault: str = "none", at_step: int = 3, seeds=None, marker: str | None = None):
        if fault == "raise_init":
            raise RuntimeError("the simulator failed to start (raise_init)")
        self.fault, self.at_step, self.marker = fault, int(at_step), marker
        self.seeds = None if seeds is None else {int(s) for s in seeds}
        self._armed = False

    def _arm(self, seed) -> bool:
        if self.fault == "none" or (self.seeds is not None and seed not in self.seeds):
            return False
        return self.marker is None or claim(self.marker)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self._armed = self._arm(seed)
        if self._armed and self.fault == "raise_reset":
            raise ValueError("reset failed (raise_reset)")
        self.x = self.np_random.uniform(-1, 1, 2).astype(np.float32)
        self.t = 0
        if self._armed and self.fault == "old_reset":
            return self._obs()
        return self._obs(), {}

    def _obs(self):
        return np.array([self.x[0], self.x[1], self.t / 20.0], np.float32)

    def step(self, action):
        self.t += 1
        if self.fault == "slow":
            time.sleep(0.005)
        self.x = np.clip(self.x + 0.2 * np.asarray(action, np.float32), -10, 10)
        obs, reward = self._obs(), 1.0 - float(np.linalg.norm(self.x))
        if self._armed and self.fault == "huge_reward" and self.t >= self.at_step:
            reward = 1e308
        if self._armed and self.t == self.at_step:
            f = self.fault
            if f == "raise_step":
                raise RuntimeError("the simulator lost its connection (raise_step)")
            if f == "nan_reward":
                reward = float("nan")
            elif f == "nan_obs":
                obs[1] = np.nan
            elif f == "shape":
                obs = np.zeros(5, np.float32)
            elif f == "hang":
                while True:
                    time.sleep(1)
            elif f == "exit":
                os._exit(13)
            elif f == "sys_exit0":
                sys.exit(0)
            elif f == "sys_exit_msg":
                sys.exit("the simulator quit")
            elif f == "string_reward":
                reward = "1e6"
            elif f == "array_reward":
                reward = np.ones(3)
            elif f == "dict_obs":
                obs = {"x": obs}
        if self._armed and self.fault == "old_step":
            return obs, reward, self.t >= 20, {}
        return obs, reward, False, self.t >= 20, {}

    def close(self):
        if self.fault == "close_raises":
            raise RuntimeError("the simulator would not shut down (close_raises)")


class Reach(gym.Env):
    """A point following waypoints 0.5 apart along a random direction; carries info position/waypoint.
    ``fault`` (from step ``at_step`` on): none | nan_position | inf_waypoint | position_missing |
    waypoint_3d (a 3-d waypoint from reset on, beside the 2-d position) | reward_array1 (every reward an
    array of shape (1,), as some simulators' bindings return it: one number, which every path must take)."""

    observation_space = gym.spaces.Box(-20, 20, (4,), np.float32)
    action_space = gym.spaces.Box(-1, 1, (2,), np.float32)

    metadata = {"render_modes": ["rgb_array"]}

    def __init__(self, fault: str = "none", at_step: int = 3, render_mode: str | None = None):
        self.fault, self.at_step, self.t, self.render_mode = fault, int(at_step), 0, render_mode

    def render(self):
        return np.zeros((8, 8, 3), np.uint8)  # a blank frame: enough for render's loop

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.x = np.zeros(2, np.float32)
        ang = self.np_random.uniform(0, 2 * np.pi)
        self.dir = np.array([np.cos(ang), np.sin(ang)], np.float32)
        self.k, self.t = 1, 0
        return self._obs(), self._info()

    def _wp(self):
        return (0.5 * self.k * self.dir).astype(np.float32)

    def _obs(self):
        return np.concatenate([self.x, self._wp() - self.x]).astype(np.float32)

    def _info(self):
        info = {"position": self.x.copy(), "waypoint": self._wp()}
        late = self.t >= self.at_step
        if self.fault == "waypoint_3d":
            info["waypoint"] = np.append(info["waypoint"], 0.0).astype(np.float32)
        elif late and self.fault == "nan_position":
            info["position"][0] = np.nan
        elif late and self.fault == "inf_waypoint":
            info["waypoint"][1] = np.inf
        elif late and self.fault == "position_missing":
            del info["position"]
        return info

    def step(self, action):
        self.t += 1
        self.x = (self.x + 0.3 * np.asarray(action, np.float32)).astype(np.float32)
        reward = 0.0
        if np.linalg.norm(self._wp() - self.x) < 0.3:
            self.k += 1
            reward = 10.0
        reward -= 0.1 * float(np.linalg.norm(self._wp() - self.x))
        if self.fault == "reward_array1":
            reward = np.array([reward])
        return self._obs(), reward, False, False, self._info()


class Unbounded(Faulty):
    action_space = gym.spaces.Box(-np.inf, np.inf, (2,), np.float32)


class Endless(Faulty):
    """Never terminates or truncates (and is registered without a time limit)."""

    def step(self, action):
        obs, reward, _, _, info = super().step(action)
        return obs, reward, False, False, info


class Kwargs(Faulty):
    def __init__(self, **kwargs):
        super().__init__()
        self.kwargs = kwargs


class Noisy(Faulty):
    def _obs(self):
        return super()._obs().astype(np.float64)


gym.register("Faulty-v0", entry_point=Faulty, max_episode_steps=20)
gym.register("Unbounded-v0", entry_point=Unbounded, max_episode_steps=20)
gym.register("Endless-v0", entry_point=Endless)
gym.register("Kwargs-v0", entry_point=Kwargs, max_episode_steps=20)
gym.register("Noisy-v0", entry_point=Noisy, max_episode_steps=20)
gym.register("Reach-v0", entry_point=Reach, max_episode_steps=25)

"""Arm7Reach-v0: Pusher-v5's torque-driven 7-DoF arm reaching a 3-D goal through timed waypoints.

Built on Gymnasium's MuJoCo ``PusherEnv`` (same model ``pusher_v5.xml``, frame_skip 5, dt 0.05 s,
7 joint torques in [-2, 2], zero gravity, the arm's start as Pusher's: init_qpos plus qvel noise
U(-0.005, 0.005)). The puck is parked 5 m away (slide joints at x=+5, y=+5) and never touched.

- position  p_t : world position of the ``tips_arm`` body (``data.body("tips_arm").xpos``, as Pusher's
                  ``get_body_com("tips_arm")``); 3-D.
- goal      g   : per episode from the reset seed (``self.np_random``): a random joint configuration
                  (uniform in the joint ranges, wrist/forearm rolls narrowed) pushed through forward
                  kinematics, accepted when the fingertip lands 7.5-22.5 cm above the table
                  (table surface z=-0.325, so z in [-0.25, -0.10]), |y + 0.6| <= 0.6 and 0.2-0.7 m from
                  the start fingertip. So every goal is reachable by construction.
- waypoints w_k : on the straight line from the start fingertip p_0 to g,
                  w_k = p_0 + min(1, k / (0.6 * T)) * (g - p_0), k = steps taken, T = 100:
                  the goal is due at step 60 and held for the last 40 steps.
                  info["waypoint"] after k steps is w_{k+1} (the one the next step is scored on).
- reward   r_k  : -||p_k - w_k|| - 0.01 * ||a||^2 (after the k-th step).
- obs (24)      : qpos[:7], qvel[:7], p_t, g - p_t, w_{k+1} - p_t, k / T.
- episode       : 100 steps (TimeLimit via the registration; the env itself never terminates).

``waypoint_controller(obs, info)``: a scripted resolved-rate controller toward info["waypoint"]
(damped least squares, the waypoint line's speed fed forward, a null-space pull to a bent elbow since
the start q=0 is the outstretched singular pose, joint torques 1.5 * (qd_des - qd)); the oracle label
source and the top of the threshold's scale.

Threshold (reward_threshold=-8.0), measured by ``python threshold.py`` over reset seeds 0-49:
zero action -34.5 (mean; the goal averages 0.49 m from the start), uniform random torques -52.7,
the scripted controller -1.6 (1.3 cm mean tracking error). -8.0 is ~80% of the way from zero action
to the controller: a mean distance to the moving waypoint of at most ~8 cm (less the action cost).
"""

from __future__ import annotations

import gymnasium as gym
import mujoco
import numpy as np
from gymnasium.envs.mujoco.pusher_v5 import PusherEnv

T_STEPS = 100
ARRIVE_FRAC = 0.6
CTRL_COST = 0.01
PUCK_AWAY = np.array([5.0, 5.0])


class Arm7Reach(PusherEnv):
    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.observation_space = gym.spaces.Box(-np.inf, np.inf, (24,), np.float64)
        self._fk = mujoco.MjData(self.model)
        self._tip_id = self.model.body("tips_arm").id
        self.k = 0
        self.start = np.zeros(3)
        self.goal_xyz = np.zeros(3)

    # --- geometry -------------------------------------------------------------------------------
    def _tip(self) -> np.ndarray:
        return self.data.xpos[self._tip_id].copy()

    def _waypoint(self, k: int) -> np.ndarray:
        s = min(1.0, k / (ARRIVE_FRAC * T_STEPS))
        return self.start + s * (self.goal_xyz - self.start)

    def _sample_goal(self) -> np.ndarray:
        lo, hi = self.model.jnt_range[:7, 0].copy(), self.model.jnt_range[:7, 1].copy()
        for j in (2, 4, 6):  # roll joints: keep them moderate
            lo[j], hi[j] = -0.7, 0.7
        for _ in range(10000):
            q = self.np_random.uniform(lo, hi)
            self._fk.qpos[:] = 0.0
            self._fk.qpos[:7] = q
            self._fk.qpos[7:9] = PUCK_AWAY
            mujoco.mj_kinematics(self.model, self._fk)
            p = self._fk.xpos[self._tip_id]
            d = np.linalg.norm(p - self.start)
            if -0.25 <= p[2] <= -0.10 and abs(p[1] + 0.6) <= 0.6 and 0.2 <= d <= 0.7:
                return p.copy()
        raise RuntimeError("no goal found")

    # --- gym API ----------------------------------------------------------------------------------
    def reset_model(self):
        qpos = self.init_qpos.copy()
        qpos[7:9] = PUCK_AWAY  # puck far away
        qpos[9:11] = 0.0
        qvel = self.init_qvel + self.np_random.uniform(-0.005, 0.005, self.model.nv)
        qvel[7:] = 0.0
        self.set_state(qpos, qvel)
        self.k = 0
        self.start = self._tip()
        self.goal_xyz = self._sample_goal()
        # move Pusher's red goal marker under the goal for rendering (x, y only; it is a slide pair)
        qpos = self.data.qpos.copy()
        qpos[9:11] = self.goal_xyz[[1, 0]] - np.array([-0.05, 0.45])
        self.set_state(qpos, self.data.qvel.copy())
        return self._get_obs()

    def _get_obs(self):
        p = self._tip()
        w = self._waypoint(self.k + 1)
        return np.concatenate(
            [
                self.data.qpos[:7],
                self.data.qvel[:7],
                p,
                self.goal_xyz - p,
                w - p,
                [self.k / T_STEPS],
            ]
        )

    def _info(self):
        return {
            "position": self._tip(),
            "waypoint": self._waypoint(self.k + 1),
            "goal": self.goal_xyz.copy(),
        }

    def reset(self, *, seed=None, options=None):
        obs, _ = super().reset(seed=seed, options=options)
        return obs, self._info()

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64), -2.0, 2.0)
        self.do_simulation(a, self.frame_skip)
        self.k += 1
        p = self._tip()
        dist = float(np.linalg.norm(p - self._waypoint(self.k)))
        ctrl = CTRL_COST * float(np.square(a).sum())
        reward = -dist - ctrl
        obs = self._get_obs()
        info = self._info()
        info.update(dist=dist, ctrl=ctrl, goal_dist=float(np.linalg.norm(p - self.goal_xyz)))
        if self.render_mode == "human":
            self.render()
        return obs, reward, False, False, info

    # --- scripted controller ----------------------------------------------------------------------
    def waypoint_controller(self, obs, info, kp=8.0, kv=1.5, lam=0.05, kn=1.0):
        """Resolved-rate control toward info["waypoint"]: damped-least-squares joint velocities
        (waypoint error gain kp 1/s, the waypoint line's speed fed forward), a null-space pull to a
        bent-elbow rest posture (the start, q=0, is the outstretched singular pose), and joint
        torques kv * (qd_des - qd), clipped to [-2, 2]."""
        p = self._tip()
        w = np.asarray(info["waypoint"], dtype=np.float64)
        jacp = np.zeros((3, self.model.nv))
        mujoco.mj_jacBody(self.model, self.data, jacp, None, self._tip_id)
        J = jacp[:, :7]
        q, qd = self.data.qpos[:7], self.data.qvel[:7]
        v_ff = (self._waypoint(self.k + 2) - w) / self.dt
        JJ = J @ J.T + lam**2 * np.eye(3)
        Jp = J.T @ np.linalg.solve(JJ, np.eye(3))
        q_rest = np.array([0.0, 0.3, 0.0, -1.2, 0.0, -0.5, 0.0])
        qd_des = Jp @ (kp * (w - p) + v_ff) + (np.eye(7) - Jp @ J) @ (kn * (q_rest - q))
        return np.clip(kv * (qd_des - qd), -2.0, 2.0)

gym.register(
    "Arm7Reach-v0",
    entry_point=Arm7Reach,
    max_episode_steps=T_STEPS,
    reward_threshold=-8.0,
)

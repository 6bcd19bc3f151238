"""How often Turn-v0's wrapped position makes a 2*pi jump: in a one-step displacement p_{t+1} - p_t (what M_phi
trains on) and in the query w_t - p_t (what it is asked), under random actions, full torque and the controller."""
import gymnasium as gym, numpy as np, turn  # noqa: F401

env = gym.make("Turn-v0").unwrapped
rng = np.random.default_rng(0)
pols = {"random": lambda o, i: rng.uniform(-1, 1, 1), "full torque +1": lambda o, i: np.ones(1),
        "controller": lambda o, i: env.waypoint_controller(o, i)}
for name, pol in pols.items():
    dp, q, eps_jump = [], [], 0
    for s in range(200):
        o, i = env.reset(seed=s); jumped = False
        for t in range(100):
            p = i["position"].copy(); q.append(float((i["waypoint"] - p)[0]))
            o, r, _, _, i = env.step(pol(o, i))
            dp.append(float((i["position"] - p)[0]))
        jumped = any(abs(x) > np.pi for x in dp[-100:])
        eps_jump += jumped
    dp, q = np.abs(np.array(dp)), np.abs(np.array(q))
    big = dp > np.pi
    print(f"{name:15s} steps {dp.size}: |dp|>pi {big.sum()} ({100*big.mean():.2f}%), episodes with a jump {eps_jump}/200; "
          f"std dp {np.std(dp):.3f} (without jumps {np.std(dp[~big]):.3f}), median |dp| {np.median(dp):.3f}; "
          f"|w-p|>pi {int((q>np.pi).sum())} ({100*(q>np.pi).mean():.2f}%)")

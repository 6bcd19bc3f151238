"""Non-evolutionary baselines on the same envs, seeds and metrics format as the ES methods.

``ppo``: Stable-Baselines3 PPO on a single core (the paper's Fig. 4 PPO curve); imported lazily by the CLI
so ES runs never load SB3.
"""

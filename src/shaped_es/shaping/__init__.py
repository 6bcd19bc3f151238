"""The paper's shaping layer (Lekkala & Itti, Sec. III): pure building blocks of Algorithm 1.

- :mod:`.inverse_dynamics`: ``M_phi(s_t, w_t) -> a_t``, trained on rollouts, labels actions (torch).
- :mod:`.cloning`: behaviour cloning of a whole population at once, ``theta_i -> theta*_i`` (torch).
- :mod:`.surrogate`: ``Delta = (Theta* - mu_{g+1}) / eta`` and its orthonormal basis ``U`` (NumPy).
- :mod:`.trajectories`: the Parquet trajectory store, the paper's NFS (pyarrow).
- :mod:`.shard_table`: one shard of it as an Arrow table (its columns; encoded, and read back with its checks).

Import from the submodules: this package file imports nothing, so ``shaped_es.shaping.trajectories``
(e.g. for its error type in the CLI) does not pull in torch. The layer imports only torch, numpy,
pyarrow, :mod:`shaped_es.policies` and :mod:`shaped_es.data` (never executors, strategies or the trainer).
"""

"""Counter-based standard normals for cloning under the search's parameter noise (``mean_clone.noise``).

With ``mean_clone.noise`` > 0 (off by default) the mean's clone is fitted where the search will sample it:
each Adam step's gradient is taken at ``theta + s z_k`` (``z_k`` near ``N(0, I_n)``, ``s`` = ``mean_clone.noise *
es.sigma``) and applied to ``theta``, so the fit aims at the behaviour-cloning loss smoothed by the ES's own
perturbation, ``E_z L(theta + s z)`` (the Gaussian smoothing ES itself climbs; Salimans et al. 2017, Eq. 1).
A plain clone can sit where the loss is sharp: on UR5Reach-v0 such clones, accepted as the mean, left the
population sampled around them far below the mean's own return (late population mean 0.4 against the mean's
test reward of 43, means over 10 seeds), and the ES steps from there lowered the mean. The noise brings that
population back and costs generations to the threshold (``docs/benchmarks/clone_noise_v28``).

Written by hand (not ``numpy.random``): the compiled fit (``kernels.fit_population``) draws ``z_k`` inside
its one call, step by step, with no ``(steps, n)`` buffer (a 1M-parameter policy's 200 steps would be 800
MB), and the NumPy reference must draw the same numbers. Element ``j`` of step ``k`` for seed ``s`` is a
pure function of ``(s, k n + j)``: splitmix64 (Steele et al. 2014) of the counter, whose four 16-bit parts
are summed (Irwin-Hall: a Gaussian's mean and variance after scaling, kurtosis 2.7 against 3, bounded at
+-3.46) -- about 0.5 ns an element in the kernel, where Box-Muller's logarithm and cosine cost 30-110 ns and
made a 118k-parameter clone's 200 steps 2.7x slower. The smoothing needs the search's scale, not its
exact tails. :func:`normals` here; ``kernels._normal`` the same per element, with these constants.
"""

from __future__ import annotations

import numpy as np

GOLDEN = np.uint64(0x9E3779B97F4A7C15)  # splitmix64's increment
MIX1 = np.uint64(0xBF58476D1CE4E5B9)
MIX2 = np.uint64(0x94D049BB133111EB)
SCALE = np.float32(1.7320508)  # sqrt(12 / 4): the sum of four U(0, 1) has variance 4 / 12
INV_2_16 = np.float32(1.0 / 65536.0)


def mix(x: np.ndarray) -> np.ndarray:
    """splitmix64's output function on uint64 ``x`` (wrapping arithmetic)."""
    x = (x ^ (x >> np.uint64(30))) * MIX1
    x = (x ^ (x >> np.uint64(27))) * MIX2
    return x ^ (x >> np.uint64(31))


def normals(seed: int, step: int, n: int) -> np.ndarray:
    """``z_step`` ``(n,)`` float32 for ``seed``: mean 0, variance 1 (Irwin-Hall of four uniforms, near a standard
    normal), element ``j`` from counter ``step * n + j``."""
    with np.errstate(over="ignore"):
        counter = np.uint64(step) * np.uint64(n) + np.arange(n, dtype=np.uint64)  # (n,)
        h = mix(np.uint64(seed & 0xFFFFFFFFFFFFFFFF) + (counter + np.uint64(1)) * GOLDEN)  # (n,) uint64
    parts = [(h >> np.uint64(16 * i)) & np.uint64(0xFFFF) for i in range(4)]  # four (n,) 16-bit integers
    total = (parts[0] + parts[1] + parts[2] + parts[3]).astype(np.float32)  # (n,) exact below 2^18
    return (total * INV_2_16 - np.float32(2.0)) * SCALE

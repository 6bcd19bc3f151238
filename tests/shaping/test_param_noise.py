import numpy as np
import pytest

from shaped_es.shaping import kernels
from shaped_es.shaping.param_noise import normals


def test_normals_have_a_standard_normals_moments_and_are_a_function_of_seed_and_step():
    z = normals(11, 0, 200_000)
    assert z.dtype == np.float32 and z.shape == (200_000,)
    assert abs(z.mean()) < 0.01 and abs(z.std() - 1) < 0.01
    assert 2.6 < np.mean(z ** 4) < 2.8  # Irwin-Hall of four: kurtosis 2.7 (a normal's 3, a uniform's 1.8)
    assert np.abs(z).max() <= 2 * 1.7320508 + 1e-6
    np.testing.assert_array_equal(normals(11, 3, 50), normals(11, 3, 50))
    assert not np.array_equal(normals(11, 3, 50), normals(12, 3, 50))
    assert not np.array_equal(normals(11, 3, 50), normals(11, 4, 50))
    # step k of n elements continues the counter: element j of step k is counter k n + j
    np.testing.assert_array_equal(normals(5, 2, 10), normals(5, 0, 30)[20:])
    assert abs(np.corrcoef(normals(1, 0, 10_000), normals(2, 0, 10_000))[0, 1]) < 0.05


@pytest.mark.parametrize("seed", [0, 123456789, 2**64 - 1])
def test_the_kernel_draws_the_same_numbers(seed):
    want = normals(seed, 4, 64)
    got = np.array([kernels._normal(np.uint64(seed), np.uint64(4 * 64 + j)) for j in range(64)], np.float32)
    np.testing.assert_allclose(got, want, rtol=1e-6, atol=1e-6)

import numpy as np

from shaped_es import seeding


def test_seeds_stable_and_distinct():
    a = seeding.episode_seeds(7, seeding.TRAIN, 3, np.arange(4), 2)
    b = seeding.episode_seeds(7, seeding.TRAIN, 3, np.arange(4), 2)
    assert a.shape == (4, 2) and (a == b).all()
    assert (a == a[0]).all()  # common random numbers: every member faces the same episodes
    assert a[0, 0] != a[0, 1]
    c = seeding.episode_seeds(7, seeding.TRAIN, 3, np.arange(4), 2, common=False)
    assert len(set(c.ravel().tolist())) == 8
    assert seeding.derive_seed(7, 1, 3) != seeding.derive_seed(7, 1, 4)
    assert seeding.derive_seed(7, seeding.TRAIN, 0) != seeding.derive_seed(7, seeding.TEST, 0)

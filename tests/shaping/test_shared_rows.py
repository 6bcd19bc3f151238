"""The shared-memory segment the master lays cloning's rows out in, and the handle workers open."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from shaped_es.shaping.shared_rows import RowsRef, SharedRows


def test_arrays_round_trip_through_a_picklable_handle():
    shared = SharedRows()
    try:
        views, ref = shared.arrays({"S": (3, 4, 5), "A": (3, 4, 2)})
        views["S"][...] = np.arange(60, dtype=np.float32).reshape(3, 4, 5)
        views["A"][...] = -1.0
        seen = pickle.loads(pickle.dumps(ref)).open()  # what a worker maps
        np.testing.assert_array_equal(seen["S"], views["S"])
        assert seen["A"].shape == (3, 4, 2) and np.all(seen["A"] == -1.0)
        assert all(off % 64 == 0 for _, off, _ in ref.layout)  # each array on a cache line
    finally:
        shared.close()


def test_a_larger_request_replaces_the_segment_and_close_unlinks_it():
    shared = SharedRows()
    _, small = shared.arrays({"S": (10,)})
    _, same = shared.arrays({"S": (11,)})  # fits the 25% headroom: the same segment
    assert same.name == small.name
    views, big = shared.arrays({"S": (1000,)})
    assert big.name != small.name
    views["S"][:] = 7.0
    assert np.all(big.open()["S"] == 7.0)
    with pytest.raises(FileNotFoundError):
        small.open()  # the old segment is gone
    shared.close()
    shared.close()  # twice is fine
    with pytest.raises(FileNotFoundError):
        RowsRef(big.name + "x", big.layout).open()  # a handle to no segment: the OS's error

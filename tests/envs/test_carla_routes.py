"""CarlaNav-v0's route planner on a small synthetic lane graph (exact lengths and polylines), and the
topology walk over the test double's map."""

import numpy as np
import pytest
from carla_double import LANES, Map

from shaped_es.envs.carla.routes import Located, RoadGraph, pick_route, route_length, topology_segments

# A square block of one-way lanes (env frame): A(0,0) -> B(10,0) -> C(10,10) -> D(0,10) -> A, and a
# shortcut B -> D of 16 m (shorter than the 20 m via C).
SQUARE = [
    ((1, 0, -1), np.array([[0.0, 0.0], [5.0, 0.0], [10.0, 0.0]])),  # A -> B, 10 m
    ((2, 0, -1), np.array([[10.0, 0.0], [10.0, 10.0]])),  # B -> C, 10 m
    ((3, 0, -1), np.array([[10.0, 10.0], [0.0, 10.0]])),  # C -> D, 10 m
    ((4, 0, -1), np.array([[0.0, 10.0], [0.0, 0.0]])),  # D -> A, 10 m
    ((5, 0, -1), np.array([[10.0, 0.0], [10.0, 4.0], [2.0, 10.0], [0.0, 10.0]])),  # B -> D: 4 + 10 + 2 = 16 m
]


def test_graph_joins_segment_ends_into_nodes():
    g = RoadGraph(SQUARE)
    assert len(g.nodes) == 4 and g.graph.number_of_edges() == 5
    assert [tuple(e) for e in g.ends] == [(0, 1), (1, 2), (2, 3), (3, 0), (1, 3)]
    assert g.graph[1][3]["length"] == pytest.approx(16.0)


def test_locate_by_key_then_projection():
    g = RoadGraph(SQUARE)
    assert g.locate((4.0, 0.3)) == Located(0, 4.0)
    assert g.locate((10.0, 3.0), key=(2, 0, -1)) == Located(1, 3.0)  # B -> C, not the shortcut
    assert g.locate((10.0, 3.0), key=(5, 0, -1)) == Located(4, 3.0)  # the shortcut's first leg
    assert g.locate((10.0, 3.0), key=(99, 0, -1)).segment in (1, 4)  # unknown key: geometry decides


def test_astar_takes_the_shorter_way_and_cuts_both_ends():
    g = RoadGraph(SQUARE)
    line = g.route(Located(0, 4.0), Located(3, 5.0))  # from A->B at 4 m to D->A at 5 m
    # 6 m to B, the 16 m shortcut (not 20 m via C), 5 m down D -> A
    assert route_length(line) == pytest.approx(6.0 + 16.0 + 5.0)
    np.testing.assert_allclose(line, [[4, 0], [5, 0], [10, 0], [10, 4], [2, 10], [0, 10], [0, 5]])


def test_same_segment_ahead_and_behind():
    g = RoadGraph(SQUARE)
    np.testing.assert_allclose(g.route(Located(0, 1.0), Located(0, 7.5)), [[1, 0], [5, 0], [7.5, 0]])
    behind = g.route(Located(0, 7.5), Located(0, 1.0))  # all the way round: 2.5 + 16 + 10 + 1
    assert route_length(behind) == pytest.approx(29.5)


def test_unreachable_is_none():
    g = RoadGraph(SQUARE[:2])  # A -> B -> C, nothing back
    assert g.route(Located(1, 5.0), Located(0, 5.0)) is None
    with pytest.raises(ValueError, match="no lane topology"):
        RoadGraph([])


def test_pick_route_hits_the_length_range_or_takes_the_closest():
    g = RoadGraph(SQUARE)
    spots = [Located(0, 1.0), Located(1, 5.0), Located(2, 5.0), Located(3, 5.0)]
    # from spot 0 (A->B at 1 m): spot 1 is 9 + 5 = 14 m, spot 2 is 9 + 10 + 5 = 24 m, spot 3 is 9 + 16 + 5 = 30 m
    lengths = sorted(route_length(g.route(spots[0], s)) for s in spots[1:])
    assert lengths == pytest.approx([14.0, 24.0, 30.0])
    for seed in range(5):
        line = pick_route(g, spots, 0, np.random.default_rng(seed), (20.0, 26.0), tries=50)
        assert route_length(line) == pytest.approx(24.0)
    closest = pick_route(g, spots, 0, np.random.default_rng(0), (100.0, 200.0), tries=50)
    assert route_length(closest) == pytest.approx(30.0)
    assert pick_route(g, spots[:1], 0, np.random.default_rng(0), (1.0, 2.0), tries=5) is None


def test_topology_walk_samples_each_lane_and_flips_y():
    segs = topology_segments(Map(), 0.5)
    assert len(segs) == len(LANES)
    key, pts = segs[2]  # lane (100, 0) -> (100, 60) in CARLA's frame: y flips
    assert key == (3, 0, -1) and pts.shape == (121, 3)
    np.testing.assert_allclose(pts[[0, 1, -1]], [[100, 0, 0], [100, -0.5, 0], [100, -60, 0]])
    g = RoadGraph(segs)
    assert len(g.nodes) == 6  # the loop's corners and the middle road's two junctions

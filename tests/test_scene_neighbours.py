import numpy as np

from imgmtf.scene.neighbours import close_pairs, components, pairs_within


def _brute_pairs(q, p, r):
    d2 = ((q[:, None, :] - p[None, :, :]) ** 2).sum(axis=2)
    return set(zip(*np.nonzero(d2 <= r * r)))


def test_pairs_are_every_pair_within_the_radius_once_even_far_outside_the_points():
    rng = np.random.default_rng(0)
    points = rng.uniform(0, 60, (300, 2))
    queries = np.vstack([rng.uniform(-10, 70, (120, 2)), points[:5] + np.array([3.0, 0.0]),  # at the radius
                         [[-500.0, 900.0], [900.0, -500.0]]])
    for radius in (3.0, 0.7, 25.0):
        i, j = pairs_within(queries, points, radius)
        assert len(set(zip(i, j))) == len(i) and set(zip(i, j)) == _brute_pairs(queries, points, radius)
    pairs = close_pairs(points, 3.0)
    expected = {(a, b) for a, b in _brute_pairs(points, points, 3.0) if a < b}
    assert {tuple(p) for p in pairs} == expected and len(pairs) == len(expected)
    assert close_pairs(points[:1], 3.0).shape == (0, 2) and pairs_within(points[:0], points, 1.0)[0].size == 0


def test_components_are_numbered_by_their_lowest_node():
    rng = np.random.default_rng(1)
    n = 40
    a, b = rng.integers(0, n, 25), rng.integers(0, n, 25)
    count, label = components(n, a, b)
    # the closure by brute force: a node's component is everything reachable from it
    reach = np.eye(n, dtype=bool)
    reach[a, b] = reach[b, a] = True
    for _ in range(n):
        reach = reach | (reach.astype(int) @ reach.astype(int) > 0)
    lowest = reach.argmax(axis=1)           # each node's lowest reachable node
    assert count == len(np.unique(lowest))
    np.testing.assert_array_equal(label, np.unique(lowest, return_inverse=True)[1])
    assert components(5, [], [])[0] == 5 and components(0, [], [])[0] == 0

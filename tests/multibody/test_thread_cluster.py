"""The clusters of thread-box contact pairs (multibody/thread_cluster.py) against a plain-Python grouping."""
from __future__ import annotations

import numpy as np
import pytest

from multibody.thread_cluster import group_pairs


def clusters_by_search(pair_thread, pair_shape, threads) -> list[list[int]]:
    """The pairs grouped by a breadth-first search: two pairs on one shape whose threads share a node are in one
    cluster, transitively; clusters in the order of their first pair, pairs in their order (group_pairs' contract)."""
    n_pairs = len(pair_thread)
    cluster_of = [-1] * n_pairs
    clusters = []
    for first in range(n_pairs):
        if cluster_of[first] >= 0:
            continue
        cluster_of[first] = len(clusters)
        members, frontier = [first], [first]
        while frontier:
            p = frontier.pop()
            for q in range(n_pairs):
                if (cluster_of[q] < 0 and pair_shape[q] == pair_shape[p]
                        and set(threads[pair_thread[q]]) & set(threads[pair_thread[p]])):
                    cluster_of[q] = cluster_of[first]
                    members.append(q)
                    frontier.append(q)
        clusters.append(sorted(members))
    return clusters


@pytest.mark.parametrize("seed", range(5))
def test_group_pairs_finds_the_connected_clusters_in_order(seed):
    """A 6 x 6 net's threads (60), a random third of them paired with one of two boxes, some with both: the clusters
    are exactly the connected components of the search above, in its order (integers: no tolerance), and the work
    array ``root_cluster`` leaves all -1 as it came, so the next step's call starts clean."""
    rng = np.random.default_rng(seed)
    side = 6
    index = np.arange(side * side).reshape(side, side)
    threads = np.array([(index[r, c], index[r, c + 1]) for r in range(side) for c in range(side - 1)]
                       + [(index[r, c], index[r + 1, c]) for r in range(side - 1) for c in range(side)], np.int64)
    n_nodes, n_shapes = side * side, 2
    chosen = rng.choice(len(threads), size=20, replace=False)
    pairs = [(int(j), int(rng.integers(n_shapes))) for j in chosen] + [(int(j), 1) for j in chosen[:4]]
    pair_thread = np.array([p[0] for p in pairs], np.int64)
    pair_shape = np.array([p[1] for p in pairs], np.int64)
    n_pairs = len(pairs)
    parent = np.zeros(n_shapes * n_nodes, np.int64)
    root_cluster = np.full(n_shapes * n_nodes, -1, np.int64)
    order = np.zeros(n_pairs, np.int64)
    start = np.full(n_pairs + 1, 99, np.int64)     # filled by the call
    n_clusters = group_pairs(pair_thread, pair_shape, n_pairs, threads, n_nodes, parent, root_cluster, order, start)
    expected = clusters_by_search(pair_thread, pair_shape, threads)
    found = [list(order[start[k]:start[k + 1]]) for k in range(n_clusters)]
    assert found == expected
    assert start[0] == 0 and start[n_clusters] == n_pairs
    assert (root_cluster == -1).all()

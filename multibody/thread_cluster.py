"""The threads in contact with one box, grouped into clusters that share nodes (union-find).

A net node with two or more threads in contact with the same box takes all of their contact forces and its own
contact with the box at once; integrated apart (each thread's sub-cycle predicting the node's own contact, the node
contact integrating it with the threads' mean pushes), the paths differ and each thread's contact starts the next
step away from where its sub-cycle ended it (docs/model.md, "Contact": the reference case gained energy that way).
So the threads in contact with a box are grouped by the nodes they share (two threads on the same box that share a
node are in one cluster, and so on transitively), and each cluster is integrated as one system
(:func:`multibody.segment_cycle.cluster_contact_over_step`). Helper thread13, 2026-11-27.

A pair is (thread, box shape); its nodes are keyed ``node + n * shape`` so that clusters never span two shapes.
"""
from __future__ import annotations

from numba import njit

from multibody.jit_cache import NO_REFCOUNTS


@njit(cache=True, inline="always")
def _root(parent, key):
    """The representative of ``key``'s set, halving the path on the way (union-find)."""
    while parent[key] != key:
        parent[key] = parent[parent[key]]
        key = parent[key]
    return key


@njit(cache=True, **NO_REFCOUNTS)
def group_pairs(pair_thread, pair_shape, n_pairs, threads, n_nodes, parent, root_cluster, order, start):
    """Group the first ``n_pairs`` (thread, shape) contact pairs into clusters of pairs on one shape that share
    nodes, transitively.

    Parameters
    ----------
    pair_thread, pair_shape : (P,) int64
        Each pair's thread and box shape.
    n_pairs : int
    threads : (m, 2) int64
        The net's threads' nodes.
    n_nodes : int
        The net's nodes.
    parent, root_cluster : (ns * n,) int64
        Work; ``root_cluster`` enters and leaves all -1.
    order : (P,) int64
        Out: the pairs, cluster after cluster (clusters in the order of their first pair, pairs in their order).
    start : (P + 1,) int64
        Out: cluster ``k``'s pairs are ``order[start[k]:start[k + 1]]``.

    Returns
    -------
    n_clusters : int
    """
    for p in range(n_pairs):
        offset = n_nodes * pair_shape[p]
        for e in range(2):
            key = threads[pair_thread[p], e] + offset
            parent[key] = key
    for p in range(n_pairs):
        offset = n_nodes * pair_shape[p]
        ra = _root(parent, threads[pair_thread[p], 0] + offset)
        rc = _root(parent, threads[pair_thread[p], 1] + offset)
        if ra != rc:
            parent[max(ra, rc)] = min(ra, rc)
    n_clusters = 0
    start[: n_pairs + 1] = 0
    for p in range(n_pairs):
        r = _root(parent, threads[pair_thread[p], 0] + n_nodes * pair_shape[p])
        if root_cluster[r] < 0:
            root_cluster[r] = n_clusters
            n_clusters += 1
        start[root_cluster[r] + 1] += 1
    for k in range(n_clusters):
        start[k + 1] += start[k]
    # each cluster's pairs placed at start[k], which counts up to its end (the next cluster's start) ...
    for p in range(n_pairs):
        k = root_cluster[_root(parent, threads[pair_thread[p], 0] + n_nodes * pair_shape[p])]
        order[start[k]] = p
        start[k] += 1
    # ... and shifted back by one cluster (no copy of the starts: this kernel allocates nothing, so it runs without
    # reference counts, jit_cache.NO_REFCOUNTS)
    for k in range(n_clusters, 0, -1):
        start[k] = start[k - 1]
    start[0] = 0
    for p in range(n_pairs):
        root_cluster[_root(parent, threads[pair_thread[p], 0] + n_nodes * pair_shape[p])] = -1
    return n_clusters

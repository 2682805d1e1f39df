"""Counting-sort cell list against a brute-force neighbour search."""
import numpy as np
import pytest

from sphdvi.sph import cells


@pytest.mark.parametrize("is2d", [True, False])
def test_neighbours_match_bruteforce(is2d):
    rng = np.random.default_rng(1)
    n = 700 if is2d else 1200
    pos = rng.random((n, 3)) * np.array([1.0, 0.6, 0.8])
    if is2d:
        pos[:, 1] = 0.0
    h = 0.03 if is2d else 0.06
    cl = cells.CellList(h, is2d)
    order = cl.build(pos)
    assert sorted(order.tolist()) == list(range(n))
    sorted_cells = cl.cell[order]
    assert np.all(np.diff(sorted_cells) >= 0)          # sorted by cell
    for c in np.unique(sorted_cells)[:50]:               # cell_start consistent
        k = np.nonzero(sorted_cells == c)[0]
        assert cl.cell_start[c] == k[0] and cl.cell_start[c + 1] == k[-1] + 1
    spos = pos[order]
    found = cells._pairs_from_cells(spos, sorted_cells, cl.cell_start, *cl.shape, is2d, 2 * h)
    found = {(int(order[i]), int(order[j])) for i, j in found}
    found = {(min(a, b), max(a, b)) for a, b in found}
    ref = cells.neighbour_pairs_bruteforce(pos, 2 * h, is2d)
    assert len(ref) > 2 * n
    assert found == ref


def test_grid_covers_given_box_and_clamps_outside():
    pos = np.array([[0.0, 0, 0], [0.5, 0, 0.5], [2.0, 0, -1.0]])
    cl = cells.CellList(0.1, True)
    cl.build(pos, pmin=np.zeros(3), pmax=np.ones(3))
    assert cl.shape == (6, 1, 6)
    assert cl.cell[2] == 5            # clamped to cell (5, 0)


@pytest.mark.parametrize("is2d", [True, False])
def test_counting_sort_is_stable_and_every_cell_start_is_right(is2d):
    """The order is numpy's stable argsort of the cells (equal cells keep their order, which
    resumed runs rely on to repeat a run bitwise), and cell_start is the first sorted row of
    every cell, empty ones included (the search reads the start of a stencil row's first cell
    and of the cell after its last one), with n at the end."""
    rng = np.random.default_rng(7)
    pos = rng.random((900, 3)) * np.array([1.0, 0.5, 0.7])
    pos[::3] = pos[::3].round(1)                 # clusters of particles in the same cells
    cl = cells.CellList(0.005 if is2d else 0.02, is2d)      # more cells than particles
    order = cl.build(pos)
    np.testing.assert_array_equal(order, np.argsort(cl.cell, kind="stable"))
    ncells = int(np.prod(cl.shape))
    assert cl.cell_start.shape == (ncells + 1,)
    np.testing.assert_array_equal(cl.cell_start, np.searchsorted(cl.cell[order], np.arange(ncells + 1)))
    assert ncells > 2 * len(pos) and cl.cell_start[-1] == len(pos)

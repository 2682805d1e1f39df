"""Exclusion helpers (masks and counts)."""
import numpy as np

from sphdvi.sph.exclusion import (count_reasons, domain_out_mask, not_finite_mask,
                                  rhop_out_mask)


def test_masks_and_counts():
    pos = np.array([[0.0, 0, 0], [2.0, 0, 0], [0.5, 0, 0.5], [0.5, 0, 0.5], [np.nan, 0, 0]])
    vel = np.zeros_like(pos)
    rhop = np.array([1000.0, 1000.0, 650.0, 1350.0, 1000.0])
    ptype = np.array([3, 3, 3, 0, 3], np.int8)
    assert rhop_out_mask(rhop, ptype, 700, 1300).tolist() == [False, False, True, False, False]
    assert domain_out_mask(pos[:4], ptype[:4], [-1, -1, -1], [1, 1, 1]).tolist() == \
        [False, True, False, False]
    assert not_finite_mask(pos, vel, rhop).tolist() == [False, False, False, False, True]
    assert count_reasons([0, 1, 2, 2, 3]) == {"rhop": 1, "position": 2, "not finite": 1}

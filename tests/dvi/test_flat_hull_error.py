"""A hull whose points do not span a solid is an input error naming its body and shape
(System.add_shape), not Qhull's raw "QH6154 Qhull precision error: Initial simplex is flat"
(audit hunt11/b, finding 8).  Case files make no hull shapes (their bodies collide as particle
clouds), so there is no case-file form of this error."""
import numpy as np
import pytest

from sphdvi.dvi import System


@pytest.mark.parametrize("pts,what", [
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], "coplanar"),
    ([[0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3]], "collinear"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], "three points"),
])
def test_flat_hull_is_a_clear_error(pts, what):
    s = System()
    s.add_body(1.0, (1, 1, 1), name="ground", kind="fixed")
    s.add_sphere(0, 0.1)
    b = s.add_body(1.0, (1, 1, 1), name="plate")
    with pytest.raises(ValueError) as e:
        s.add_hull(b, np.array(pts, float))
    msg = str(e.value)
    assert "hull shape 1 of body 1 ('plate')" in msg and "coplanar or collinear" in msg
    assert "QH" not in msg
    assert s.sh_type.shape[0] == 1       # nothing of the bad shape was added


def test_duplicated_vertices_are_fine():
    """A tetrahedron with repeated vertices is still a solid."""
    s = System()
    b = s.add_body(1.0, (1, 1, 1))
    V = np.array([[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1], [0.1, 0, 0], [0, 0, 0]], float)
    s.add_hull(b, V)
    assert s.samp_cnt[-1] == 4 and s.pl_cnt[-1] == 4

"""``<fillbox>`` against the particle counts GenCase wrote for DualSPHysics example cases.

GenCase fills only the nodes lying at least dp/2 inside the fill box: a node on the box's face,
or closer than dp/2 to it, stays void. The evidence (GenCase's own output files, which carry the
case's geometry, ``<particles>`` and ``<constants>``), all at the box's top, the free surface:

* DualSPHysics/DualSPHysics examples/others/GaugeSystem/WallRegAwas2.xml (GenCase4 v4.0.059):
  top 1.268 - 1 = 0.268 m, 1/3 dp above the node at 0.266 m: fluid 21,457, b 141,264 Pa
  (hswl 0.252 m: fluid from 0.008 to 0.260 m); the node at 0.266 m is not filled.
* Otor123/DualSPHysics examples/others/Variables/GenericWaveTank.xml (GenCase v5.0.165):
  top on a node (z = 0 after <move z="-depth">): fluid 97,122, b 1.4345508571e6 Pa (hswl 2.56 m,
  not 2.58 m); the 864 nodes of the row at z = 0 are not filled (the 18 left are the beach's
  oblique layers, drawn thinner by sphdvi than by GenCase).
* Otor123/DualSPHysics examples/others/FtRestrictions/FtSloshing.xml (GenCase4 v4.0.092): top on
  a node (0.4 m): fluid 5,345 = 139 x 39 rows (0.01 ... 0.39 m) less the 4 x 19 nodes of the
  floating box below 0.4 m (GenCase drew that box as its 19 x 9 inner nodes, see below).

No output tells the other faces apart (walls stop those fills); they follow the same rule here.
"""
from __future__ import annotations

from test_draw import box, draw, lattice_box, nodes


def fill(seed, point, size):
    return ('<setmkfluid mk="0"/><fillbox x="{}" y="{}" z="{}"><modefill>void</modefill>'
            .format(*seed) + '<point x="{}" y="{}" z="{}"/>'.format(*point)
            + '<size x="{}" y="{}" z="{}"/></fillbox>'.format(*size))


def test_wallregawas2_fluid_count(tmp_path):
    # WallRegAwas2's geometry: piston (mk 10), tank bottom | right (mk 0), fill up to 0.268 m
    body = ('<setdrawmode mode="full"/><setmkbound mk="10"/>'
            + box((-0.014, 0, 0), (0.014, 2, 0.6))
            + '<setmkbound mk="0"/>' + box((-0.2, 0, 0), (3.2, 2, 0.6), fill="bottom | right")
            + fill((0.25, 1, 0.05), (-1, 0, -1), (6, 2, 1.268)))
    d = draw(tmp_path, body, dp=0.006, pmin=(-1, 1, -1), pmax=(5, 1, 5))
    assert d.count_fluid == 21457                          # GenCase: 21,457 (sphdvi was 21,956)
    assert d.count_bound == 635 + 400
    z = d.pos[d.is_fluid, 2]
    assert abs(z.max() - 0.260) < 1e-9 and abs(z.max() - z.min() - 0.252) < 1e-9   # hswl 0.252


def test_ftsloshing_fluid_count(tmp_path):
    # FtSloshing's tank (all faces) and fill up to 0.4 m, a node; the floating box drawn as the
    # 19 x 9 nodes GenCase wrote for it (171 particles; see test_default_mode_box_is_not_changed)
    body = ('<setdrawmode mode="full"/><setmkbound mk="0"/>'
            + box((-0.7, -0.1, 0), (1.4, 0.2, 0.9), fill="all")
            + '<setmkbound mk="1"/>' + box((0.01, -0.1, 0.36), (0.18, 0.2, 0.08))
            + fill((0, 0, 0.1), (-2, -0.1, -1), (4, 0.2, 1.4)))
    d = draw(tmp_path, body, dp=0.01, pmin=(-2, 0, -1), pmax=(2, 0, 2))
    assert d.count_bound == 460 + 171
    assert d.count_fluid == 5345                            # GenCase: 5,345
    assert abs(d.pos[d.is_fluid, 2].max() - 0.39) < 1e-9


def test_fillbox_top_on_a_node_and_between_nodes(tmp_path):
    tank = '<setmkbound mk="0"/>' + box((0, 0, 0), (6, 6, 6), fill="all")
    for top, zmax in [(3, 2), (3.3, 2), (3.49, 2), (3.5, 3), (3.51, 3), (3.9, 3), (4, 3)]:
        d = draw(tmp_path, tank + fill((3, 3, 2), (-1, -1, -1), (8, 8, top + 1)))
        assert nodes(d, fluid=True) == lattice_box((1, 1, 1), (5, 5, zmax)), top


def test_fillbox_all_faces_keep_dp_half_inside(tmp_path):
    # no walls: the box alone limits the fill, on every face alike
    d = draw(tmp_path, fill((5, 5, 5), (2, 2.2, 2.6), (6, 5.7, 5.1)))
    assert nodes(d, fluid=True) == lattice_box((3, 3, 4), (7, 7, 7))
    # a box thinner than dp fills nothing (warning: the seed is outside the fill range)
    d = draw(tmp_path, fill((5, 5, 5), (4.6, 0, 0), (0.8, 10, 10)))
    assert d.count_fluid == 0


def test_default_mode_box_is_not_changed(tmp_path):
    # FtSloshing (GenCase4 v4.0.092) draws its floating box before any <setdrawmode> and GenCase
    # wrote 171 = 19 x 9 particles for it (the box's inner nodes), where full mode gives 21 x 11.
    # sphdvi keeps its full-mode default (one v4 output; v5's default and the off-lattice rule
    # are not known): this pins the present behaviour so that a change is deliberate.
    body = '<setmkbound mk="1"/>' + box((0, -0.1, 0.35), (0.2, 0.2, 0.1))
    d = draw(tmp_path, body, dp=0.01, pmin=(-2, 0, -1), pmax=(2, 0, 2))
    assert d.count_bound == 21 * 11

"""GenCase's redraw commands (``redraw``, ``redrawbox``, ``redrawnear``, ``redrawnearbox``) and
its line rule. GenCase's own records of DualSPHysics's examples RedrawSimple and RedrawComplex are
matched count for count in ``test_gencase_outputs_counts.py``; here each rule on its own, on
dp = 1 lattices."""
from __future__ import annotations

import itertools

import numpy as np
import pytest
from test_draw import box, draw, lattice_box, nodes

from sphdvi.errors import CaseError

CUBE = dict(pmin=(0, 0, 0), pmax=(9, 9, 9))   # nodes 0..8 on each axis


def mk_nodes(d, mk, fluid=False):
    sel = (d.mk == mk) & (d.is_fluid == fluid)
    return {tuple(int(round(v)) for v in p) for p in d.pos[sel]}


def test_redraw_without_label_takes_every_node_void_included(tmp_path):
    d = draw(tmp_path, '<setmkbound mk="3"/><redraw/>', **CUBE)
    assert len(d.pos) == 9 ** 3 and set(d.mk) == {3}


def test_redraw_with_a_label_changes_that_label_only(tmp_path):
    body = ('<setmkbound mk="0"/>' + box((0, 0, 0), (2, 2, 2)) + '<setmkfluid mk="1"/>'
            + box((5, 5, 5), (2, 2, 2)) + '<setmkbound mk="7"/><redraw mkfluid="1"/>')
    d = draw(tmp_path, body, **CUBE)
    assert mk_nodes(d, 7) == lattice_box((5, 5, 5), (7, 7, 7))
    assert mk_nodes(d, 0) == lattice_box((0, 0, 0), (2, 2, 2))
    assert not d.is_fluid.any()


def test_redraw_with_the_void_pen_erases(tmp_path):
    body = ('<setmkbound mk="0"/>' + box((0, 0, 0), (8, 8, 0), fill="solid")
            + '<setmkfluid mk="0"/>' + box((0, 0, 1), (8, 8, 3)) + '<setmkvoid/><redraw mkfluid="0"/>')
    d = draw(tmp_path, body, **CUBE)
    assert not d.is_fluid.any() and len(d.pos) == 81


def test_redrawbox_takes_the_nodes_of_a_solid_drawbox(tmp_path):
    """The box's nodes run from the node nearest its min corner to the node nearest its max corner,
    as a solid <drawbox>'s (off the lattice here: 1.4 .. 5.6 -> 1 .. 6)."""
    ref = draw(tmp_path, '<setmkbound mk="2"/>' + box((1.4, 1.4, 1.4), (4.2, 4.2, 4.2)), **CUBE)
    d = draw(tmp_path, '<setmkbound mk="2"/><redrawbox><point x="1.4" y="1.4" z="1.4"/>'
                       '<size x="4.2" y="4.2" z="4.2"/></redrawbox>', **CUBE)
    assert nodes(d) == nodes(ref) == lattice_box((1, 1, 1), (6, 6, 6))


def test_redrawbox_follows_the_move_matrix(tmp_path):
    d = draw(tmp_path, '<move x="2" y="0" z="0"/><setmkbound mk="2"/><redrawbox>'
                       '<point x="0" y="0" z="0"/><endpoint x="1" y="1" z="1"/></redrawbox>', **CUBE)
    assert nodes(d) == lattice_box((2, 0, 0), (3, 1, 1))


def test_redrawnear_touches_across_faces_edges_and_corners(tmp_path):
    """One pass around a single node takes its 26 neighbours; a second pass, whose border
    includes the first pass's nodes (bordertp bound, any mk), the next shell of 98."""
    body = ('<setmkbound mk="0"/><drawpoint x="4" y="4" z="4"/><setmkbound mk="1"/>'
            '<redrawnear times="{}" targettp="void" bordertp="bound"/>')
    one = draw(tmp_path, body.format(1), **CUBE)
    assert mk_nodes(one, 1) == lattice_box((3, 3, 3), (5, 5, 5)) - {(4, 4, 4)}
    two = draw(tmp_path, body.format(2), **CUBE)
    assert mk_nodes(two, 1) == lattice_box((2, 2, 2), (6, 6, 6)) - {(4, 4, 4)}


def test_redrawnear_border_mk_and_target_mk(tmp_path):
    """bordermk restricts the border to that mk, targetmk the target; a pen other than the
    border does not grow it: later passes find nothing new."""
    body = ('<setmkbound mk="0"/><redraw/>'                   # every node mkbound 0
            '<setmkbound mk="5"/><drawpoint x="1" y="4" z="4"/>'
            '<setmkbound mk="6"/><drawpoint x="7" y="4" z="4"/>'
            '<setmkfluid mk="0"/><redrawnear times="3" targettp="bound" targetmk="0" '
            'bordertp="bound" bordermk="5"/>')
    d = draw(tmp_path, body, **CUBE)
    assert mk_nodes(d, 0, fluid=True) == lattice_box((0, 3, 3), (2, 5, 5)) - {(1, 4, 4)}
    assert mk_nodes(d, 6) == {(7, 4, 4)}


def test_redrawnear_grows_a_pen_equal_to_the_border(tmp_path):
    """RedrawComplex's letters: a pen equal to the border grows it one layer a pass."""
    body = ('<setmkbound mk="0"/><redraw/><setmkfluid mk="2"/><drawpoint x="4" y="4" z="4"/>'
            '<redrawnear times="3" targettp="bound" bordertp="fluid" bordermk="2"/>')
    d = draw(tmp_path, body, **CUBE)
    assert mk_nodes(d, 2, fluid=True) == lattice_box((1, 1, 1), (7, 7, 7))


def test_redrawnearbox_limits_the_targets_not_the_border(tmp_path):
    body = ('<setmkbound mk="0"/><drawpoint x="4" y="4" z="4"/><setmkbound mk="1"/>'
            '<redrawnearbox targettp="void" bordertp="bound" bordermk="0">'
            '<point x="5" y="0" z="0"/><size x="3" y="8" z="8"/></redrawnearbox>')
    d = draw(tmp_path, body, **CUBE)
    assert mk_nodes(d, 1) == lattice_box((5, 3, 3), (5, 5, 5))


def test_redrawnear_in_2d_takes_eight_neighbours(tmp_path):
    body = ('<setmkbound mk="0"/><drawpoint x="4" y="0" z="4"/><setmkbound mk="1"/>'
            '<redrawnear targettp="void" bordertp="bound"/>')
    d = draw(tmp_path, body, pmin=(0, 0, 0), pmax=(9, 0, 9))
    assert {(p[0], p[2]) for p in mk_nodes(d, 1)} == \
        {(x, z) for x in (3, 4, 5) for z in (3, 4, 5)} - {(4, 4)}


def test_redrawnear_times_zero_and_dirfilter_all(tmp_path):
    body = ('<setmkbound mk="0"/><drawpoint x="4" y="4" z="4"/><setmkbound mk="1"/>'
            '<redrawnear times="0" targettp="void" bordertp="bound"/>'
            '<redrawnear targettp="void" bordertp="bound"><dirfilter>all</dirfilter></redrawnear>')
    d = draw(tmp_path, body, **CUBE)
    assert len(mk_nodes(d, 1)) == 26


@pytest.mark.parametrize("command, expected", [
    ('<redrawnear targettp="void" bordertp="bound"><dirfilter>top | right</dirfilter></redrawnear>',
     "dirfilter"),
    ('<redraw mkfluid="0" mkbound="0"/>', "both mkfluid and mkbound"),
    ('<redrawnear targettp="water" bordertp="bound"/>', "targettp='water' is not recognised"),
    ('<redrawnear bordertp="bound"/>', "missing attribute 'targettp'"),
    ('<redrawnear targettp="void" bordertp="bound" times="-1"/>', "times='-1' is below 0"),
    ('<rotate ang="30" x="0" y="0" z="1"/><scale x="2" y="1" z="1"/><redrawbox><point x="0" y="0" z="0"/>'
     '<size x="1" y="1" z="1"/></redrawbox>', "under a non-uniform scale"),
    ('<redrawbox><point x="0" y="0" z="0"/></redrawbox>', "<size> or <endpoint>"),
])
def test_bad_redraw_commands_name_the_problem(tmp_path, command, expected):
    with pytest.raises(CaseError, match=None) as err:
        draw(tmp_path, '<setmkbound mk="1"/>' + command, **CUBE)
    assert expected in str(err.value)


def test_oblique_line_takes_the_nodes_within_0_6_dp():
    """A line takes the nodes within 0.6 dp of it: along an axis or a 45-degree diagonal one node
    a step, an oblique one a second node where it passes near the middle of two (GenCase's
    RedrawSimple record: 157 nodes, a Bresenham rule 127)."""
    from sphdvi.case.draw.lattice import Lattice
    from sphdvi.case.draw.raster import segment_pieces
    lat = Lattice(1.0, (0, 0, 0), (20, 0, 20))

    def line(a, b):
        pieces = segment_pieces(lat, np.array([[a, b]], dtype=float))
        return {tuple(map(int, n)) for p in pieces for n in p.nodes}

    assert len(line((0, 0, 0), (10, 0, 0))) == 11
    assert len(line((0, 0, 0), (10, 0, 10))) == 11
    got = line((0, 0, 0), (10, 0, 5))           # slope 1/2: passes half-way between two nodes
    assert {(x, z) for x, _, z in got} == {(x, z) for x in range(11) for z in range(6)
                                           if abs(2 * z - x) / np.sqrt(5) <= 0.6}
    assert len(got) == 16


def test_a_redrawn_floating_body_gets_no_analytic_mass(tmp_path):
    """A floating body drawn as one box has an analytic mass beside the particle one, unless a
    later redraw may have changed its nodes (here the void pen takes its outer layer)."""
    from casetext import case_xml, write_case

    from sphdvi.case.gencase import build_case
    box_cmd = ('<setmkbound mk="3"/><drawbox><boxfill>solid</boxfill><point x="0.3" y="0" z="0.3"/>'
               '<size x="0.4" y="0" z="0.4"/></drawbox>')
    floatings = '<floatings><floating mkbound="3" rhopbody="500"/></floatings>'
    kw = dict(dp="0.02", pointmin=("0", "0", "0"), pointmax=("1", "0", "1"), casedef_extra=floatings)
    plain = build_case(write_case(tmp_path, case_xml(commands=box_cmd, **kw), "a.xml"), str(tmp_path / "a"))
    eroded = ('<setmkvoid/><redrawnear targettp="bound" targetmk="3" bordertp="void"/>')
    r = build_case(write_case(tmp_path, case_xml(commands=box_cmd + eroded, **kw), "b.xml"), str(tmp_path / "b"))
    assert plain.bodies[0].analytic["mass"] == pytest.approx(500 * 0.4 * 0.4)
    assert r.bodies[0].analytic is None
    assert len(r.particles["mk"]) == 19 * 19        # 21 x 21 less the outer ring


@pytest.mark.parametrize("command, message", [
    ('<setmkbound mk="1"/><redraw mkfluid="4"/>', "changed no node: no node holds mkfluid 4"),
    ('<setmkbound mk="1"/><redrawbox mkbound="0"><point x="6" y="6" z="6"/><size x="1" y="1" z="1"/>'
     '</redrawbox>', "no node holds mkbound 0 (other than the pen's) within its box"),
    ('<setmkbound mk="0"/><redraw/><redraw/>', "every node already holds the pen's label"),
    ('<setmkbound mk="1"/><redrawnear targettp="void" bordertp="fluid"/>',
     "no void node (other than the pen's) touches a fluid node"),
])
def test_a_redraw_that_changes_nothing_is_warned(tmp_path, command, message):
    """A misspelt label, or one not drawn yet, made a redraw do nothing without a word."""
    from test_draw_compat import warnings_of
    _, warns = warnings_of(tmp_path, '<setmkbound mk="0"/>' + box((0, 0, 0), (2, 2, 2)) + command, **CUBE)
    assert any(message in str(w) for w in warns), [str(w) for w in warns]


def test_a_redraw_that_changes_nodes_is_not_warned(tmp_path):
    from test_draw_compat import warnings_of
    _, warns = warnings_of(tmp_path, '<setmkbound mk="0"/>' + box((0, 0, 0), (2, 2, 2))
                           + '<setmkbound mk="1"/><redraw mkbound="0"/><redrawnear times="0" '
                           'targettp="void" bordertp="bound"/>', **CUBE)
    assert not warns


def test_redraw_boxes_under_a_rotation_take_the_turned_solid_box(tmp_path):
    """<redrawbox> and <redrawnearbox> under a rotation change the nodes a solid <drawbox> under
    that rotation draws, and none outside it."""
    turn = '<rotate ang="25" x="0" y="0" z="1"/>'
    box = '<point x="3" y="1" z="2"/><size x="4" y="3" z="4"/>'
    everything = '<setmkbound mk="0"/><redraw/>'
    d = draw(tmp_path, everything + f'<setmkbound mk="1"/>{turn}<redrawbox>{box}</redrawbox>', **CUBE)
    solid = draw(tmp_path, f'<setmkbound mk="1"/>{turn}<drawbox><boxfill>solid</boxfill>{box}</drawbox>', **CUBE)
    assert mk_nodes(d, 1) == mk_nodes(solid, 1) and len(mk_nodes(d, 1)) > 50
    # a node near a corner of the turned box grows mk 1 around it, within the box only
    from sphdvi.case.draw import transform as tf
    corner = tf.apply(tf.rotation_line(25, np.zeros(3), (0, 0, 1)), np.array([[3.6, 1.6, 2.6]]))[0]
    near = (everything + '<setmkbound mk="2"/><drawpoint x="{}" y="{}" z="{}"/>'.format(*corner)
            + f'<setmkbound mk="1"/>{turn}<redrawnearbox times="2" targettp="bound" targetmk="0" '
            f'bordertp="bound" bordermk="2">{box}</redrawnearbox>')
    d = draw(tmp_path, near, **CUBE)
    grown = mk_nodes(d, 1)
    assert grown and grown <= mk_nodes(solid, 1)
    seed = next(iter(mk_nodes(d, 2)))
    ring = {tuple(int(v) for v in np.add(seed, s)) for s in itertools.product((-1, 0, 1), repeat=3)} - {seed}
    assert grown == ring & mk_nodes(solid, 1) and grown != ring     # the box cuts the ring

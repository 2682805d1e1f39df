"""Drawing rules against the numbers GenCase wrote for third-party cases (its logs and output
files; the repositories and paths are named at each test). The geometry is the case's own, cut to
the part the record speaks of; the numbers are GenCase's.

* The domain: an axis holds floor((pointmax - pointmin)/dp) nodes, none on pointmax.
* A closed sphere or cylinder in ``full`` mode fills the nodes within r + 0.6 dp.
* ``<layers>`` of a box of faces: each face moved along its normal and widened towards its drawn
  neighbours only.
* A box's corner half-way between two nodes goes to the node its floating-point lattice
  coordinate (x - origin)/dp rounds to, with no tolerance: GenCase's "ties" fall either way.
"""
from __future__ import annotations

import numpy as np
import pytest
from casetext import write_case

from sphdvi.case.draw.lattice import Lattice
from sphdvi.case.gencase import build_case

CONSTANTS = ('<constantsdef><gravity x="0" y="0" z="-9.81"/><rhop0 value="1000"/><hswl value="0" '
             'auto="true"/><gamma value="7"/><speedsystem value="0" auto="true"/><coefsound value="20"/>'
             '<speedsound value="0" auto="true"/><coefh value="1.2"/><cflnumber value="0.2"/></constantsdef>')


def case(definition: str, commands: str, extra: str = "") -> str:
    return (f'<case><casedef>{CONSTANTS}<mkconfig boundcount="240" fluidcount="9"/><geometry>'
            f'{definition}<commands><mainlist>{commands}</mainlist></commands></geometry>{extra}'
            '</casedef><execution><parameters><parameter key="TimeMax" value="0.1"/>'
            '<parameter key="TimeOut" value="0.01"/></parameters></execution></case>')


def counts(r) -> dict:
    mk = np.asarray(r.particles["mk"])
    return {int(m): int((mk == m).sum()) for m in np.unique(mk)}


@pytest.mark.parametrize("pmin, pmax, dp, shape", [
    # yzhao469/DualSPHysicsAgent_v1 .../2D_DebrisFlow_Dambreak_run01/out/Case_Def.out (GenCase v5.0):
    # "Case limits: (-5,0,-5) - (105,0,45)", "Domain points: 220 x 1 x 100"
    ((-5, 0, -5), (105, 0, 45), 0.5, (220, 1, 100)),
    # ... examples/main/01_DamBreak/CaseDambreak_out/CaseDambreak.out (GenCase v5.0):
    # "(-0.05,-0.05,-0.05) - (2,1,1)", dp 0.0085: "241 x 123 x 123"
    ((-0.05, -0.05, -0.05), (2, 1, 1), 0.0085, (241, 123, 123)),
    # feynman0406/DualSPHysicsGPT CaseDambreak_Def.out and CaseSloshingHR_Def_from_xml.out (v5.4)
    ((0, 0, 0), (1.6, 0.01, 0.4), 0.01, (160, 1, 40)),
    ((-1, 0, -1), (1, 0, 1), 0.002, (1000, 1, 1000)),
])
def test_domain_points_as_gencase_logs(pmin, pmax, dp, shape):
    assert Lattice(dp, pmin, pmax).shape == shape


BOWLING = case(
    '<definition dp="0.01"><pointref x="0" y="0" z="0"/><pointmin x="0" y="1" z="-0.02"/>'
    '<pointmax x="4.3" y="1" z="6"/></definition>',
    '<setdrawmode mode="full"/><setmkbound mk="0"/><drawbeach mask="1|2|5"><point x="0" y="2" z="1"/>'
    '<point x="1.5" y="2" z="0"/><point x="4.35" y="2" z="0"/></drawbeach>'
    '<setmkbound mk="9"/><drawcylinder radius="0.25" mask="0"><point x="0.3" y="0" z="1.4"/>'
    '<point x="0.3" y="2" z="1.4"/></drawcylinder>',
    '<floatings><floating mkbound="9" relativeweight="2"/></floatings>')


def test_bowling_ball_full_cylinder(tmp_path):
    """shordyk/dualsphysics_algae examples/main/14_DEM/CaseBowling_out/CaseBowling.xml (GenCase
    v5.0.278c), its ball: a drawcylinder of r 0.25 m across the 2D plane at dp 0.01 in full mode,
    2061 particles, massbody 412.2, inertia v11 6.76028 kg m^2 (the nodes within r + 0.6 dp;
    within r: 1961)."""
    r = build_case(write_case(tmp_path, BOWLING), None)
    body = r.bodies[0]
    assert counts(r)[19] == 2061
    assert body.mass == pytest.approx(412.2, rel=1e-9)
    assert np.asarray(body.inertia)[0][0] == pytest.approx(6.76028, rel=1e-6)


def test_bowling_beach(tmp_path):
    """CaseBowling's 2D beach (drawbeach mask 1|2|5, a 1.5 m x 1 m slope and a flat floor to
    x = 4.29): 530 particles in GenCase's record. In 2D an oblique face's band is as thick as a
    4-connected digital line, half-width (|nx| + |nz|)/2 (the plain band of half-width 1/2 gave 430)."""
    r = build_case(write_case(tmp_path, BOWLING), None)
    assert counts(r)[10] == 530


def test_rootsphysics_full_cylinders_and_sphere(tmp_path):
    """MatthiasMimault/RootSPHysicsV2_DB debug-AIA/DBG_out/DBG.xml (GenCase4 v4.0.062), the fork's
    constants left out: a fixed cylinder of r 2 and a fluid cylinder and sphere of r 1 along x, the
    2D plane at y = 0.01 off their axes, dp 0.1: 630 fixed, 1760 fluid (within r: 610 and 1587)."""
    text = case('<definition dp="0.1"><pointmin x="-2" y="0.01" z="-3"/><pointmax x="20" y="0.01" '
                'z="3"/></definition>',
                '<setdrawmode mode="full"/><setmkbound mk="0"/><drawcylinder radius="2">'
                '<point x="-1" y="0" z="0"/><point x="1" y="0" z="0"/></drawcylinder>'
                '<setmkfluid mk="0"/><drawcylinder radius="1"><point x="0" y="0" z="0"/>'
                '<point x="7.5" y="0" z="0"/></drawcylinder><drawsphere radius="1">'
                '<point x="7.5" y="0" z="0"/></drawsphere>')
    r = build_case(write_case(tmp_path, text), None)
    assert counts(r) == {1: 1760, 10: 630}


def test_open_tank_layers(tmp_path):
    """yupengxiang/DualSPHysics F1_DUAL_FINITE_CENTER_DP001_003 (GenCase v5.4.354.01, its
    dbc_alternative_001 record): the tank, boxfill all^top with <layers vdp="0,1,2"> on a lattice
    through 0.005 at dp 0.01, is 361,104 particles from (-0.015, -0.025, -0.025) to
    (3.255, 1.025, 0.995): its layers closed at the edges and corners, its walls ending at the
    node below their top z = 1.0 (half-way between two nodes)."""
    text = case('<definition dp="0.01"><pointref x="0.005" y="0.005" z="0.005"/><pointmin x="-1.005" '
                'y="-1.005" z="-1.005"/><pointmax x="3.305" y="1.105" z="1.105"/></definition>',
                '<setdrawmode mode="full"/><setmkbound mk="0"/><drawbox><boxfill>all^top</boxfill>'
                '<point x="0" y="-0.005" z="-0.005"/><endpoint x="3.23" y="1.005" z="1"/>'
                '<layers vdp="0,1,2"/></drawbox>')
    r = build_case(write_case(tmp_path, text), None)
    pos = np.asarray(r.particles["pos"])
    assert len(pos) == 361104
    assert np.allclose(pos.min(axis=0), [-0.015, -0.025, -0.025], atol=1e-6)
    assert np.allclose(pos.max(axis=0), [3.255, 1.025, 0.995], atol=1e-6)


def test_box_on_half_node_ties_rounds_as_the_floating_point_value(tmp_path):
    """yupengxiang/DualSPHysics F1_DUAL_FINITE_INIT_DP001_001 (GenCase v5.4, its
    native_preflight_audit_001 record): the fluid box from (2.105, 0.005, 0.005), every corner
    half-way between two nodes of the lattice through 0 at dp 0.01 with pointmin -1, starts at
    (2.11, 0.0, 0.0) and is 112 x 101 x 56 = 633,472 particles; relative to the lattice origin,
    2.105 is 310.5 and 0.005 is 100.49999999999999 in double precision. Cut to a 0.2 m cube at
    the same corner (its far corner, as the record's, 1e-6 m past a tie): 21^3 from (2.11, 0, 0). sphdvi took every tie upwards (20 x 20 x 20
    from (2.11, 0.01, 0.01)); the whole case is now GenCase's 997,590 particles."""
    text = case('<definition dp="0.01"><pointref x="0" y="0" z="0"/><pointmin x="-1" y="-1" z="-1"/>'
                '<pointmax x="3.3" y="1.1" z="1.1"/></definition>',
                '<setdrawmode mode="full"/><setmkfluid mk="0"/><drawbox><boxfill>solid</boxfill>'
                '<point x="2.105" y="0.005" z="0.005"/><size x="0.200001" y="0.190001" z="0.190001"/></drawbox>')
    r = build_case(write_case(tmp_path, text), None)
    pos = np.asarray(r.particles["pos"])
    assert len(pos) == 21 ** 3
    assert np.allclose(pos.min(axis=0), [2.11, 0.0, 0.0], atol=1e-9)
    assert np.allclose(pos.max(axis=0), [2.31, 0.2, 0.2], atol=1e-9)


def test_layers_on_half_node_ties_keep_every_layer(tmp_path):
    """yupengxiang/DualSPHysics F2_SLOT_TRANSFER anchor (GenCase v5.4, its preflight-v1 record):
    a tank 1.8 x 0.6 x 0.9 m from the origin, boxfill bottom|left|right|front|back with
    <layers vdp="0,1,2">, at dp 0.0075 with pointref dp/2 (DesignSPHysics 0.8's default):
    every face half-way between two nodes. Each layer lies a whole number of nodes from the
    first, which makes 245 x 85 x 123 - 239 x 79 x 120 = 295,755 particles. GenCase wrote
    296,421 (no rule found gives it); moved in world coordinates, the layer dp out from the y = 0
    face came to 25.499999999999996 lattice units against the face's 26.5 and skipped a node:
    268,389, a wall with a layer missing."""
    text = case('<definition dp="0.0074999999999999997"><pointmin x="-0.30" y="-0.20" z="-0.20"/>'
                '<pointmax x="2.00" y="0.80" z="1.30"/><pointref x="0.0037499999999999999" '
                'y="0.0037499999999999999" z="0.0037499999999999999"/></definition>',
                '<setdrawmode mode="full"/><setmkbound mk="0"/><drawbox>'
                '<boxfill>bottom | left | right | front | back</boxfill><point x="0" y="0" z="0"/>'
                '<size x="1.8" y="0.59999999999999998" z="0.90000000000000002"/><layers vdp="0,1,2"/></drawbox>')
    r = build_case(write_case(tmp_path, text), None)
    pos = np.asarray(r.particles["pos"])
    assert len(pos) == 245 * 85 * 123 - 239 * 79 * 120 == 295755
    for axis in range(3):
        rows = np.unique(np.round(pos[:, axis] / 0.0075 - 0.5).astype(int))
        assert np.array_equal(rows, np.arange(rows[0], rows[-1] + 1))      # no empty row between layers


@pytest.mark.parametrize("maxsizeh, with_normal", [('<maxsizeh value="0.0" />', 5676),
                                                  ('<maxsizeh v="2.1" />', 5676),
                                                  ('<maxsizeh v="0.4" />', None)])
def test_norgeometry_maxsizeh(tmp_path, maxsizeh, with_normal):
    """<norgeometry><maxsizeh> (GenCase v5.4's template; DesignSPHysics 0.8 writes value="0.0"):
    0 is no limit, a limit beyond distanceh changes nothing, a shorter one leaves the particles
    whose normal would be longer without one (CaseSloshingHR's record: 5,676 of its 5,688 wall
    particles get a normal with distanceh 2)."""
    import gencase_output_cases as cases
    text = cases.CASESLOSHINGHR_V54.replace('<distanceh v="2.0"', maxsizeh + '<distanceh v="2.0"')
    (tmp_path / "SloshingMotionData.dat").write_text("0 0\n100 0\n")
    r = build_case(write_case(tmp_path, text, "Slosh.xml"), str(tmp_path / "out"))
    n = int(np.count_nonzero(np.linalg.norm(r.normals, axis=1) > 0))
    if with_normal is None:
        assert 0 < n < 5676 and np.linalg.norm(r.normals, axis=1).max() <= 0.4 * r.constants.h * (1 + 1e-9)
    else:
        assert n == with_normal

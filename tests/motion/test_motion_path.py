"""<mvpathfile>: positions and three Euler angles from one file (DualSPHysics v5.4's JMotionMovPathFile:
``fieldx``-``z``, ``fieldang1``-``3``, ``center``, ``movecenter``, ``intrinsic``, ``axes``), read as sphdvi
reads ``mvrectfile`` and ``mvrotadvfile``: the displacement and the turn relative to the file's first
row, about a centre that travels with the path (``movecenter``, the default) or stays put."""
import numpy as np
import pytest
from lxml import etree

from sphdvi.case.reader import read_motion
from sphdvi.case.xmldoc import CaseReader
from sphdvi.errors import CaseError
from sphdvi.motion import MotionSet, chain_transform, euler_matrix, euler_rate

FILE = "time;x;y;z;a1;a2;a3\n0;0.1;0.2;0.3;5;-10;15\n2;0.5;-0.2;0.7;45;30;-25\n"
C = np.array([1.0, 2.0, 3.0])
X0 = np.array([[2.0, 2.5, 3.5], [0.0, 0.0, 0.0], [1.0, 2.0, 3.0]])


def read(tmp_path, body, files=None, is2d=False):
    for name, content in (files or {"p.csv": FILE}).items():
        (tmp_path / name).write_text(content)
    y = '<pointmin x="0" y="0" z="0"/><pointmax x="1" y="0" z="1"/>' if is2d else ""
    xml = (f'<casedef>\n<geometry><definition dp="0.1">{y}</definition></geometry>'
           f'<motion><objreal ref="1"><begin mov="1" start="0"/>\n{body}\n</objreal></motion>\n</casedef>')
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    return read_motion(reader, etree.fromstring(xml)), reader


def path(movecenter='<movecenter value="true"/>', file='<file name="p.csv" fields="7"/>', axes="ZYX",
         intrinsic="true", center='<center x="1" y="2" z="3"/>'):
    return (f'<mvpathfile id="1" duration="100" anglesunits="degrees">{file}{center}{movecenter}'
            f'<intrinsic value="{intrinsic}"/><axes value="{axes}"/></mvpathfile>')


def _expected(t, movecenter):
    """The closed form at t in [0, 2] (the rows' values interpolated linearly)."""
    f = t / 2
    d = f * np.array([0.4, -0.4, 0.4])
    a0 = np.radians([5, -10, 15])
    a = a0 + f * np.radians([40, 40, -40])
    R = euler_matrix(a, "ZYX", True) @ euler_matrix(a0, "ZYX", True).T
    if movecenter:
        return C + d + (X0 - C) @ R.T
    return C + (X0 + d - C) @ R.T


@pytest.mark.parametrize("movecenter,flag", [(True, '<movecenter value="true"/>'), (True, ""),
                                             (False, '<movecenter value="false"/>')])
def test_the_path_and_the_turn_from_the_first_row(tmp_path, movecenter, flag):
    """The object is where it is drawn at t = 0 (the first row is not zero), then displaced by the
    positions and turned by the angles relative to the first row; movecenter (the default) carries
    the centre along the path, without it the travelled object turns about the fixed centre."""
    (m,), _ = read(tmp_path, path(movecenter=flag))
    mv = m["movements"][0]
    assert mv["fields"] == {"fieldtime": 0, "fieldx": 1, "fieldy": 2, "fieldz": 3, "fieldang1": 4, "fieldang2": 5,
                            "fieldang3": 6}
    assert mv["movecenter"] is movecenter
    np.testing.assert_allclose(chain_transform(m, 0.0).apply(X0)[0], X0, atol=1e-14)
    for t in (0.5, 1.3, 2.0):
        np.testing.assert_allclose(chain_transform(m, t).apply(X0)[0], _expected(t, movecenter), atol=1e-13)
    # held at the last row, at rest
    x, v = chain_transform(m, 5.0).apply(X0)
    np.testing.assert_allclose(x, _expected(2.0, movecenter), atol=1e-13)
    np.testing.assert_allclose(v, 0, atol=1e-14)
    np.testing.assert_allclose(MotionSet([m]).transform(1, 1.3).apply(X0)[0], _expected(1.3, movecenter),
                               atol=1e-13)


@pytest.mark.parametrize("movecenter", [True, False])
def test_the_velocity_is_the_rate_of_the_positions(tmp_path, movecenter):
    """v(x) = V + Ω × (x − c) against central differences of the closed form inside a row segment."""
    (m,), _ = read(tmp_path, path(movecenter=f'<movecenter value="{str(movecenter).lower()}"/>'))
    h = 1e-6
    for t in (0.4, 1.1):
        v = chain_transform(m, t).apply(X0)[1]
        np.testing.assert_allclose(v, (_expected(t + h, movecenter) - _expected(t - h, movecenter)) / (2 * h),
                                   atol=1e-7)
        W = chain_transform(m, t).W
        a = np.radians([5, -10, 15]) + t / 2 * np.radians([40, 40, -40])
        np.testing.assert_allclose(W, euler_rate(a, np.radians([20, 20, -20]), "ZYX", True), atol=1e-14)


def test_positions_only_is_mvrectfile_and_angles_only_is_mvrotadvfile(tmp_path):
    files = {"p.csv": FILE}
    (pth,), _ = read(tmp_path, path(file='<file name="p.csv" fields="7" fieldx="1" fieldy="2" fieldz="3"/>'), files)
    (rect,), _ = read(tmp_path, '<mvrectfile id="1" duration="100"><file name="p.csv" fields="7" fieldx="1" '
                                'fieldy="2" fieldz="3"/></mvrectfile>', files)
    (turn,), _ = read(tmp_path, path(file='<file name="p.csv" fields="7" fieldang1="4" fieldang2="5" fieldang3="6"/>',
                                     movecenter=""), files)
    (adv,), _ = read(tmp_path, '<mvrotadvfile id="1" duration="100"><file name="p.csv" fields="7" fieldang1="4" '
                               'fieldang2="5" fieldang3="6"/><center x="1" y="2" z="3"/><intrinsic value="true"/>'
                               '<axes value="ZYX"/></mvrotadvfile>', files)
    for t in (0.7, 2.5):
        for a, b in ((pth, rect), (turn, adv)):
            xa, va = chain_transform(a, t).apply(X0)
            xb, vb = chain_transform(b, t).apply(X0)
            np.testing.assert_allclose(xa, xb, atol=1e-14)
            np.testing.assert_allclose(va, vb, atol=1e-14)


@pytest.mark.parametrize("body, element, match", [
    (path(movecenter='<movecenter value="maybe"/>'), "movecenter", "movecenter"),
    (path().replace("<center", '<axisp1 x="0" y="0" z="0"/><center'), "axisp1", "unknown element <axisp1>"),
    (path(axes="XXY"), "axes", "axes value='XXY'"),
    (path(file='<file name="p.csv" fields="7" fieldx="7"/>'), "file", "fieldx=7 is not a column"),
])
def test_reader_refusals(tmp_path, body, element, match):
    with pytest.raises(CaseError, match=match) as e:
        read(tmp_path, body)
    assert e.value.element == element


def test_2d_warns_of_motion_out_of_the_plane(tmp_path):
    _, reader = read(tmp_path, path(axes="YXZ"), is2d=True)
    (w,) = [w for w in reader.warnings if "out of the x-z plane" in w]
    assert "the file's y column (fieldy); angles about X and Z from the file" in w
    _, reader = read(tmp_path, path(axes="YXZ", file='<file name="p.csv" fields="7" fieldx="1" fieldz="3" '
                                                     'fieldang1="4"/>'), is2d=True)
    assert not [w for w in reader.warnings if "out of the x-z plane" in w]


def test_2d_constant_columns_are_not_warned(tmp_path):
    """A 2D ship-motion file whose y, roll and yaw columns hold zeros (the 7-column default layout):
    nothing moves out of the x-z plane, so nothing is warned."""
    flat = "0;0.1;0;0.3;0;5;0\n2;0.5;0;0.7;0;-10;0\n"
    _, reader = read(tmp_path, path(axes="ZYX"), files={"p.csv": flat}, is2d=True)
    assert not [w for w in reader.warnings if "out of the x-z plane" in w]

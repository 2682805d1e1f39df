"""<mvrotadvfile>: three Euler angles from a file (axes, intrinsic or fixed axes, a centre), the
orientation relative to the file's first row, its angular velocity, and the reader's checks."""
import math

import numpy as np
import pytest
from lxml import etree

from sphdvi.case.reader import read_motion
from sphdvi.case.xmldoc import CaseReader
from sphdvi.errors import CaseError
from sphdvi.motion import _rotation, chain_transform, euler_matrix, euler_rate

E = np.eye(3)


def read(tmp_path, body, files, is2d=False):
    for name, content in files.items():
        (tmp_path / name).write_text(content)
    y = '<pointmin x="0" y="0" z="0"/><pointmax x="1" y="0" z="1"/>' if is2d else ""
    xml = (f'<casedef>\n<geometry><definition dp="0.1">{y}</definition></geometry>'
           f'<motion><objreal ref="1"><begin mov="1" start="0"/>\n{body}\n</objreal></motion>\n</casedef>')
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    return read_motion(reader, etree.fromstring(xml)), reader


def rotadv(axes="XYZ", intrinsic="true", center='<center x="0" y="0" z="0"/>', file='<file name="e.csv"/>',
           units="degrees"):
    return (f'<mvrotadvfile id="1" duration="100" anglesunits="{units}">{file}{center}'
            f'<intrinsic value="{intrinsic}"/><axes value="{axes}"/></mvrotadvfile>')


def test_euler_conventions():
    """Intrinsic XYZ is Rx Ry Rz; extrinsic XYZ is Rz Ry Rx, i.e. intrinsic ZYX of the reversed
    angles; proper Euler angles (ZXZ) are accepted; each turn right-handed."""
    a, b, c = 0.3, -0.7, 1.1
    Rx, Ry, Rz = _rotation(E[0], a), _rotation(E[1], b), _rotation(E[2], c)
    np.testing.assert_allclose(euler_matrix((a, b, c), "XYZ", True), Rx @ Ry @ Rz, atol=1e-15)
    np.testing.assert_allclose(euler_matrix((a, b, c), "XYZ", False), Rz @ Ry @ Rx, atol=1e-15)
    np.testing.assert_allclose(euler_matrix((a, b, c), "XYZ", False), euler_matrix((c, b, a), "ZYX", True), atol=1e-15)
    np.testing.assert_allclose(euler_matrix((a, b, c), "ZXZ", True),
                               _rotation(E[2], a) @ _rotation(E[0], b) @ _rotation(E[2], c), atol=1e-15)
    np.testing.assert_allclose(euler_matrix((0, math.pi / 2, 0), "XYZ", True) @ E[0], [0, 0, -1], atol=1e-15)


@pytest.mark.parametrize("axes, intrinsic", [("XYZ", True), ("XYZ", False), ("ZXZ", True), ("YZX", False)])
def test_angular_velocity_is_the_rate_of_the_matrix(axes, intrinsic):
    """[ω]ₓ = Ṙ Rᵀ, against central differences."""
    a0, rate = np.array([0.4, -0.9, 1.3]), np.array([0.7, 0.2, -1.5])
    h = 1e-6
    R = euler_matrix(a0, axes, intrinsic)
    dR = (euler_matrix(a0 + h * rate, axes, intrinsic) - euler_matrix(a0 - h * rate, axes, intrinsic)) / (2 * h)
    W = dR @ R.T
    w = euler_rate(a0, rate, axes, intrinsic)
    np.testing.assert_allclose([W[2, 1], W[0, 2], W[1, 0]], w, atol=1e-8)
    np.testing.assert_allclose(W + W.T, 0, atol=1e-8)


def test_rotadvfile_turns_about_its_centre_from_the_first_rows_orientation(tmp_path):
    """At τ = 0 the object is where it is drawn although the file's first row is not zero; later it
    has turned by R(a(τ)) R(a(0))ᵀ about the centre; between rows the angles are interpolated."""
    content = "time;a1;a2;a3\n0;10;20;30\n2;50;-40;90\n"
    (m,), _ = read(tmp_path, rotadv(center='<center x="1" y="2" z="3"/>'), {"e.csv": content})
    mv = m["movements"][0]
    assert (mv["axes"], mv["intrinsic"], mv["center"]) == ("XYZ", True, [1.0, 2.0, 3.0])
    x0 = np.array([[2.0, 2.5, 3.5], [0.0, 0.0, 0.0]])
    np.testing.assert_allclose(chain_transform(m, 0.0).apply(x0)[0], x0, atol=1e-14)
    r = chain_transform(m, 1.0)
    a = np.radians([30, -10, 60])
    R = euler_matrix(a, "XYZ", True) @ euler_matrix(np.radians([10, 20, 30]), "XYZ", True).T
    c = np.array([1.0, 2.0, 3.0])
    np.testing.assert_allclose(r.apply(x0)[0], (x0 - c) @ R.T + c, atol=1e-14)
    np.testing.assert_allclose(r.W, euler_rate(a, np.radians([20, -30, 30]), "XYZ", True), atol=1e-14)


def test_one_angle_about_y_is_mvrotfile_about_y(tmp_path):
    """With only a Y angle it is the right-handed turn about +y through the centre: mvrotfile's
    turn about axisp2 -> axisp1 (DualSPHysics's sense) with axisp1 - axisp2 = +y."""
    files = {"e.csv": "0;0\n1;35\n2;-20\n"}
    (adv,), _ = read(tmp_path, rotadv(axes="YXZ", center='<center x="0.5" y="0" z="0.2"/>',
                                      file='<file name="e.csv" fields="2" fieldang1="1"/>'), files)
    (rot,), _ = read(tmp_path, '<mvrotfile id="1" duration="100"><file name="e.csv"/><axisp1 x="0.5" y="1" z="0.2"/>'
                               '<axisp2 x="0.5" y="0" z="0.2"/></mvrotfile>', files)
    x0 = np.array([[1.0, 0.0, 0.5], [0.2, 0.0, -0.3]])
    for t in (0.5, 1.0, 1.7, 3.0):
        np.testing.assert_allclose(chain_transform(adv, t).apply(x0)[0], chain_transform(rot, t).apply(x0)[0],
                                   atol=1e-14)
        np.testing.assert_allclose(chain_transform(adv, t).apply(x0)[1], chain_transform(rot, t).apply(x0)[1],
                                   atol=1e-14)


def test_radians_and_default_columns(tmp_path):
    (m,), _ = read(tmp_path, rotadv(axes="ZYX", units="radians", center=""), {"e.csv": "0 0 0 0\n1 0.5 0 0\n"})
    assert m["movements"][0]["center"] == [0.0, 0.0, 0.0]
    np.testing.assert_allclose(chain_transform(m, 1.0).R, _rotation(E[2], 0.5), atol=1e-15)


@pytest.mark.parametrize("body, element, match", [
    (rotadv(axes="XXY"), "axes", "axes value='XXY'"),
    (rotadv(axes="XYW"), "axes", "three of X, Y, Z"),
    (rotadv(axes="XY"), "axes", "axes value='XY'"),
    (rotadv().replace('<intrinsic value="true"/>', ""), "mvrotadvfile", "<intrinsic>"),
    (rotadv().replace('<axes value="XYZ"/>', ""), "mvrotadvfile", "<axes>"),
    (rotadv().replace("<center", '<axisp1 x="0" y="0" z="0"/><center'), "axisp1", "unknown element <axisp1>"),
    (rotadv(file='<file name="e.csv" fields="4" fieldang1="4"/>'), "file", "fieldang1=4 is not a column"),
])
def test_reader_refusals(tmp_path, body, element, match):
    with pytest.raises(CaseError, match=match) as e:
        read(tmp_path, body, {"e.csv": "0;0;0;0\n1;1;1;1\n"})
    assert e.value.element == element


def test_2d_warns_of_turns_out_of_the_plane(tmp_path):
    _, reader = read(tmp_path, rotadv(axes="YXZ", file='<file name="e.csv" fields="4" fieldang1="1" fieldang3="3"/>'),
                     {"e.csv": "0;0;0;0\n1;1;1;1\n"}, is2d=True)
    assert any("angles about Z from the file" in w for w in reader.warnings)
    _, reader = read(tmp_path, rotadv(axes="YXZ", file='<file name="e.csv" fields="2" fieldang1="1"/>'),
                     {"e.csv": "0;0\n1;1\n"}, is2d=True)
    assert not reader.warnings

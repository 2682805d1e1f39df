"""Random hostile <geometry> documents: only CaseError, never another exception or a file outside outdir."""
from __future__ import annotations

import os
import random

import pytest
from lxml import etree

from sphdvi.case.draw import run_geometry
from sphdvi.case.xmldoc import CaseReader
from sphdvi.errors import CaseError

VALUES = ["0", "1", "-1", "2.5", "1e308", "-1e308", "nan", "inf", "-inf", "abc", "", "#1/0",
          "#Dp*3", "1e-300", "3", "0.5", "#x", "1e9", "-0", "5", "#sqrt(-1)", "1e15"]


LAYERS = ["", '<layers vdp="0,1"/>', '<layers vdp="-1e9"/>', '<layers vdp="x"/>']


def _v(rng):
    return rng.choice(VALUES)


def _pt(rng, tag="point"):
    return f'<{tag} x="{_v(rng)}" y="{_v(rng)}" z="{_v(rng)}"/>'


def _pts(rng):
    return "".join(_pt(rng) for _ in range(rng.randint(0, 9)))


def _command(rng):
    v, pt, pts = (lambda: _v(rng)), (lambda tag="point": _pt(rng, tag)), (lambda: _pts(rng))
    makers = [
        lambda: f'<setmkfluid mk="{v()}"/>', lambda: f'<setmkbound mk="{v()}"/>',
        lambda: '<setmkvoid/>',
        lambda: f'<setdrawmode mode="{rng.choice(["full", "face", "solid", "wire", "x"])}"/>',
        lambda: (f'<drawbox><boxfill>{rng.choice(["solid", "all", "top | left", "all ^ top", "bad", ""])}'
                 f'</boxfill>{pt()}{pt(rng.choice(["size", "endpoint"]))}'
                 f'{pt("angles") if rng.random() < .3 else ""}'
                 f'{rng.choice(LAYERS)}</drawbox>'),
        lambda: f'<drawsphere radius="{v()}">{pts()}</drawsphere>',
        lambda: f'<drawcylinder radius="{v()}" mask="{rng.choice(["0", "1|2", "x", "-1"])}">{pts()}</drawcylinder>',
        lambda: f'<drawellipsoid radius="{v()}">{pts()}</drawellipsoid>',
        lambda: f'<drawellipsoid>{pt()}{pt("radius")}</drawellipsoid>',
        lambda: f'<drawprism mask="{v()}">{pts()}</drawprism>',
        lambda: f'<drawpyramid>{pts()}</drawpyramid>', lambda: f'<drawpolygon>{pts()}</drawpolygon>',
        lambda: f'<drawline>{pts()}</drawline>', lambda: f'<drawlines>{pts()}</drawlines>',
        lambda: f'<drawpoint x="{v()}" y="{v()}" z="{v()}"/>', lambda: f'<drawpoints>{pts()}</drawpoints>',
        lambda: f'<drawtriangle>{pts()}</drawtriangle>', lambda: f'<drawquadri>{pts()}</drawquadri>',
        lambda: f'<drawtrianglesfan>{pts()}</drawtrianglesfan>',
        lambda: (f'<drawtriangles><points>{pts()}</points><triangles><triangle x="{v()}" y="{v()}" '
                 f'z="{v()}"/></triangles></drawtriangles>'),
        lambda: f'<move x="{v()}" y="{v()}" z="{v()}"/>', lambda: f'<scale x="{v()}" y="{v()}" z="{v()}"/>',
        lambda: f'<rotate ang="{v()}" x="{v()}" y="{v()}" z="{v()}"/>',
        lambda: f'<rotateline ang="{v()}">{pts()}</rotateline>',
        lambda: '<matrixreset/>', lambda: '<matrixsave/>', lambda: '<matrixload/>',
        lambda: '<statesave/>', lambda: '<stateload/>',
        lambda: (f'<fillpoint x="{v()}" y="{v()}" z="{v()}"><modefill>'
                 f'{rng.choice(["void", "fluid | bound", "border", "x"])}</modefill></fillpoint>'),
        lambda: f'<fillbox x="{v()}" y="{v()}" z="{v()}"><modefill>void</modefill>{pt()}{pt("size")}</fillbox>',
        lambda: f'<newvar x="{v()}"/>', lambda: f'<setvar x="{v()}"/>', lambda: f'<printf text="[{v()}]"/>',
        lambda: (f'<shapeout file="{rng.choice(["a", "../b", "", "/x/y", "..", "c:/w"])}" '
                 f'format="{rng.choice(["vtk", "vtp", "vtu", "stl", "obj"])}"/>'),
        lambda: f'<drawfilestl file="{rng.choice(["bad.stl", "../a.stl", "/etc/passwd", "", "no.stl"])}"/>',
        lambda: f'<runlist name="L" times="{v()}"/>', lambda: '<bogus/>', lambda: '<drawwave/>',
    ]
    return rng.choice(makers)()


def _document(rng):
    body = "".join(_command(rng) for _ in range(rng.randint(1, 8)))
    # mostly valid domains, so that the commands get executed
    dp = rng.choice(["1", "0.5", "0.3"]) if rng.random() < .9 else _v(rng)
    pmin = _pt(rng, "pointmin") if rng.random() < .1 else '<pointmin x="0" y="0" z="0"/>'
    pmax = rng.choice(['<pointmax x="10" y="10" z="10"/>', '<pointmax x="10" y="0" z="10"/>']) \
        if rng.random() < .9 else _pt(rng, "pointmax")
    return (f'<geometry><definition dp="{dp}">{pmin}{pmax}</definition><commands>'
            f'<list name="L">{_command(rng)}</list><mainlist>{body}</mainlist></commands></geometry>')


@pytest.mark.parametrize("seed", range(300))
def test_random_geometry_documents(tmp_path, seed):
    rng = random.Random(seed)
    case_dir = tmp_path / "case"
    out = tmp_path / "out"
    case_dir.mkdir()
    out.mkdir()
    (case_dir / "bad.stl").write_text("solid nothing\n")
    try:
        el = etree.fromstring(_document(rng))
    except etree.XMLSyntaxError:
        return
    reader = CaseReader(str(case_dir / "case.xml"), base_dir=str(case_dir))
    try:
        run_geometry(reader, el, casename="c", outdir=str(out), max_nodes=2_000_000)
    except CaseError as exc:
        assert str(exc).startswith(str(case_dir / "case.xml"))
    assert sorted(os.listdir(tmp_path)) == ["case", "out"]
    assert os.listdir(case_dir) == ["bad.stl"]

"""A floating body too large for its periodic domain, as DualSPHysics's JSph::CalcFloatingRadius
refuses it at the start of a run: the body's radius is 1.2 times its particles' largest distance
from its centre, and a periodic length not above the largest radius stops the run ("The floating
body radius (%g [m]) is too large for periodic distance in X (%g [m])"), or only warns with the
FtIgnoreRadius parameter (audit hunt10/b2 finding 1; before, sphdvi ran such a case on)."""
import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.errors import EXIT_INPUT, InputError
from sphdvi.sph.periodic import Periodicity

from test_coupling import _coupling, case_data  # noqa: F401 (case_data: the gencased floatingbox2d)


def _period(data, length):
    """An x period of ``length`` for the case's particles."""
    per = Periodicity(["x"], data["particles"]["pos"], 0.01, {})
    per.length[0] = per.shift[0, 0] = length
    return per


def test_radius_limit_is_the_periodic_length(case_data):
    """The limit is DualSPHysics's: a period equal to the radius (1.2 x the largest particle distance
    from the centre, computed here from the particles) stops with an InputError (exit 2) naming the
    body, its radius and the period; a period just above it passes, as does one of 2 radii (half the
    period: not the limit)."""
    fb = _coupling(case_data)
    p = case_data["particles"]
    sel = fb.particles[0][0]
    radius = 1.2 * np.linalg.norm(p["pos"][sel] - fb.system.pos[0], axis=1).max()
    assert radius > 0.05
    with pytest.raises(InputError, match=rf"floating body mkbound {fb.mkbounds[0]} \('{fb.names[0]}'\): its radius, "
                                         rf"{radius:.6g} m \(1.2 x the largest distance of its particles from its "
                                         rf"centre.*\), is not below the periodic length along x, {radius:.6g} m.*"
                                         r"FtIgnoreRadius=1") as exc:
        fb.check_radius(_period(case_data, radius))
    assert exc.value.exit_code == EXIT_INPUT
    fb.check_radius(_period(case_data, radius * (1 + 1e-9)))
    fb.check_radius(_period(case_data, 2 * radius))
    fb.check_radius(None)                                              # not periodic: nothing to check


def test_ftignoreradius_warns_instead(case_data):
    """FtIgnoreRadius (any value but 0 in DualSPHysics) turns the stop into a warning, as DualSPHysics's
    Log->PrintWarning."""
    fb = _coupling(case_data)
    with pytest.warns(UserWarning, match=r"is not below the periodic length along x.*run on as FtIgnoreRadius asks"):
        fb.check_radius(_period(case_data, 0.05), ignore=True)


# 2D x-periodic channel 0.3 m long (15 dp), 0.1 m of water; a floating plate 0.06 m wide and TALL m
# tall standing in it (its radius 1.2 x its particles' half-diagonal: 0.243 m for TALL = 0.4, 0.541 m for 0.9)
CASE = """<?xml version="1.0" encoding="UTF-8" ?>
<case>
    <casedef>
        <constantsdef><gravity x="0" y="0" z="-9.81" /><rhop0 value="1000" /><coefh value="1.0" /><coefsound value="20" /></constantsdef>
        <mkconfig boundcount="240" fluidcount="9" />
        <geometry>
            <definition dp="0.02"><pointmin x="0" y="0" z="-0.1" /><pointmax x="0.3" y="0" z="1.2" /></definition>
            <commands><mainlist>
                <setmkfluid mk="0" />
                <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0.02" /><size x="0.28" y="2" z="0.1" /></drawbox>
                <setmkbound mk="0" />
                <drawbox><boxfill>bottom</boxfill><point x="0" y="-1" z="0" /><size x="0.28" y="2" z="0.2" /></drawbox>
                <setmkbound mk="1" />
                <drawbox><boxfill>solid</boxfill><point x="0.12" y="-1" z="0.2" /><size x="0.06" y="2" z="TALL" /></drawbox>
            </mainlist></commands>
        </geometry>
        <floatings><floating mkbound="1" rhopbody="500" /></floatings>
    </casedef>
    <execution>
        <parameters>
            <parameter key="XPeriodicIncZ" value="0" />
            <parameter key="StepAlgorithm" value="2" />
            <parameter key="TimeMax" value="0.002" />
            <parameter key="TimeOut" value="0.001" />
            IGNORE
            <simulationdomain><posmax z="default + 50%" /></simulationdomain>
        </parameters>
    </execution>
</case>
"""


def _run(tmp_path, name, tall, ignore=""):
    case = tmp_path / f"{name}_Def.xml"
    case.write_text(CASE.replace("TALL", tall).replace("IGNORE", ignore))
    return CliRunner().invoke(main, ["run", str(case), "-o", str(tmp_path / name), "--threads", "1", "-q"])


def test_too_tall_a_body_stops_the_run(tmp_path):
    """From the case file: the 0.9 m plate (radius 0.541 m) in the 0.3 m period stops `sphdvi run` at
    its start with exit 2 and the message; the 0.4 m one (radius 0.243 m, below the period) runs;
    with FtIgnoreRadius=1 the tall one runs too, with the warning."""
    r = _run(tmp_path, "tall", "0.9")
    assert r.exit_code == 2, r.output
    assert "floating body mkbound 1 ('floating1'): its radius, 0.541199 m" in r.output
    assert "is not below the periodic length along x, 0.3 m" in r.output
    r = _run(tmp_path, "short", "0.4")
    assert r.exit_code == 0, r.output
    with pytest.warns(UserWarning, match=r"floating body mkbound 1 .* is not below the periodic length along x, "
                                         r"0\.3 m.*run on as FtIgnoreRadius asks"):
        r = _run(tmp_path, "ignored", "0.9", '<parameter key="FtIgnoreRadius" value="1" />')
    assert r.exit_code == 0, r.output

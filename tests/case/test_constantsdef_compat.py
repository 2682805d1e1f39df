"""<constantsdef> elements as DualSPHysics's JCaseCtes::ReadXmlDef reads them: <coefficient>
(old name of <coefh>), <eps> (read, unused, warned when not 0) and <lattice> (1 only)."""
import math

import pytest

from casetext import CONSTANTS, case_xml, write_case
from sphdvi.case.gencase import build_case
from sphdvi.errors import CaseError


def build(tmp_path, constants):
    tmp_path.mkdir(parents=True, exist_ok=True)
    return build_case(write_case(tmp_path, case_xml(constants=constants)), str(tmp_path / "out"))


def test_coefficient_is_read_as_coefh(tmp_path):
    r = build(tmp_path, CONSTANTS.replace('<coefh value="1.0" />', '<coefficient value="1.2" />'))
    assert r.constants.h == pytest.approx(1.2 * math.sqrt(2) * 0.02)
    assert not any("coefficient" in w for w in r.warnings)


def test_coefh_wins_over_coefficient(tmp_path):
    r = build(tmp_path, CONSTANTS.replace('<coefh value="1.0" />',
                                          '<coefh value="1.0" /><coefficient value="1.2" />'))
    assert r.constants.h == pytest.approx(math.sqrt(2) * 0.02)
    assert any("<coefficient> is ignored" in w for w in r.warnings)


def test_coefficient_and_hdp_are_refused(tmp_path):
    consts = CONSTANTS.replace('<coefh value="1.0" />', '<coefficient value="1.2" /><hdp value="2" />')
    with pytest.raises(CaseError, match=r"both <coefficient> and <hdp>"):
        build(tmp_path, consts)


@pytest.mark.parametrize("value,warned", [("0.5", True), ("0", False)])
def test_eps_is_accepted_and_unused(tmp_path, value, warned):
    r = build(tmp_path / "eps", CONSTANTS.replace("</constantsdef>", f'<eps value="{value}" /></constantsdef>'))
    ref = build(tmp_path / "ref", CONSTANTS)
    assert r.constants.h == ref.constants.h and r.constants.b == ref.constants.b
    assert any("Eps value is not used" in w for w in r.warnings) == warned


def test_lattice_1_is_silent(tmp_path):
    r = build(tmp_path, CONSTANTS.replace("<constantsdef>", '<constantsdef><lattice bound="1" fluid="1" />'))
    assert int((r.particles["type"] == 3).sum()) == 5000
    assert not any("lattice" in w for w in r.warnings)


@pytest.mark.parametrize("attrs", ['bound="2" fluid="1"', 'bound="1" fluid="2"'])
def test_lattice_2_is_refused(tmp_path, attrs):
    """GenCase's lattice 2 puts twice the particles on a staggered lattice; sphdvi draws the
    cubic one only, so the case is refused with the line of <lattice>."""
    with pytest.raises(CaseError, match=r"lattice 2 .* not supported") as e:
        build(tmp_path, CONSTANTS.replace("<constantsdef>", f"<constantsdef><lattice {attrs} />"))
    assert e.value.line is not None


def test_coefhdp_is_ignored_and_said(tmp_path):
    """<coefhdp> is no DualSPHysics element (h/dp is <hdp value>): h stays coefh's, with a warning
    (it was accepted silently)."""
    r = build(tmp_path, CONSTANTS.replace('<coefh value="1.0" />', '<coefh value="1.0" /><coefhdp value="2" />'))
    assert r.constants.h == pytest.approx(math.sqrt(2) * 0.02)
    assert any("<coefhdp> is ignored" in w and "<hdp value=" in w for w in r.warnings)


ZERO_INPUTS = {"coefsound": ('<coefsound value="20" />', '<coefsound value="0" />', "coefsound is 0"),
               "hswl": ('<hswl value="0" auto="true" />', '<hswl value="0" auto="false" />', "hswl is 0"),
               "speedsystem": ('<speedsystem value="0" auto="true" />', '<speedsystem value="0" />',
                               "speedsystem is 0"),
               "speedsound": ('<speedsound value="0" auto="true" />', '<speedsound value="0" />',
                              "speedsound is 0")}


@pytest.mark.parametrize("name", sorted(ZERO_INPUTS))
def test_a_zero_sound_input_is_accepted_where_b_makes_it_unused(tmp_path, name):
    """Real cases give B explicitly and leave coefsound, hswl or speedsound at 0 (JCaseCtes reads them
    as they are; JSph::ConfigConstants takes c0 from B): read, unused."""
    old, new, _ = ZERO_INPUTS[name]
    assert old in CONSTANTS
    r = build(tmp_path, CONSTANTS.replace(old, new).replace("</constantsdef>", '<b value="1e5" /></constantsdef>'))
    assert r.constants.b == 1e5 and r.constants.cs0 == pytest.approx(math.sqrt(7 * 1e5 / 1000))


@pytest.mark.parametrize("name", sorted(ZERO_INPUTS))
def test_a_zero_sound_input_that_makes_c0_zero_is_refused_with_its_cause(tmp_path, name):
    old, new, cause = ZERO_INPUTS[name]
    with pytest.raises(CaseError, match=rf"<constantsdef>: the speed of sound is zero: {cause}"):
        build(tmp_path, CONSTANTS.replace(old, new))


def test_negative_sound_inputs_are_refused(tmp_path):
    with pytest.raises(CaseError, match=r"<coefsound>: value='-1' is negative"):
        build(tmp_path, CONSTANTS.replace('<coefsound value="20" />', '<coefsound value="-1" />'))

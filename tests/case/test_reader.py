"""Case reader: constants, parameters, special sections, materials, errors with file:line."""
import math
import re

import numpy as np
import pytest
from lxml import etree

from casetext import CONSTANTS, TANK_2D, case_xml, write_case
from sphdvi.case.constants import resolve_constants
from sphdvi.case.gencase import build_case
from sphdvi.case.model import ConstantsDef
from sphdvi.case.xmldoc import CaseReader, parse_xml_text, strip_disabled
from sphdvi.errors import CaseError


def build(tmp_path, **kw):
    tmp_path.mkdir(parents=True, exist_ok=True)
    return build_case(write_case(tmp_path, case_xml(**kw)), str(tmp_path / "out"))


# -- constants -----------------------------------------------------------------
def test_dambreak_2d_constants_match_gencase(tmp_path):
    """DualSPHysics GenCase on CaseDambreakVal2D at dp=0.02: 5000 fluid, 501 boundary,
    h = 0.0282843 m, B = 1 109 931 Pa."""
    r = build(tmp_path)
    t = r.particles["type"]
    assert int((t == 3).sum()) == 5000
    assert int((t != 3).sum()) == 501
    assert r.constants.h == pytest.approx(0.0282843, abs=5e-8)
    assert round(r.constants.b) == 1109931
    assert r.constants.hswl == pytest.approx(1.98)
    assert r.constants.massfluid == pytest.approx(0.4)
    assert r.constants.is2d


def test_resolve_constants_rules():
    cdef = ConstantsDef(coefh=1.2, coefsound=10.0)
    c = resolve_constants(cdef, 0.05, False, 0.0, np.array([0.0, 0.5, 1.0]))
    assert c.h == pytest.approx(1.2 * math.sqrt(3) * 0.05)
    assert c.cs0 == pytest.approx(10 * math.sqrt(9.81 * 1.0))
    assert c.b == pytest.approx(c.cs0 ** 2 * 1000 / 7)
    assert c.massfluid == pytest.approx(1000 * 0.05 ** 3)
    cdef = ConstantsDef(hdp=2.0, speedsound=50.0, b=1e5, hswl=3.0)
    c = resolve_constants(cdef, 0.1, True, 0.0, np.array([0.0]))
    # an explicit B decides c0 (DualSPHysics: Cs0 = sqrt(γ B / ρ0)), whatever speedsound says
    assert c.h == pytest.approx(0.2) and c.b == 1e5 and c.hswl == 3.0
    assert c.cs0 == pytest.approx(math.sqrt(7 * 1e5 / 1000))
    assert c.massbound == pytest.approx(1000 * 0.01)


def test_explicit_constants_and_expressions(tmp_path):
    consts = CONSTANTS.replace('<coefh value="1.0" />', '<hdp value="#1.5*2/2" />').replace(
        '<speedsound value="0" auto="true" />', '<speedsound value="#1000/20" />')
    r = build(tmp_path, constants=consts)
    assert r.constants.h == pytest.approx(1.5 * 0.02)
    assert r.constants.cs0 == pytest.approx(50.0)


def test_hydrostatic_initial_density(tmp_path):
    """rhopgradient 2: ρ = ρ0 (1 + ρ0 g (z_top − z)/B)^(1/γ) down each water column."""
    r = build(tmp_path)
    p, c = r.particles, r.constants
    fluid = p["type"] == 3
    z = p["pos"][fluid, 2]
    expected = c.rhop0 * (1 + c.rhop0 * 9.81 * (2.0 - z) / c.b) ** (1 / 7)
    assert np.allclose(p["rhop"][fluid], expected, rtol=1e-12)
    assert np.all(p["rhop"][~fluid] == 1000.0)


def test_rhopgradient_1_is_uniform(tmp_path):
    consts = CONSTANTS.replace("<gamma", '<rhopgradient value="1" /><gamma')
    r = build(tmp_path, constants=consts)
    assert np.all(r.particles["rhop"] == 1000.0)


# -- ordering, mk, types ---------------------------------------------------------
def test_particle_order_types_and_mk(tmp_path):
    r = build(tmp_path)
    t, mk = r.particles["type"], r.particles["mk"]
    assert np.all(np.diff(t.astype(int)) >= 0)
    assert set(mk[t == 3]) == {1} and set(mk[t == 0]) == {10}
    assert np.array_equal(r.particles["idp"], np.arange(t.size))


# -- parameters ---------------------------------------------------------------------
def test_parameters_defaults_and_values(tmp_path):
    r = build(tmp_path, parameters='<parameter key="Visco" value="0.02"/><parameter key="#Shifting" value="9"/>'
                                   '<parameter key="TimeMax" value="#2*Dp"/>')
    p = r.case.parameters
    assert p["Visco"] == 0.02 and p["Shifting"] == 0 and p["TimeMax"] == pytest.approx(0.04)
    assert p["StepAlgorithm"] == 1 and p["VerletSteps"] == 40 and p["RhopOutMin"] == 700
    assert r.case.parameters_set == ["Visco", "TimeMax"]


@pytest.mark.parametrize("param, fragment", [
    ('<parameter key="Visc" value="0.1"/>', "unknown parameter key 'Visc' (DualSPHysics skips a key it does not "
                                            "know; sphdvi stops, so that a misspelt key is not lost); expected 'Visco'"),
    # an unrelated key gets no 'did you mean' (PeriodicDomain was said to be 'ZPeriodicIncY'), but the remark form
    ('<parameter key="PeriodicDomain" value="1"/>', "or key=\"#PeriodicDomain\" to keep it as a remark"),
    ('<parameter key="Kernel" value="5"/>', "Kernel: 5 is not one of 1, 2"),
    ('<parameter key="StepAlgorithm" value="1.5"/>', "is not an integer"),
    ('<parameter key="TimeMax" value="abc"/>', "is not a number"),
    ('<parameter key="TimeOut" value="-1"/>', "below"),
    ('<parameter key="TimeOut" value="0"/>', "0.0 is not > 0 (TimeOut must be positive); expected a number > 0 and"),
    ('<parameter key="RhopOutMin" value="1400"/>', "RhopOutMin (1400.0) >= RhopOutMax"),
    ('<parameter key="VerletSteps" value="-1"/>', "VerletSteps: -1 is below 0"),
    ('<parameter key="CFLnumber" value="0.2"/>', "'CFLnumber' is a constant of the case"),
])
def test_parameter_errors(tmp_path, param, fragment):
    with pytest.raises(CaseError) as err:
        build(tmp_path, parameters=param)
    assert fragment in str(err.value)
    assert "Case_Def.xml:" in str(err.value)


def test_dp_is_defined_for_the_domain_points(tmp_path):
    """GenCase defines Dp before it reads pointmin/pointmax (DualSPHysics's CaseJet2D writes
    x="#-int(bx/Dp)*Dp-Dp*6"); here pointmin x = -50 dp = -1 m, as the default case's."""
    ref = build(tmp_path / "a")
    r = build(tmp_path / "b", pointmin=("#-int(1/Dp)*Dp", "0", "#-50*Dp"))
    assert r.particles["pos"].shape == ref.particles["pos"].shape
    assert np.array_equal(r.particles["pos"], ref.particles["pos"])


def test_a_domain_thinner_than_dp_in_y_is_an_error(tmp_path):
    """pointmax y = 0.001 with dp 0.02 leaves a 3D case no node along y (GenCase places
    floor((pointmax - pointmin)/dp) nodes per axis; 2D only where pointmin y = pointmax y): the
    error says so, with what a 2D case needs; a 2D case is built."""
    with pytest.raises(CaseError, match=r"<definition>: the domain holds no node along y: pointmax - pointmin "
                                        r"is 0.001 m, less than dp \(0.02 m\).*for a 2D case give pointmin "
                                        r"and pointmax the same y"):
        build(tmp_path / "a", pointmax=("4.5", "0.001", "3.5"))
    build(tmp_path / "b")


def test_schema_errors_say_what_the_attribute_holds(tmp_path):
    """An XSD pattern error names only the last pattern tried: the expected form comes from the
    attribute's type (a boolean and an mk list were both said to expect a number)."""
    from casetext import TANK_2D
    with pytest.raises(CaseError, match=r"attribute 'auto': the value 'yes please' is not valid; expected "
                                        r"true/false or 1/0"):
        build(tmp_path / "a", constants=CONSTANTS.replace('<hswl value="0" auto="true"',
                                                         '<hswl value="0" auto="yes please"'))
    with pytest.raises(CaseError, match=r"attribute 'mkbound': the value '5-' is not valid; expected an mk number, "
                                        r"a range or a list"):
        build(tmp_path / "b", commands=TANK_2D, casedef_extra='<floatings><floating mkbound="5-"/></floatings>')


def test_verlet_steps_zero_is_accepted(tmp_path):
    """DualSPHysics's v5.4 examples write VerletSteps 0 (Symplectic cases; under Verlet it
    means an Euler step every step)."""
    assert build(tmp_path, parameters='<parameter key="VerletSteps" value="0"/>').case.parameters["VerletSteps"] == 0


def test_simulation_domain(tmp_path):
    r = build(tmp_path, parameters='<simulationdomain><posmin x="default - 10%" z="-0.5"/>'
                                   '<posmax z="default + 50%"/></simulationdomain>')
    b = 0.05 * r.constants.h          # the particles (0..4, 0..3) widened by 0.05 h (BORDER_MAP)
    assert r.domain["posmin"][0] == pytest.approx(-b - 0.1 * (4 + 2 * b))
    assert r.domain["posmin"][2] == pytest.approx(-0.5)
    assert r.domain["posmax"][2] == pytest.approx(3 + b + 0.5 * (3 + 2 * b))


def test_checks_after_reading_name_the_line(tmp_path):
    """Errors gencase finds once the case is drawn name the element's line too (they gave the
    file and element only)."""
    import re as _re
    cases = [(dict(mkconfig='<mkconfig boundcount="240" fluidcount="1" />',
                   commands=TANK_2D.replace('<setmkfluid mk="0"', '<setmkfluid mk="3"')), "mkconfig",
              "mkfluid 3 is not below fluidcount=1"),
             (dict(parameters='<parameter key="RigidAlgorithm" value="3"/>'), "parameter", "RigidAlgorithm=3"),
             (dict(parameters='<simulationdomain><posmin z="5"/><posmax z="4"/></simulationdomain>'),
              "simulationdomain", "simulation domain is empty")]
    for i, (kw, element, text) in enumerate(cases):
        with pytest.raises(CaseError) as info:
            build(tmp_path / str(i), **kw)
        msg = str(info.value)
        assert _re.search(rf"Case_Def\.xml:\d+: <{element}>: ", msg) and text in msg, msg


def test_deprecated_domain_keys_as_dualsphysics(tmp_path):
    """IncZ v raises the top by v times the height (= posmax z "default + 100 v %"), DomainFixed
    fixes all six limits and DomainFixedXmin ... one each (DualSPHysics v5.4 still applies them,
    with a warning); with a <simulationdomain> they are an error."""
    ref = build(tmp_path / "a", parameters='<simulationdomain><posmax z="default + 50%"/></simulationdomain>')
    r = build(tmp_path / "b", parameters='<parameter key="IncZ" value="0.5"/>')
    assert r.domain["posmax"][2] == pytest.approx(ref.domain["posmax"][2])
    assert any("IncZ" in w and "deprecated" in w for w in r.warnings)
    r = build(tmp_path / "c", parameters='<parameter key="DomainFixed" value="-0.5:-1:-0.25:2.5:1:3"/>'
                                        '<parameter key="DomainFixedZmax" value="3.5"/>')
    lo, hi = r.domain["posmin"], r.domain["posmax"]          # (a 2D case: y is its plane)
    assert [lo[0], lo[2], hi[0], hi[2]] == pytest.approx([-0.5, -0.25, 2.5, 3.5])
    r = build(tmp_path / "d", parameters='<parameter key="DomainFixedXmin" value="0"/>')
    assert r.domain["posmin"][0] == 0.0
    with pytest.raises(CaseError) as err:
        build(tmp_path / "e", parameters='<parameter key="IncZ" value="0.5"/>'
                                        '<simulationdomain><posmax z="default + 50%"/></simulationdomain>')
    assert "IncZ cannot be combined with a <simulationdomain>" in str(err.value)
    with pytest.raises(CaseError) as err:
        build(tmp_path / "f", parameters='<parameter key="DomainFixed" value="1:2:3"/>')
    assert "expected six numbers" in str(err.value)


def test_keys_without_effect_are_warned(tmp_path):
    r = build(tmp_path / "a", parameters='<parameter key="FtSaveAce" value="1"/>'
                                        '<parameter key="FtIgnoreRadius" value="0"/>'
                                        '<parameter key="SaveExtraParts" value="10"/>')
    assert sum("has no effect in sphdvi" in w for w in r.warnings) == 2
    assert any("'FtSaveAce' has no effect" in w for w in r.warnings)


def test_divergence_cleaning_is_refused_when_switched_on(tmp_path):
    """DualSPHysics v5.4's optional divergence cleaning: off is accepted, on is a case error
    (line, element, what to do), and so is --set; its coefficient alone is warned."""
    r = build(tmp_path / "a", parameters='<parameter key="DivCleaning" value="0"/>'
                                        '<parameter key="DivCleanKp" value="1"/>')
    assert any("'DivCleanKp' has no effect" in w for w in r.warnings)
    with pytest.raises(CaseError) as err:
        build(tmp_path / "b", parameters='<parameter key="DivCleaning" value="1"/>')
    msg = str(err.value)
    assert re.search(r"Case_Def.xml:\d+: <parameter>: parameter DivCleaning: DivCleaning=1 is not supported: "
                     "divergence cleaning", msg)
    assert "0 (off) or no such parameter" in msg
    from sphdvi.errors import InputError
    from sphdvi.run_options import apply_overrides
    with pytest.raises(InputError, match="--set DivCleaning: DivCleaning=1 is not supported"):
        apply_overrides({"TimeOut": 0.1}, ["DivCleaning=1"])
    assert apply_overrides({"TimeOut": 0.1}, ["DivCleaning=0"])["DivCleaning"] == 0


def test_deprecated_deltasph_selects_molteni_diffusion(tmp_path):
    r = build(tmp_path / "a", parameters='<parameter key="DeltaSPH" value="0.12"/>')
    assert r.case.parameters["DensityDT"] == 1 and r.case.parameters["DensityDTvalue"] == 0.12
    r = build(tmp_path / "b", parameters='<parameter key="DeltaSPH" value="0"/>')
    assert r.case.parameters["DensityDT"] == 0
    with pytest.raises(CaseError) as err:
        build(tmp_path / "c", parameters='<parameter key="DeltaSPH" value="0.1"/>'
                                        '<parameter key="DensityDT" value="2"/>')
    assert "'DeltaSPH' and 'DensityDT' cannot be combined" in str(err.value)
    from sphdvi.errors import InputError
    from sphdvi.run_options import apply_overrides
    with pytest.warns(UserWarning, match="'DeltaSPH' is deprecated"):
        p = apply_overrides({"TimeOut": 0.1, "DensityDT": 0}, ["DeltaSPH=0.05"])
    assert p["DensityDT"] == 1 and p["DensityDTvalue"] == 0.05
    with pytest.raises(InputError, match="run gencase again"):
        apply_overrides({"TimeOut": 0.1}, ["IncZ=0.5"])


# -- special sections ----------------------------------------------------------------
CHRONO_BODIES = """
    <setmkbound mk="50" />
    <drawbox><boxfill>solid</boxfill><point x="2" y="-1" z="0.5" /><size x="0.2" y="2" z="0.2" /></drawbox>"""
FLOATINGS = '<floatings><floating mkbound="50" rhopbody="500" property="steel"/></floatings>'
PROPS = ('<properties><property name="steel"><Young_Modulus value="2.1e11"/><PoissonRatio value="0.3"/>'
         '<Restitution_Coefficient value="0.8"/><Kfric value="0.45"/></property>'
         '<links><link mkbound="0" property="steel"/></links></properties>')


def chrono(links=""):
    return ('<chrono><savedata value="0.05"/><collision activate="true"><distancedp value="0.5"/>'
            '<contactmethod value="0"/></collision><bodyfixed id="tank" mkbound="0" modelfile="AutoActual"/>'
            f'<bodyfloating id="box" mkbound="50" modelfile="AutoActual"/>{links}</chrono>')


def test_chrono_section(tmp_path):
    links = ('<link_hinge idbody1="box" idbody2="tank"><rotpoint x="2" y="0" z="0.6"/>'
             '<rotvector x="0" y="1" z="0"/><stiffness value="#100*2"/><damping value="5"/></link_hinge>'
             '<link_linearspring idbody1="tank" idbody2="box"><point_fb1 x="2" y="0" z="0"/>'
             '<point_fb2 x="2" y="0" z="0.5"/><stiffness value="100"/><damping value="5"/>'
             '<rest_length value="0.4"/></link_linearspring>')
    r = build(tmp_path, commands=TANK_2D + CHRONO_BODIES, casedef_extra=FLOATINGS + PROPS,
              special=chrono(links), parameters='<parameter key="RigidAlgorithm" value="3"/>')
    ch = r.case.special["chrono"]
    assert ch["collision"] == {"activate": True, "distancedp": 0.5, "contactmethod": 0}
    assert [b["id"] for b in ch["bodies"]] == ["tank", "box"]
    hinge, spring = ch["links"]
    assert hinge["type"] == "hinge" and hinge["stiffness"] == 200.0 and hinge["rotvector"] == [0, 1, 0]
    assert spring["type"] == "linearspring" and spring["rest_length"] == 0.4
    assert r.case.materials["steel"].young == 2.1e11 and r.case.materials["steel"].kfric == 0.45


def test_link_naming_unknown_body(tmp_path):
    links = '<link_spheric idbody1="box" idbody2="ghost"><rotpoint x="2" y="0" z="0.6"/></link_spheric>'
    with pytest.raises(CaseError) as err:
        build(tmp_path, commands=TANK_2D + CHRONO_BODIES,
              casedef_extra=FLOATINGS + PROPS, special=chrono(links))
    msg = str(err.value)
    assert "idbody2='ghost' names no body" in msg and "<link_spheric>" in msg and "expected one of box, tank" in msg


def test_floating_mass_from_particles(tmp_path):
    """rhopbody 500, box 0.2 x 0.2 (2D) at dp 0.02: 11 x 11 particles, mass = 500·dp²·121,
    centre at the particle mean; the analytic mass 500·0.04 = 20 is reported beside it."""
    r = build(tmp_path, commands=TANK_2D + CHRONO_BODIES, casedef_extra=FLOATINGS + PROPS)
    (b,) = r.bodies
    assert b.count == 121
    assert b.mass == pytest.approx(500 * 0.02 ** 2 * 121)
    assert b.masspart == pytest.approx(500 * 0.02 ** 2)
    assert b.center == pytest.approx([2.1, 0.0, 0.6])
    side = np.arange(11) * 0.02 - 0.1
    iyy = b.mass / 121 * 2 * 11 * np.sum(side ** 2)
    assert b.inertia[1][1] == pytest.approx(iyy)
    assert b.analytic["mass"] == pytest.approx(20.0)
    assert b.analytic["inertia"][1][1] == pytest.approx(20.0 * (0.04 + 0.04) / 12)
    # in 2D the box is a plate in the x-z plane, like its particles: I_xx + I_zz = I_yy
    ia, ip = np.diag(b.analytic["inertia"]), np.diag(b.inertia)
    assert ia[0] == pytest.approx(20.0 * 0.04 / 12) and ia[0] + ia[2] == pytest.approx(ia[1])
    assert ip[0] + ip[2] == pytest.approx(ip[1])


def test_floating_without_particles(tmp_path):
    with pytest.raises(CaseError, match="floating mkbound 50 has no particles"):
        build(tmp_path, casedef_extra=FLOATINGS + PROPS)


@pytest.mark.parametrize("extra, message", [
    ('<redumax value="-1"/>', "<redumax> is -1"), ('<overlimit value="-0.5"/>', "<overlimit> is -0.5"),
    ('<factorxyz x="1" y="-1" z="1"/>', "factors >= 0")])
def test_bad_damping_zone(tmp_path, extra, message):
    special = ('<damping><dampingzone><limitmin x="3" y="0" z="0"/><limitmax x="3.9" y="0" z="0"/>'
               f'{extra}</dampingzone></damping>')
    with pytest.raises(CaseError, match=re.escape(message)):
        build(tmp_path, special=special)


def test_unknown_material(tmp_path):
    props = '<properties><links><link mkbound="0" property="wood"/></links></properties>'
    with pytest.raises(CaseError, match="property 'wood' is not defined"):
        build(tmp_path, casedef_extra=props)
    # a floating's property as a link's (the default material was used silently before)
    for prop in ("stel", "steel + wood"):
        with pytest.raises(CaseError, match=rf"Case_Def.xml:\d+: <floating>: property '{prop.split()[-1]}' is not "
                                            r"defined; expected .* \(defined: steel\)"):
            build(tmp_path, commands=TANK_2D + CHRONO_BODIES, special=chrono(),
                  casedef_extra=FLOATINGS.replace('"steel"', f'"{prop}"') + PROPS)


def test_collision_modelfile(tmp_path):
    """With collision on, a modelfile that is not there is an error (DualSPHysics loads it; it
    passed silently before); one that is there is warned about (sphdvi collides through the
    body's particles); GenCase's own shapes pass silently."""
    def case(modelfile):
        return dict(commands=TANK_2D + CHRONO_BODIES, casedef_extra=FLOATINGS + PROPS,
                    special=chrono().replace('<bodyfloating id="box" mkbound="50" modelfile="AutoActual"/>',
                             f'<bodyfloating id="box" mkbound="50" modelfile="{modelfile}"/>'))
    with pytest.raises(CaseError, match=r"<bodyfloating>: modelfile 'nofile.obj' not found .*; expected an existing "
                                        r"\.obj/\.vtk file, or AutoActual / AutoDp"):
        build(tmp_path, **case("nofile.obj"))
    (tmp_path / "box.obj").write_text("v 0 0 0\n")
    r = build(tmp_path, **case("box.obj"))
    assert any("modelfile 'box.obj': sphdvi does not read collision meshes; body 'box'" in w for w in r.warnings)
    for auto in ("AutoDp", "Case_Mkb0050_Actual.vtk"):
        r = build(tmp_path, **case(auto))
        assert not any("modelfile '" in w for w in r.warnings), list(r.warnings)


def test_misspelt_property_value_is_warned(tmp_path):
    """A property value spelt like one sphdvi reads (Kfrik) is warned (the contact would take the
    default friction); a user's own key (colour) is not. (Collisions off: a colliding body's
    material without Kfric is an error, tests/case/test_chrono_checks.py.)"""
    props = PROPS.replace("<Kfric", '<Kfrik').replace('name="steel"', 'name="steel" colour="red"')
    r = build(tmp_path, commands=TANK_2D + CHRONO_BODIES, casedef_extra=FLOATINGS + props,
              special=chrono().replace('activate="true"', 'activate="false"'))
    assert [w for w in r.warnings if "property value" in w] == [
        w for w in r.warnings if "'Kfrik' is not read (did you mean 'Kfric'?)" in w and "<Kfrik>" in w]
    assert len([w for w in r.warnings if "property value" in w]) == 1
    assert r.case.materials["steel"].kfric is None


def test_gauges_wavepaddles_damping(tmp_path):
    special = ('<gauges><default><computedt value="0.01"/></default><velocity name="v1"><point x="0.5" y="0" z="0.5"/>'
               '</velocity><swl name="s1"><point0 x="0.2" y="0" z="0"/><point2 x="0.2" y="0" z="2"/>'
               '<pointdp coefdp="0.5"/></swl></gauges>'
               '<damping><dampingzone><limitmin x="3" y="0" z="0"/><limitmax x="3.9" y="0" z="0"/>'
               '<redumax value="20"/></dampingzone></damping>')
    r = build(tmp_path, special=special)
    g = r.case.special["gauges"]
    assert g["default"]["computedt"] == 0.01
    assert [i["name"] for i in g["items"]] == ["v1", "s1"] and g["items"][0]["point"] == [0.5, 0, 0.5]
    assert r.case.special["damping"][0]["redumax"] == 20 and r.case.special["damping"][0]["overlimit"] == 0


def test_wavepaddle_needs_motion(tmp_path):
    special = ('<wavepaddles><piston><mkbound value="0"/><depth value="1"/><waveheight value="0.1"/>'
               '<waveperiod value="1"/></piston></wavepaddles>')
    with pytest.raises(CaseError, match="wave paddle mkbound 0 has no <motion> object"):
        build(tmp_path, special=special)


def test_motion_chain(tmp_path):
    motion = ('<motion><objreal ref="0"><begin mov="1" start="0"/><mvrect id="1" duration="0.5" next="2">'
              '<vel x="1" y="0" z="0"/></mvrect><mvrotsinu id="2" duration="100" anglesunits="degrees">'
              '<freq v="1"/><ampl v="10"/><phase v="0"/><axisp1 x="0" y="0" z="0"/><axisp2 x="0" y="1" z="0"/>'
              '</mvrotsinu></objreal></motion>')
    r = build(tmp_path, casedef_extra=motion)
    (m,) = r.case.motions
    assert [x["type"] for x in m["movements"]] == ["mvrect", "mvrotsinu"]
    assert m["movements"][0]["next"] == 2 and m["movements"][1]["ampl"] == 10
    assert set(r.particles["type"][r.particles["type"] != 3]) == {1}


def test_motion_next_missing(tmp_path):
    motion = ('<motion><objreal ref="0"><begin mov="1" start="0"/><mvrect id="1" duration="1" next="7">'
              '<vel x="1" y="0" z="0"/></mvrect></objreal></motion>')
    with pytest.raises(CaseError, match="next=7, which does not exist"):
        build(tmp_path, casedef_extra=motion)


def test_initials(tmp_path):
    initials = ('<initials><velocity mkfluid="0" x="1" y="0" z="-0.5"/>'
                '<densityuniform mkfluid="0" rhop="1001"><onlypos><posmax z="0.5"/></onlypos></densityuniform>'
                '</initials>')
    r = build(tmp_path, casedef_extra=initials)
    p = r.particles
    fluid = p["type"] == 3
    assert np.all(p["vel"][fluid] == [1, 0, -0.5]) and np.all(p["vel"][~fluid] == 0)
    low = fluid & (p["pos"][:, 2] <= 0.5)
    assert np.all(p["rhop"][low] == 1001) and np.all(p["rhop"][fluid & ~low] != 1001)


# -- XML leniency, disabled elements, warnings --------------------------------------------
def test_tinyxml_leniency():
    root = parse_xml_text('\n\n<?xml version="1.0"?>\n<case><abort if="Dp<0.1 && 1"/>% stray text\n<b/></case>', "f.xml")
    assert root[0].get("if") == "Dp<0.1 && 1" and root[1].sourceline == 5


def test_disabled_elements_removed():
    root = parse_xml_text('<case><_a/><b active="false"><c/></b><d active="true"/><e active="0"/></case>', "f")
    strip_disabled(root)
    assert [c.tag for c in root] == ["d"]
    # an `active` that is not a boolean is an error, not a drawing (it drew the box before)
    for value in ("maybe", "fals"):
        root = parse_xml_text(f'<case>\n<drawbox active="{value}"/></case>', "f.xml")
        with pytest.raises(CaseError, match=rf"f.xml:2: <drawbox>: active='{value}' is not a boolean; "
                                            "expected true/false or 1/0"):
            strip_disabled(root, "f.xml")


def test_unknown_attribute_warns(tmp_path):
    text = case_xml(parameters='<parameter key="Visco" value="0.1" colour="red"/>')
    r = build_case(write_case(tmp_path, text), str(tmp_path / "out"))
    assert any("unknown attribute 'colour'" in w and "<parameter>" in w for w in r.warnings)


def test_reader_typed_errors(tmp_path):
    root = etree.fromstring('<a n="x" i="1.5" b="maybe" v="#1/0"/>')
    rd = CaseReader(str(tmp_path / "c.xml"))
    with pytest.raises(CaseError, match="n='x' is not a number"):
        rd.num(root, "n")
    with pytest.raises(CaseError, match="is not an integer"):
        rd.integer(root, "i")
    with pytest.raises(CaseError, match="is not a boolean"):
        rd.boolean(root, "b")
    with pytest.raises(CaseError, match="division by zero"):
        rd.num(root, "v")
    with pytest.raises(CaseError, match="missing attribute 'q'"):
        rd.num(root, "q")


def test_property_file_and_user_overrides(tmp_path):
    (tmp_path / "Floating_Materials.xml").write_text(
        '<?xml version="1.0"?><properties><materials>'
        '<property name="pvc"><Young_Modulus value="3e9"/><PoissonRatio value="0.30"/>'
        '<Restitution_Coefficient value="0.60"/><Kfric value="0.45"/></property>'
        '<property name="steel"><Young_Modulus value="2.1e11"/><PoissonRatio value="0.3"/>'
        '<Restitution_Coefficient value="0.8"/><Kfric value="0.45"/><Kfric_User value="0.2"/></property>'
        '</materials></properties>')
    props = ('<properties><propertyfile file="Floating_Materials.xml" path="materials"/>'
             '<links><link mkbound="0" property="pvc"/></links></properties>')
    r = build(tmp_path, casedef_extra=props)
    assert r.case.materials["pvc"].young == 3e9 and r.case.materials["pvc"].restitution == 0.6
    assert r.case.materials["steel"].kfric == 0.2
    assert r.case.material_links[0]["mkbound"] == [0]


def test_property_attributes_and_combined_properties(tmp_path):
    """DualSPHysics's CaseSolids: a property whose value is an attribute
    (``Restitution_Coefficient_User="0.65"``) combined with a file property by
    ``property="steel + userdef01"``: the link gets steel's values with the restitution replaced."""
    from sphdvi.mechanism import _material_for
    props = ('<properties><property name="steel"><Young_Modulus value="2.1e11"/><PoissonRatio value="0.3"/>'
             '<Restitution_Coefficient value="0.8"/><Kfric value="0.45"/></property>'
             '<property name="userdef01" Restitution_Coefficient_User="0.65" comment="user value"/>'
             '<links><link mkbound="0" property="steel + userdef01"/></links></properties>')
    r = build(tmp_path, casedef_extra=props)
    assert r.case.materials["userdef01"].restitution == 0.65
    case_json = {"materials": {k: vars(v) for k, v in r.case.materials.items()},
                 "material_links": r.case.material_links}
    name, spec = _material_for(0, case_json)
    assert name == "steel + userdef01"
    assert spec == {"name": name, "friction": 0.45, "restitution": 0.65, "young": 2.1e11, "poisson": 0.3}
    assert _material_for(0, case_json, "steel")[1]["restitution"] == 0.8
    assert _material_for(7, case_json) == (None, None)


@pytest.mark.parametrize("inertia, message", [
    ('<inertia x="1" y="-2" z="1"/>', "negative principal moment"),
    ('<inertiafull><values v11="1" v12="0.5" v13="0"/><values v21="0" v22="1" v23="0"/>'
     '<values v31="0" v32="0" v33="1"/></inertiafull>', "not symmetric"),
    ('<inertiafull><values v11="1" v12="2" v13="0"/><values v21="2" v22="1" v23="0"/>'
     '<values v31="0" v32="0" v33="1"/></inertiafull>', "negative principal moment")])
def test_bad_floating_inertia(tmp_path, inertia, message):
    floatings = f'<floatings><floating mkbound="50" rhopbody="500">{inertia}</floating></floatings>'
    with pytest.raises(CaseError, match=message):
        build(tmp_path, commands=TANK_2D + CHRONO_BODIES, casedef_extra=floatings)


def test_link_of_a_body_to_itself(tmp_path):
    links = ('<link_hinge idbody1="box" idbody2="box"><rotpoint x="2" y="0" z="0.6"/>'
             '<rotvector x="0" y="1" z="0"/></link_hinge>')
    with pytest.raises(CaseError, match="idbody1 and idbody2 are both 'box'"):
        build(tmp_path, commands=TANK_2D + CHRONO_BODIES, casedef_extra=FLOATINGS + PROPS,
              special=chrono(links), parameters='<parameter key="RigidAlgorithm" value="3"/>')


def test_bad_material_values(tmp_path):
    props = ('<properties><property name="x"><PoissonRatio value="0.7"/></property></properties>')
    with pytest.raises(CaseError, match="PoissonRatio 0.7 out of range"):
        build(tmp_path, casedef_extra=props)


def test_analytic_inertia_of_rotated_box(tmp_path):
    """A 3D box rotated 30° about z: analytic inertia R diag(I) Rᵀ is printed beside the particle one."""
    commands = """
        <setmkbound mk="3" />
        <move x="0.5" y="0.5" z="0.5" />
        <rotate ang="30" x="0" y="0" z="1" />
        <drawbox><boxfill>solid</boxfill><point x="-0.2" y="-0.1" z="-0.05" /><size x="0.4" y="0.2" z="0.1" /></drawbox>"""
    r = build(tmp_path, dp="0.02", pointmin=("-0.5", "-0.5", "-0.5"), pointmax=("1.5", "1.5", "1.5"),
              commands=commands, casedef_extra='<floatings><floating mkbound="3" rhopbody="500"/></floatings>')
    (b,) = r.bodies
    a = b.analytic
    m = 500 * 0.4 * 0.2 * 0.1
    assert a["mass"] == pytest.approx(m)
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    R = np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])      # <rotate> turns DualSPHysics's way: −30° about +z
    local = np.diag([0.2 ** 2 + 0.1 ** 2, 0.4 ** 2 + 0.1 ** 2, 0.4 ** 2 + 0.2 ** 2]) * m / 12
    assert np.allclose(a["inertia"], R @ local @ R.T, rtol=1e-9, atol=1e-12)
    assert b.center == pytest.approx([0.5, 0.5, 0.5], abs=0.011)


@pytest.mark.parametrize("p2, mass, diag", [
    # across the plane (y): a disc of radius 0.1, as a 2D sphere: I_yy = m r²/2
    (("0.5", "1", "0.5"), 500 * math.pi * 0.01, np.array([0.25, 0.5, 0.25]) * 500 * math.pi * 0.01 * 0.01),
    # along x: a 0.3 × 0.2 rectangle in the x-z plane
    (("0.8", "0", "0.5"), 500 * 0.06, np.array([0.04, 0.09 + 0.04, 0.09]) * 500 * 0.06 / 12),
])
def test_analytic_mass_of_a_2d_cylinder(tmp_path, p2, mass, diag):
    """In 2D a drawcylinder is a disc (axis along y) or a rectangle (axis along x or z): its
    analytic mass and inertia are printed beside the particle values (none were in 2D)."""
    commands = f"""
        <setmkbound mk="3" />
        <drawcylinder radius="0.1"><point x="0.5" y="0" z="0.5" /><point x="{p2[0]}" y="{p2[1]}" z="{p2[2]}" />
        </drawcylinder>"""
    r = build(tmp_path, dp="0.01", pointmin=("0", "0", "0"), pointmax=("1", "0", "1"), commands=commands,
              casedef_extra='<floatings><floating mkbound="3" rhopbody="500"/></floatings>')
    (b,) = r.bodies
    assert b.analytic["mass"] == pytest.approx(mass)
    assert np.allclose(np.diag(b.analytic["inertia"]), diag, rtol=1e-12)


def test_second_order_flap_is_warned_and_first_order(tmp_path):
    """DualSPHysics's example main/08_WavesFlap asks <waveorder value="2"> of a <flap>; its format
    doc gives flaps no <waveorder> (second order is for pistons): warned, generated at first order
    (it was refused, which stopped the example)."""
    from sphdvi.case.wavepaddles_xml import read_wavepaddles
    from sphdvi.case.xmldoc import CaseReader
    from lxml import etree
    xml = ('<wavepaddles><flap><mkbound value="0"/><depth value="1"/>\n<waveorder value="2"/>'
           '<waveheight value="0.1"/><waveperiod value="1"/><flapaxis0 x="0" y="0" z="0"/>'
           '<flapaxis1 x="0" y="1" z="0"/></flap></wavepaddles>')
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    (wp,) = read_wavepaddles(reader, etree.fromstring(xml))
    assert wp["waveorder"] == 1
    (w,) = list(reader.warnings)
    assert ":2: warning: <waveorder>: second-order generation is for pistons" in w
    # a flap_spectrum asking second order: the same (its format gives it no <waveorder> either)
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    (wp,) = read_wavepaddles(reader, etree.fromstring(xml.replace("<flap>", "<flap_spectrum>").replace(
        "</flap>", '<spectrum value="jonswap"/></flap_spectrum>')))
    assert wp["waveorder"] == 1
    assert any("second-order generation is for pistons (DualSPHysics's format gives a <flap_spectrum>" in w
               for w in reader.warnings)


def test_a_wave_paddles_depth_unlike_the_water_drawn_is_warned(tmp_path):
    """<depth> 3 m for the 0.3 m of water drawn in front of the piston is warned (the waves are
    made for the depth given; it passed silently); the case's own 0.3 m is not."""
    from pathlib import Path
    flume = Path(__file__).resolve().parents[2] / "cases" / "waveflume2d" / "CaseWaveFlume2D_Def.xml"
    for depth, warned in (("0.3", False), ("3", True)):
        case = tmp_path / f"d{depth}" / "CaseWaveFlume2D_Def.xml"
        case.parent.mkdir()
        case.write_text(flume.read_text().replace('<depth value="0.3" />', f'<depth value="{depth}" />'))
        r = build_case(str(case), None, dp=0.02)
        found = [w for w in r.warnings if "differs from the water drawn in front of it" in w]
        assert bool(found) == warned, list(r.warnings)
        if warned:
            assert "<depth> 3 m of the wave paddle" in found[0] and "0.3 m deep" in found[0]


def test_particle_inertia_of_a_row_is_never_negative():
    """A row of particles along x (DualSPHysics's chrono/01 CaseDemolisher, mkbound 3: 20
    particles) has I_xx = 0; Σ r·r − Σ x² left −3.3e-17. The tensor against the direct sums."""
    from sphdvi.case.gencase import particle_inertia
    x = 8.0 + 0.05 * np.arange(20)
    pos = np.column_stack([x, np.full(20, 5.0), np.full(20, 5.2)])
    c = pos.mean(axis=0)
    I = particle_inertia(pos, c, 0.15)
    assert I[0, 0] >= 0.0 and abs(I[0, 0]) < 1e-12
    assert I[1, 1] == pytest.approx(0.15 * np.sum((x - c[0]) ** 2)) == I[2, 2]
    rng = np.random.default_rng(2)
    p = rng.normal(size=(50, 3))
    c = p.mean(axis=0)
    r = p - c
    ref = 2.0 * sum(np.dot(v, v) * np.eye(3) - np.outer(v, v) for v in r)
    assert np.allclose(particle_inertia(p, c, 2.0), ref, rtol=1e-13, atol=1e-13)

import math

import numpy as np
import pytest

from sphdvi.case.expressions import ExpressionError, Variables
from sphdvi.case.mkrange import format_mk_range, parse_mk_range


@pytest.fixture
def v():
    vs = Variables()
    vs.define("Dp", 0.01, constant=True)
    vs.define("x1", 11)
    vs.define("x2", 22)
    vs.define("x3", 33)
    return vs


@pytest.mark.parametrize("text, value", [
    ("(Dp+2)*2.8", (0.01 + 2) * 2.8),
    ("x[1]+x[1+1]+x[3]", 66.0),
    ("2^10", 1024.0),
    ("pow(2,3)+sqrt(16)", 12.0),
    ("sindg(30)", 0.5),
    ("cosdg(60)", 0.5),
    ("atan2(1,1)", math.pi / 4),
    ("eval(Dp<0.1, 7, 9)", 7.0),
    ("eval(Dp>0.1, 7, 9)", 9.0),
    ("min(3, 1, 2) + max(4, 5)", 6.0),
    ("fmod(7, 3)", 1.0),
    ("fmodr(-1, 3)", 2.0),
    ("round(2.5)", 3.0),
    ("floor(-1.5)", -2.0),
    ("abs(-3)*pi()", 3 * math.pi),
    ("log10(1000)", 3.0),
    ("Dp>0 && x1==11", True),
    ("!(Dp>0) || false", False),
])
def test_expression_values(v, text, value):
    assert v.evaluate(text) == pytest.approx(value)


@pytest.mark.parametrize("text, value", [
    # C, not Python: comparisons do not chain, < <= > >= bind tighter than == !=, ! is unary
    ("Dp!=0.1==(true||false)", True),       # GenCase_CaseTemplate.xml: (Dp!=0.1)==true
    ("Dp==0.1==(true||false)", False),
    ("1<2<1.5", True),                      # (1<2)<1.5 = 1<1.5
    ("3>2>1", False),                       # (3>2)>1 = 1>1
    ("2==2==2", False),                     # (2==2)==2 = 1==2
    ("1==1==1", True),
    ("1<2==3>2", True),                     # (1<2)==(3>2)
    ("0==1<2", False),                      # 0==(1<2)
    ("!2==1", False),                       # (!2)==1 = 0==1
    ("!0==1", True),
    ("!x1<5", True),                        # (!11)<5
    ("!1+1", 1.0),                          # (!1)+1
    ("(2||0)==1", True),                    # || gives 0 or 1
    ("1 || 0 && 0", True),                  # && before ||
    ("1 || 0 @@ 0", True),                  # @@ is && (GenericWaveTank.xml: "use_beach @@ (ang<2 || ang>90)")
    ("1 @@ (x1<2 || x1>10)", True),
    ("0 @@ (x1<2 || x1>10)", False),
    ("x1!=11 || !(x2>21)", False),
])
def test_c_operator_precedence(v, text, value):
    assert v.evaluate(text) == value


def test_roundpos(v):
    """roundpos(pos,posmin,dp) (GenCase_CaseTemplate.xml): the nearest posmin + k*dp."""
    assert v.number("roundpos(0.37, 0, 0.1)") == pytest.approx(0.4)
    assert v.number("roundpos(0.34, 0.05, 0.1)") == pytest.approx(0.35)
    assert v.number("roundpos(-0.26, 0, 0.1)") == pytest.approx(-0.3)
    assert v.number("roundpos(0.25, 0, 0.1)") == pytest.approx(0.3)     # halves up
    with pytest.raises(ExpressionError, match="dp > 0"):
        v.number("roundpos(1, 0, 0)")
    # roundposx/y/z need the lattice of <definition>
    with pytest.raises(ExpressionError, match=r"roundposx\(\) needs the particle lattice"):
        v.number("roundposx(0.3)")
    v.lattice = ((0.025, 0.0, -0.01), 0.05)
    assert v.number("roundposx(0.1)") == pytest.approx(0.125)
    assert v.number("roundposy(0.1)") == pytest.approx(0.1)
    assert v.number("roundposz(0.1)") == pytest.approx(0.09)
    assert v.copy().number("roundposz(0)") == pytest.approx(-0.01)
    with pytest.raises(ExpressionError, match="takes one argument"):
        v.number("roundposx(1, 2)")


def test_roundpos_in_a_case(tmp_path):
    """roundposx/z in the commands use the <definition> lattice (pointref-aligned here); in
    <predefinition> they are an error naming why."""
    from test_draw import draw

    from sphdvi.errors import CaseError
    body = ('<newvar X="roundposx(2.4)" Z="roundposz(3.6)"/><setmkfluid mk="0"/>'
            '<drawpoint x="#X" y="0" z="#Z"/><printf text="[X] [Z]"/>')
    d = draw(tmp_path, body, pointref=(0.5, 0, 0.5))
    assert d.messages == ["2.5 3.5"] and np.allclose(d.pos, [[2.5, 0, 3.5]])
    with pytest.raises(CaseError, match="needs the particle lattice"):
        draw(tmp_path, '<setmkfluid mk="0"/><drawpoint x="0" y="0" z="0"/>',
             predef='<predefinition><newvar X="roundposx(2.4)"/></predefinition>')


def test_wavelength_satisfies_dispersion(v):
    """L from wavelength(g,d,T) satisfies ω² = g k tanh(k d)."""
    length = v.number("wavelength(9.81, 0.4, 1.2)")
    k = 2 * math.pi / length
    omega = 2 * math.pi / 1.2
    assert omega ** 2 == pytest.approx(9.81 * k * math.tanh(k * 0.4), rel=1e-12)


@pytest.mark.parametrize("text, fragment", [
    ("Unknown+1", "unknown variable 'Unknown'"),
    ("1/0", "division by zero"),
    ("foo(1)", "unknown function 'foo()'"),
    ("__import__('os')", "unknown function"),
    ("(1+", "cannot parse"),
    ("x1.real", "unsupported syntax"),
    ("2^1e9", "exponent too large"),
    ("sqrt(-1)", "cannot evaluate"),
])
def test_expression_errors(v, text, fragment):
    with pytest.raises(ExpressionError, match=fragment.replace("(", r"\(").replace(")", r"\)")):
        v.number(text)


def test_constants_cannot_change(v):
    with pytest.raises(ExpressionError, match="constant"):
        v.define("Dp", 0.02)


def test_interpolation(v):
    assert v.interpolate("dp is [Dp*100] cm, x3=[x[3]]") == "dp is 1 cm, x3=33"


def test_interpolation_leaves_binary_noise_out(v):
    """[0.1*3] is 0.30000000000000004 in binary: the text is "0.3" (a file name built with it
    named a file that does not exist); meaningful digits stay (15 significant)."""
    v.define("a", 0.1)
    assert v.interpolate("part_[a*3].stl") == "part_0.3.stl"
    assert v.interpolate("[1/3]") == "0.333333333333333"
    assert v.interpolate("[a*1e-20]") == "1e-21"


def test_delete_pattern(v):
    v.delete("x?")
    assert "x1" not in v.values and "Dp" in v.values


@pytest.mark.parametrize("text, values", [
    ("0-3,7", [0, 1, 2, 3, 7]),
    ("5", [5]),
    (" 2 , 0-1 ", [0, 1, 2]),
    ("10-10", [10]),
])
def test_mk_range(text, values):
    assert parse_mk_range(text) == values
    assert parse_mk_range(format_mk_range(values)) == values


@pytest.mark.parametrize("text", ["", "a", "3-1", "1,,2", "-1", "1-", "70000", "0-99999999"])
def test_mk_range_errors(text):
    with pytest.raises(ValueError):
        parse_mk_range(text)


@pytest.mark.parametrize("kind", ["newvarcte", "newvar"])
def test_case_variable_named_like_a_computed_builtin_is_kept(tmp_path, kind):
    """GenCase defines H, B, MassFluid and MassBound once the fluid is drawn. A case that
    defined one of those names itself keeps its value (its later expressions mean it) and
    gets a warning; it used to stop gencase with an internal error."""
    from click.testing import CliRunner

    from sphdvi.cli import main
    from sphdvi.io.casefile import read_case_h5
    case = tmp_path / "CaseH_Def.xml"
    case.write_text(f"""<?xml version="1.0" encoding="UTF-8" ?>
<case><casedef><constantsdef><gravity x="0" y="0" z="-9.81" /><coefsound value="20" /></constantsdef>
<geometry><predefinition><{kind} H="0.2" /></predefinition>
<definition dp="0.02"><pointmin x="-0.1" y="0" z="-0.1" /><pointmax x="1" y="0" z="1" /></definition>
<commands><mainlist><setmkfluid mk="0" />
<drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="0.4" y="2" z="#H" /></drawbox>
<setmkbound mk="0" />
<drawbox><boxfill>bottom|left|right</boxfill><point x="0" y="-1" z="0" /><size x="0.4" y="2" z="#2*H" /></drawbox>
</mainlist></commands></geometry></casedef>
<execution><parameters><parameter key="TimeMax" value="#H" /></parameters></execution></case>
""")
    r = CliRunner().invoke(main, ["gencase", str(case), "-o", str(tmp_path / "out")])
    assert r.exit_code == 0, r.output
    assert "defines a variable 'H' (0.2); it is kept" in r.output
    assert read_case_h5(str(tmp_path / "out" / "CaseH.h5"))["parameters"]["TimeMax"] == pytest.approx(0.2)


def test_printf_and_abort_texts_take_hash_expressions(tmp_path):
    """DualSPHysics's examples/others/Variables/GenericWaveTank.xml prints
    ``"==>> Ursell number.............: #Ur#"`` and aborts with ``"Beach angle (#ang#) is not in the
    range"``; ``[expr]`` works as before; a ``#...#`` that is no expression stays as written."""
    from test_draw import draw

    from sphdvi.errors import CaseError
    body = ('<newvar wh="0.5" wl="4" ang="95"/><setmkfluid mk="0"/><drawpoint x="0" y="0" z="0"/>'
            '<printf text="steepness: #wh/wl#, [wl*2]; #nothing here# and # alone"/>')
    d = draw(tmp_path, body)
    assert d.messages == ["steepness: 0.125, 8; #nothing here# and # alone"]
    with pytest.raises(CaseError, match=r"<abort>: Beach angle \(95\) is not in the range"):
        draw(tmp_path, body + '<abort if="ang>90 @@ 1" text="Beach angle (#ang#) is not in the range"/>')

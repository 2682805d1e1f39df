import math

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

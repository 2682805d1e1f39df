"""Data files and values a case refers to, checked at gencase (audit hunt8/b findings 1, 2, 4, 5,
7, 10, 14): a UTF-8 byte-order mark kept out of the first row (JReadDatafile keeps that row), a
<floating> driver's file with DualSPHysics's `none` (JLinearValue's SpecialValues) read and checked
as the inline table, times that go back refused in every time table, NaN/inf in a data file an
error naming its line, a zero <rotateaxis> axis and absurd dp/masses clear case errors."""
import pytest
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)
from click.testing import CliRunner

from sphdvi.case.datafiles import read_columns, read_motion_table, read_vector_table
from sphdvi.case.gencase import build_case
from sphdvi.cli import main
from sphdvi.errors import CaseError

# a fluid block and a floating box (mkbound 1) in a tank: gencase only
FLOAT_TANK = """
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="1" y="2" z="0.5" /></drawbox>
                    <setmkbound mk="1" />
                    <drawbox><boxfill>solid</boxfill><point x="1.5" y="-1" z="0.2" /><size x="0.2" y="2" z="0.2" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | left | right | front | back</boxfill>
                        <point x="0" y="-1" z="0" /><size x="3" y="2" z="1.5" /></drawbox>"""


def float_case(tmp_path, floating="", files=None, constants=None, dp="0.05", initials=""):
    """The FLOAT_TANK case with ``floating`` inside its <floating mkbound="1">; ``files`` beside it."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    for name, text in (files or {}).items():
        (tmp_path / name).write_bytes(text if isinstance(text, bytes) else text.encode())
    extra = f'<floatings><floating mkbound="1" rhopbody="500">{floating}</floating></floatings>' + initials
    kw = {"constants": constants} if constants else {}
    return write_case(tmp_path, case_xml(dp=dp, commands=FLOAT_TANK, casedef_extra=extra,
                                         pointmin=("-0.5", "0", "-0.5"), pointmax=("3.5", "0", "2"), **kw))


def test_a_bom_does_not_cost_the_first_row(tmp_path):
    """Excel's "CSV UTF-8" starts the file with a BOM: the first row was taken for a header and
    the motion started from the second sample."""
    f = tmp_path / "m.csv"
    f.write_bytes(b"\xef\xbb\xbf0 0\n0.5 5\n1 10\n")
    a = read_motion_table(str(f), 2, {"fieldtime": 0, "fieldang": 1}, "motion data")
    assert a.tolist() == [[0.0, 0.0], [0.5, 5.0], [1.0, 10.0]]
    f.write_bytes(b"\xef\xbb\xbftime;value\n0;1\n1;2\n")       # a real header after a BOM is still one
    assert read_columns(str(f), 2, "t").tolist() == [[0.0, 1.0], [1.0, 2.0]]


@pytest.mark.parametrize("text, message", [
    ("0 1\n1 nan\n", r"x\.txt:2: .*'nan' in '1 nan' is not a finite number"),
    ("0 1\n1 1\n2 -inf\n", r"x\.txt:3: .*'-inf' in '2 -inf' is not a finite number")])
def test_non_finite_values_in_a_data_file(tmp_path, text, message):
    (tmp_path / "x.txt").write_text(text)
    with pytest.raises(CaseError, match=message):
        read_columns(str(tmp_path / "x.txt"), 2, "t")


def test_a_driver_file_with_none(tmp_path):
    """DualSPHysics's chrono/12_ExternalVelocity files: Time[s];Vel.x;Vel.y;Vel.z with `none`
    for a free component, read at gencase into the inline form (None where none)."""
    text = "Time[s];Vel.x;Vel.y;Vel.z\n0;1;none;None\n1;1;NONE;0.5\n"
    r = build_case(float_case(tmp_path, '<linearvel file="v.csv"/>', {"v.csv": text}), str(tmp_path / "g"))
    (fd,) = r.case.floatings
    assert fd.linearvel["times"] == [0.0, 1.0]
    assert fd.linearvel["values"] == [[1.0, None, None], [1.0, None, 0.5]]
    times, values = read_vector_table(str(tmp_path / "v.csv"), "v", allow_none=True)
    assert times == [0.0, 1.0] and values[1] == [1.0, None, 0.5]


@pytest.mark.parametrize("driver, text, message", [
    ('<linearvel file="v.csv"/>', "0;1;0;0\n", r"v\.csv: .*one data row \(line 1\)"),
    ('<linearvel file="v.csv"/>', "Time;x;y;z\n", r"v\.csv: .*no data rows"),
    ('<linearvel file="v.csv"/>', "0;1;0;0\n1;x;0;0\n", r"v\.csv:2: .*'1;x;0;0' is not numeric"),
    ('<linearvel file="v.csv"/>', "0;1;0;0\nnone;1;0;0\n", r"v\.csv:2: .*the time is none"),
    ('<linearvel file="v.csv"/>', "0;1;0;0\n1;inf;0;0\n", r"v\.csv:2: .*'inf' in '1;inf;0;0' is not a finite"),
    ('<linearforce file="v.csv"/>', "0;1;0;0\n1;1;none;0\n", r"v\.csv:2: .*'1;1;none;0' is not numeric"),
    ('<linearvel file="v.csv"/>', "1;0;0;0\n0;5;0;5\n",
     r"v\.csv:2: .*times are not in increasing order \(time 0 after 1 on line 1\)"),
    ('<angularforce file="v.csv"/>', "0;0;0;0\n2;0;0;0\n1;0;0;0\n", r"v\.csv:3: .*times are not in increasing order"),
])
def test_bad_driver_files_at_gencase(tmp_path, driver, text, message):
    """A malformed driver file is a CaseError at gencase naming the case line, the element and the
    file's line (it came at run time, without the case line, and 'none' rows were dropped as
    headers); times that go back are refused in the inline table's words."""
    with pytest.raises(CaseError, match=r"Case_Def\.xml:\d+: <\w+>: .*" + message):
        build_case(float_case(tmp_path, driver, {"v.csv": text}), str(tmp_path / "g"))


def test_inline_driver_times_message_is_the_files(tmp_path):
    inline = '<linearvel><vel time="1" x="0" y="0" z="0"/><vel time="0" x="5" y="0" z="5"/></linearvel>'
    with pytest.raises(CaseError, match="times are not in increasing order"):
        build_case(float_case(tmp_path, inline), str(tmp_path / "g"))


def test_nan_in_an_acctimesfile(tmp_path):
    """A NaN acceleration passed gencase and the run 'blew up' (exit 3)."""
    from run.test_accinputs_case import BLOCKS, FLOAT, PARAMS
    (tmp_path / "push.csv").write_text("0 1 0 0 0 0 0\n1 nan 0 0 0 0 0\n")
    case = write_case(tmp_path, case_xml(dp="0.05", commands=BLOCKS, special=FLOAT, parameters=PARAMS))
    with pytest.raises(CaseError, match=r"<acctimesfile>: .*push\.csv:2: .*'nan' in .* is not a finite number"):
        build_case(case, str(tmp_path / "g"))


def test_rotateaxis_with_a_zero_axis(tmp_path):
    """axisp1 == axisp2 wrote NaN positions (a RuntimeWarning) and the run 'blew up'."""
    initials = ('<initials><rotateaxis mkbound="1" angle="10"><axisp1 x="1" y="0" z="1"/>'
                '<axisp2 x="1" y="0" z="1"/></rotateaxis></initials>')
    with pytest.raises(CaseError, match=r"<rotateaxis>: axisp1 equals axisp2"):
        build_case(float_case(tmp_path, initials=initials), str(tmp_path / "g"))


@pytest.mark.parametrize("how", ["xml", "option"])
def test_a_huge_dp_is_a_case_error(tmp_path, how):
    """dp=1e308 overflowed (OverflowError: internal error, exit 1)."""
    case = float_case(tmp_path, dp="1e308" if how == "xml" else "0.05")
    args = ["gencase", case, "-o", str(tmp_path / "g"), "-q"] + (["--dp", "1e308"] if how == "option" else [])
    r = CliRunner().invoke(main, args)
    assert r.exit_code == 2, r.output
    assert "<definition>: dp=1e+308 is too large" in r.output and "internal error" not in r.output


@pytest.mark.parametrize("floating, constants, message", [
    ('', None, None),
    ('<massbody value="1e300"/>', None, r"<floating>: floating mkbound 1: a body mass of 1e\+300 kg"),
    ('<massbody value="1e40"/>', None, r"a body mass of 1e\+40 kg"),
    ('', "massfluid", r"<constantsdef>: massfluid = 1e\+300 is not a finite number within the float range"),
])
def test_absurd_masses(tmp_path, recwarn, floating, constants, message):
    """A massbody of 1e300 passed gencase with a numpy overflow warning (the float32 Mass of the
    VTK file) and the run stopped with overflow warnings and exit 3; now a case error."""
    from case.casetext import CONSTANTS
    consts = CONSTANTS.replace("<cflnumber", '<massfluid value="1e300" auto="false" /><cflnumber') if constants else None
    case = float_case(tmp_path, floating, constants=consts)
    if message is None:
        build_case(case, str(tmp_path / "g"))
    else:
        with pytest.raises(CaseError, match=message):
            build_case(case, str(tmp_path / "g"))
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


def test_descending_link_coefficient_tables(tmp_path):
    """<stiffness><k time=..> rows and a stiffness file whose times go back are refused (they ran)."""
    from case.test_chrono_checks import build
    hinge = ('<bodyfloating id="A" mkbound="1"/><link_hinge idbody1="A"><rotpoint x="0.15" y="0" z="0.5"/>'
             '<rotvector x="0" y="1" z="0"/>{}</link_hinge>')
    inline = '<stiffness><k time="1" value="10"/><k time="0" value="10"/></stiffness>'
    with pytest.raises(CaseError, match=r"<stiffness>: times are not in increasing order"):
        build(tmp_path / "a", hinge.format(inline))
    with pytest.raises(CaseError, match=r"<stiffness>: .*k\.txt:3: <stiffness> table: times are not in increasing"):
        build(tmp_path / "b", hinge.format('<stiffness file="k.txt"/>'), files={"k.txt": "0 1\n2 1\n1 1\n"})


@pytest.mark.parametrize("change, message", [
    ({"constants": ('z="-9.81"', 'z="-1e300"')}, r"<constantsdef>: speedsystem = inf is not a finite number"),
    ({"constants": ('<rhop0 value="1000"', '<rhop0 value="1e300"')}, r"<constantsdef>: rhop0 = 1e\+300 is not"),
    ({"constants": ('<coefsound value="20"', '<coefsound value="1e300"')}, r"<constantsdef>: coefsound = 1e\+300"),
    ({"floating": '<center x="1e300" y="0" z="0"/>'}, r"<floating>: floating mkbound 1: its centre \[1e\+300"),
    ({"floating": '<inertia x="1e300" y="1e300" z="1e300"/>'}, r"<floating>: .* or inertia \[\[1e\+300"),
    ({"floating": '<linearvelini x="1e300" y="0" z="0"/>'}, r"particle\(s\) get a vel that is not a finite"),
])
def test_absurd_finite_values_are_case_errors(tmp_path, recwarn, change, message):
    """Finite but absurd values overflowed later (numpy RuntimeWarnings naming sphdvi's source files,
    then a run that 'blew up'): refused at gencase against the float range DualSPHysics keeps them in,
    with no RuntimeWarning."""
    from case.casetext import CONSTANTS
    consts = CONSTANTS.replace(*change["constants"]) if "constants" in change else None
    with pytest.raises(CaseError, match=message):
        build_case(float_case(tmp_path, change.get("floating", ""), constants=consts), str(tmp_path / "g"))
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


def test_an_older_case_files_driver_table_is_read_as_gencase_reads_it(tmp_path):
    """A case file written before the tables were read at gencase holds {"file": path}: the run
    reads it with the same reader, 'none' a free velocity component (it was taken for a header)."""
    from sphdvi.mechanism import _vector_series
    f = tmp_path / "v.csv"
    f.write_text("0;1;none;0\n1;3;none;2\n")
    at = _vector_series({"file": str(f)}, "<linearvel>")
    assert at(0.5) == [2.0, None, 1.0]
    with pytest.raises(CaseError, match="no data rows"):      # a force has no free component
        _vector_series({"file": str(f)}, "<linearforce>", allow_none=False)

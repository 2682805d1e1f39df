"""``--set`` keys that cannot work (audit hunt10/d, finding 18): a dotted key or one naming a
<special> section is refused with a message that such settings are edited in the case file
(exit 2); ``MdbcMkbound`` (sphdvi's key: DualSPHysics has no such parameter, its mDBC acts on
every boundary with normals) warns when the run is not mDBC (Boundary != 2) or when it names an
mkbound the case does not have."""
import warnings
from pathlib import Path

import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.errors import InputError

REPO = Path(__file__).resolve().parents[2]
DAMBREAK = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def small_case(tmp_path):
    path = tmp_path / "CaseDB_Def.xml"
    path.write_text(DAMBREAK.read_text().replace('dp="0.01"', 'dp="0.05"'))
    return path


@pytest.mark.parametrize("item, section", [("special.shifting.mode=1", "<special><shifting>"),
                                           ("gauges.swl1.point0=1", "<special><gauges>"),
                                           ("special.timeout=0.1", "<special><timeout>"),
                                           ("special=1", "<special>"),
                                           ("foo.bar=2", "a nested element")])
def test_nested_or_special_keys_are_edited_in_the_case_file(item, section):
    from sphdvi.run_options import apply_overrides
    key = item.split("=")[0]
    with pytest.raises(InputError) as exc:
        apply_overrides({"TimeOut": 0.1}, [item])
    text = str(exc.value)
    assert text.startswith(f"--set {key}: {section} is a section of the case file, not a --set key")
    assert "edit it in the case file and run gencase again" in text and "unknown parameter" not in text


def test_a_special_section_name_also_points_to_the_parameter_of_that_name():
    """``--set shifting=1``: <special><shifting> is a section; the parameter is 'Shifting'."""
    from sphdvi.run_options import apply_overrides
    with pytest.raises(InputError, match=r"<special><shifting> is a section.*did you mean the parameter 'Shifting'"):
        apply_overrides({"TimeOut": 0.1}, ["shifting=1"])
    assert apply_overrides({"TimeOut": 0.1}, ["Shifting=1"])["Shifting"] == 1      # the parameter itself


def test_nested_set_exits_2_from_the_command_line(tmp_path):
    r = invoke(["run", small_case(tmp_path), "-o", tmp_path / "o", "--tmax", "0.002", "--threads", "1", "-q",
                "--set", "special.shifting.mode=1"])
    assert r.exit_code == 2, r.output
    assert "--set special.shifting.mode: <special><shifting> is a section of the case file" in r.output
    assert "Traceback" not in r.output


def test_mdbc_mkbound_without_mdbc_warns_that_it_does_nothing():
    from sphdvi.run_options import apply_overrides
    with pytest.warns(UserWarning, match=r"MdbcMkbound '50' does nothing: .*Boundary is 1 \(DBC\), not 2"):
        apply_overrides({"TimeOut": 0.1, "Boundary": 1}, ["MdbcMkbound=50"])
    with pytest.warns(UserWarning, match=r"MdbcMkbound '5' does nothing"):      # Boundary left at its default
        apply_overrides({"TimeOut": 0.1}, ["MdbcMkbound=5"])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        apply_overrides({"TimeOut": 0.1, "Boundary": 1}, ["Boundary=2", "MdbcMkbound=50"])
        apply_overrides({"TimeOut": 0.1, "Boundary": 1}, ["Visco=0.05"])


def test_mdbc_mkbound_naming_an_absent_mkbound_warns_at_the_run(tmp_path):
    """Boundary=2 with MdbcMkbound 0,99 on the dam break (walls mkbound 0 only): a warning naming the
    key, the absent mkbound and that the entry does nothing; the run completes (its one-layer walls
    warned about as well)."""
    with pytest.warns(UserWarning, match=r"MdbcMkbound '0,99': no boundary particles of mkbound 99 in this case: "
                                         r"that entry does nothing"), \
            pytest.warns(UserWarning, match="mDBC on mkbound 0: a wall one particle thick"):
        r = invoke(["run", small_case(tmp_path), "-o", tmp_path / "o", "--tmax", "0.002", "--tout", "0.002",
                    "--threads", "1", "-q", "--set", "Boundary=2", "--set", "MdbcMkbound=0,99"])
    assert r.exit_code == 0, r.output

"""The gencase output <case>.h5 read back by `sphdvi run` (audit hunt8/b finding 16): a file of a
newer layout or sphdvi version, or with damaged contents (shapes, NaN positions, unknown particle
types, duplicated ids, dp <= 0, a text parameter), is an InputError naming the file and what is
wrong (exit 2), never an internal error; a file of the current layout, or of sphdvi 0.1.0 without
a layout attribute, is read."""
import shutil

import h5py
import numpy as np
import pytest
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.errors import InputError
from sphdvi.io.casefile import LAYOUT, read_case_h5


@pytest.fixture(scope="module")
def case_h5(tmp_path_factory):
    d = tmp_path_factory.mktemp("casefile")
    r = CliRunner().invoke(main, ["gencase", write_case(d, case_xml(dp="0.1")), "-o", str(d / "g"), "-q"])
    assert r.exit_code == 0, r.output
    return d / "g" / "Case.h5"


def _replace(f, name, data):
    del f[name]
    f[name] = data


MUTATIONS = {
    "version_newer": (lambda f: (f.attrs.__delitem__("layout"), f.attrs.__setitem__("version", "9.9.9")),
                      "was written by sphdvi 9.9.9, newer than this sphdvi"),
    "version_junk": (lambda f: (f.attrs.__delitem__("layout"), f.attrs.__setitem__("version", "abc")),
                     "its version attribute 'abc' is not a sphdvi version"),
    "layout_newer": (lambda f: f.attrs.__setitem__("layout", LAYOUT + 1),
                     f"in case-file layout {LAYOUT + 1}; this sphdvi .* reads layouts up to {LAYOUT}"),
    "vel_short": (lambda f: _replace(f, "particles/vel", f["particles/vel"][:-5]),
                  r"particles/vel has the shape \(\d+, 3\), expected"),
    "pos_nan": (lambda f: f["particles/pos"].__setitem__((3, 0), np.nan),
                r"particles/pos of particle 3 is \[nan, .*expected finite numbers"),
    "type_bad": (lambda f: f["particles/type"].__setitem__(0, 7), r"particles/type holds \[7\], expected 0-3"),
    "idp_dup": (lambda f: f["particles/idp"].__setitem__(1, f["particles/idp"][0]), "idp holds the same id twice"),
    "dp_zero": (lambda f: f["constants"].attrs.__setitem__("dp", 0.0), "constants/dp is 0.0, expected a positive"),
    "param_text": (lambda f: f["parameters"].attrs.__setitem__("Visco", "abc"),
                   "parameters/Visco is 'abc', expected a number"),
}


@pytest.mark.parametrize("name", sorted(MUTATIONS))
def test_a_damaged_or_newer_case_file_is_an_input_error(tmp_path, case_h5, name):
    mutate, message = MUTATIONS[name]
    path = tmp_path / "Case.h5"
    shutil.copy(case_h5, path)
    with h5py.File(path, "a") as f:
        mutate(f)
    with pytest.raises(InputError, match=r"Case\.h5 .*" + message):
        read_case_h5(str(path))
    r = CliRunner().invoke(main, ["run", str(tmp_path), "-o", str(tmp_path / "r"), "-q", "--threads", "1"])
    assert r.exit_code == 2 and "internal error" not in r.output and "Case.h5" in r.output, r.output


def test_current_and_older_case_files_are_read(tmp_path, case_h5):
    with h5py.File(case_h5) as f:
        assert f.attrs["layout"] == LAYOUT
    assert read_case_h5(str(case_h5))["version"]
    path = tmp_path / "Case.h5"
    shutil.copy(case_h5, path)
    with h5py.File(path, "a") as f:     # as sphdvi 0.1.0 wrote it: no layout attribute
        del f.attrs["layout"]
        f.attrs["version"] = "0.1.0"
    assert read_case_h5(str(path))["particles"]["pos"].shape[1] == 3

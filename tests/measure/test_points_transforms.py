"""MeasureTool's transformation lines in a points file (audit hunt11/m finding 1): MOVE, ROTATEAXIS and
SCALE. DualSPHysics's doc/help/FilePointsTemplate.txt gives their syntax and the one line
"Use_transformation_options_between_POINTS_and_after_POINTSLIST_or_POINTSENDLIST"; it does not say
which points they move (after the line or before it), whether they accumulate or a block resets them,
their order of composition or the rotation's sense, no example case uses them and MeasureTool's source
is not public. sphdvi therefore refuses them, with an error naming the file, line and keyword and
saying how to write the points instead (before: "'MOVE 1 0 0' is not a list of numbers"), exit 2."""
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.measure.post import parse_points

ADVICE = "write the points out already transformed, as x y z rows or POINTSLIST / POINTSENDLIST blocks"


def _file(tmp_path, text):
    path = tmp_path / "points.txt"
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize("line, word", [
    ("MOVE 1 0 0", "MOVE"),
    ("ROTATEAXIS 90 0 0 0 0 0 1", "ROTATEAXIS"),
    ("SCALE 2 2 2", "SCALE"),
    ("move 1 0 0", "MOVE"),                         # keywords are read in any case, as POINTS is
    ("MOVE 1,0,0 # shift", "MOVE"),
])
def test_transform_line_is_refused(tmp_path, line, word):
    """Between POINTS blocks, as the template places them: an error naming file:line, the line and the
    keyword, and saying what is refused and what to write instead."""
    path = _file(tmp_path, f"POINTS\n0 0 1\n{line}\nPOINTS\n1 0.5 -5\n")
    with pytest.raises(ValueError) as exc:
        parse_points(path)
    msg = str(exc.value)
    assert msg.startswith(f"{path}:3: '{line}': ") and f"({word} here)" in msg
    assert "MeasureTool's transformation lines (MOVE, ROTATEAXIS, SCALE) are not read by sphdvi" in msg
    assert "which points they move (those after the line or before it)" in msg
    assert ADVICE in msg and "remove the line" in msg


@pytest.mark.parametrize("text, lineno", [
    ("SCALE 2 2 2\nPOINTS\n0 0 1\n", 1),                                 # before any block
    ("POINTSLIST\n0 0 0\n1 0 0\n10 1 1\nMOVE 0 0 1\n", 5),               # after a list block
    ("POINTSLIST\n0 0 0\nMOVE 0 0 1\n1 0 0\n10 1 1\n", 3),               # inside a list block's rows
    ("POINTSENDLIST\n0 0 0\n0.1 0 0\nROTATEAXIS 90 0 0 0 0 1 0\n", 4),   # in place of a row
])
def test_transform_line_anywhere_names_its_line(tmp_path, text, lineno):
    """Wherever the line stands (also among a POINTSLIST's three rows, where it used to read as a bad
    row), the same refusal naming its line."""
    path = _file(tmp_path, text)
    with pytest.raises(ValueError, match=rf"^{path}:{lineno}: '.*': MeasureTool's transformation lines"):
        parse_points(path)


def test_cli_exit_2(tmp_path):
    """`sphdvi measure points` and `measure elevation --at FILE`: exit 2, the message on stderr (the points
    are read before the run folder)."""
    path = _file(tmp_path, "POINTS\n0 0 1\nMOVE 1 0 0\n")
    for args in (["points", str(tmp_path), "--points", path], ["elevation", str(tmp_path), "--at", path]):
        r = CliRunner().invoke(main, ["measure", *args])
        assert r.exit_code == 2, r.output
        assert f"{path}:3: 'MOVE 1 0 0': MeasureTool's transformation lines" in r.output
        assert "write the points out already transformed" in " ".join(r.output.split())


def test_plain_points_files_unchanged(tmp_path):
    """The template's own example (its POINTS and POINTSLIST blocks, without transformation lines)
    reads as before: 2 + 10 + 200 points."""
    path = _file(tmp_path, "POINTS\n0 0    1 #Point:(0,0,1)\n1 0.5 -5\n\nPOINTSLIST\n0  0 0\n1  0 0\n10 1 1\n\n"
                           "POINTSLIST\n10  0 0\n1   1 0\n10 20 1\n")
    pts = parse_points(path)
    assert pts.shape == (212, 3)
    assert pts[:2].tolist() == [[0, 0, 1], [1, 0.5, -5]]
    assert pts[11].tolist() == [9, 0, 0] and pts[-1].tolist() == [19, 19, 0]

"""bodies.csv / links.csv cut back to the restart time on resume (io.runfiles.BodyLog)."""
from sphdvi.dvi.runner import BODIES_HEADER, LINKS_HEADER, csv_time
from sphdvi.io.runfiles import BodyLog


def test_resume_keeps_the_row_written_at_the_restart_time(tmp_path):
    """The time column has 9 digits: a restart time whose printed value rounds up must
    still keep its own row (and drop the later ones)."""
    t_restart = 0.1500393946                  # prints as 0.150039395 > t_restart
    assert float(csv_time(t_restart)) > t_restart
    times = [0.1, t_restart, 0.1600393946]
    for name, header in (("bodies.csv", BODIES_HEADER), ("links.csv", LINKS_HEADER)):
        rows = "".join(f"{csv_time(t)},b,1,2\n" for t in times)
        (tmp_path / name).write_text(header + "\n" + rows + "0.17,b,1")   # a torn last line
    BodyLog(str(tmp_path), None, ["b"], resume_time=t_restart)
    for name in ("bodies.csv", "links.csv"):
        lines = (tmp_path / name).read_text().splitlines()
        assert [ln.split(",")[0] for ln in lines[1:]] == [csv_time(0.1), csv_time(t_restart)]


def test_resume_of_an_older_bodies_csv_pads_its_rows(tmp_path):
    """bodies.csv written before the fluid-load columns (ffx..ftz): a resume keeps one table,
    the older rows filled with nan under the new columns."""
    old_header = BODIES_HEADER.rsplit(",ffx", 1)[0]
    row = "0.1,b," + ",".join(["1"] * (old_header.count(",") - 1))
    (tmp_path / "bodies.csv").write_text(old_header + "\n" + row + "\n")
    (tmp_path / "links.csv").write_text(LINKS_HEADER + "\n")
    BodyLog(str(tmp_path), None, ["b"], resume_time=0.1)
    lines = (tmp_path / "bodies.csv").read_text().splitlines()
    assert lines[0] == BODIES_HEADER
    assert lines[1].split(",")[-6:] == ["nan"] * 6 and lines[1].count(",") == BODIES_HEADER.count(",")
